//! Box caps (issue 5): where a solid leaves its grid's box it is closed on
//! the box, and those triangles are the face `NAME_box_cap` with the
//! fragment `NAME|box`, apart from `NAME_boundary` / `NAME|exterior`.

mod implicit_common;

use geomc::driver::{Options, check_file};
use geomc::implicit::xml::mesh::append;
use geomc::implicit::{lang, surface_to_mesh};
use geomc::mesh::Mesh;
use geomc::span::SourceFile;
use std::f64::consts::PI;

/// A ball of r = 1.2 in the box [-1, 1]³: six discs of radius
/// sqrt(1.2² − 1) are cut off by the box.
const CUT_BALL: &str = "Geom.x_min = -1; Geom.x_max = 1; Geom.y_min = -1; Geom.y_max = 1;
Geom.z_min = -1; Geom.z_max = 1; Geom.nx = 40; Geom.ny = 40; Geom.nz = 40;
Geom.name = \"cut\";
function cut(x, y, z) { return Ball(x, y, z, 1.2, 0, 0, 0); }
";

fn tri_area(m: &Mesh, t: [u32; 3]) -> f64 {
    let [a, b, c] = t.map(|i| m.nodes[i as usize]);
    let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
    let n = [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ];
    0.5 * (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt()
}

/// Area of each fragment, by name.
fn fragment_areas(m: &Mesh) -> Vec<(String, f64)> {
    m.fragments
        .iter()
        .map(|f| {
            let a = f
                .faces
                .iter()
                .flat_map(|&face| m.faces[face as usize].triangles.iter())
                .map(|&t| tri_area(m, t))
                .sum();
            (f.name.clone(), a)
        })
        .collect()
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

#[test]
fn a_ball_cut_by_its_box_has_its_caps_tagged() {
    let (model, diags) = lang::compile(&SourceFile::new("cut.rfs", CUT_BALL));
    assert!(!diags.has_errors(), "{:?}", diags.items);
    let model = model.expect("a model");
    let surface = model.polygonize(None);
    let mesh = surface_to_mesh(&surface, model.name(), model.geom.min, model.geom.max);
    let areas = fragment_areas(&mesh);
    let names: Vec<&str> = areas.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, ["cut|exterior", "cut|box"]);
    let faces: Vec<&str> = mesh.faces.iter().map(|f| f.name.as_str()).collect();
    assert_eq!(faces, ["cut_boundary", "cut_box_cap"]);
    assert_eq!(mesh.subdomains[0].faces, vec![(0, true), (1, true)]);
    // Six discs of radius² 0.44. Box samples count as at most 0, so a cap
    // ends at the samples inside the disc and the strip to the true rim
    // (up to a cell wide) is boundary: measured 6.7% short at 40³, 3.2% at
    // 80³ (the cut converges with the spacing).
    let caps = 6.0 * PI * 0.44;
    let short = 1.0 - areas[1].1 / caps;
    assert!(
        (0.05..0.08).contains(&short),
        "caps {} vs {caps}",
        areas[1].1
    );
    let fine = model.polygonize(Some([80; 3]));
    let fine = surface_to_mesh(&fine, model.name(), model.geom.min, model.geom.max);
    let fine_short = 1.0 - fragment_areas(&fine)[1].1 / caps;
    assert!((0.02..0.04).contains(&fine_short), "80³: {fine_short}");
    // Every cap node on a box face.
    for &t in &mesh.faces[1].triangles {
        let on = (0..3).any(|a| {
            t.iter()
                .all(|&v| (mesh.nodes[v as usize][a].abs() - 1.0).abs() < 1e-12)
        });
        assert!(on, "{t:?} is not on a box face");
    }
    // Nothing is lost: both faces together are the whole closed surface.
    let total: usize = mesh.faces.iter().map(|f| f.triangles.len()).sum();
    assert_eq!(total, surface.triangles.len());
}

#[test]
fn a_ball_inside_its_box_has_no_cap() {
    let text = CUT_BALL.replace("1.2, 0, 0, 0", "0.8, 0, 0, 0");
    let (model, _) = lang::compile(&SourceFile::new("ball.rfs", &text));
    let model = model.expect("a model");
    let mesh = surface_to_mesh(
        &model.polygonize(None),
        model.name(),
        model.geom.min,
        model.geom.max,
    );
    let names: Vec<&str> = mesh.fragments.iter().map(|f| f.name.as_str()).collect();
    assert_eq!(names, ["cut|exterior"]);
}

/// The XML path: a lone subdomain and a block reaching past the joint grid
/// (meshed with a pin through it) both get their `|box` fragment.
#[test]
fn xml_subdomains_cut_by_their_box_have_box_fragments() {
    let dir = tempfile::tempdir().expect("temp dir");
    let xml = r#"<?xml version="1.0"?>
<geometry version="1">
<rfunction name="cyl" rsystem="minmax" nx="24" ny="24" nz="24">
  <intersection> <disk r="0.3" x0="0" y0="0"/> <formula value="0.9 - abs(z)"/> </intersection>
</rfunction>
<rfunction name="slab" rsystem="minmax" nx="24" ny="24" nz="24"> <box x0="-2" y0="-2" z0="-0.5" w="4" h="4" d="1"/> </rfunction>
<subdomain name="pin"> <solid ref="cyl"/> </subdomain>
<subdomain name="plate"> <difference> <solid ref="slab"/> <solid ref="cyl"/> </difference> </subdomain>
</geometry>
"#;
    let path = dir.path().join("caps.xml");
    std::fs::write(&path, xml).expect("write the model");
    let c = check_file(&path, &Options::default()).expect("read the model");
    assert!(c.is_valid(), "{:#?}", c.diagnostics.items);
    let mut mesh = Mesh::default();
    append(&mut mesh, &c.implicit, None, None);
    let areas = fragment_areas(&mesh);
    let names: Vec<&str> = areas.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(
        names,
        ["pin|exterior", "plate|exterior", "plate|box", "pin|plate",]
    );
    let area = |name: &str| areas.iter().find(|(n, _)| n == name).map_or(0.0, |a| a.1);
    // The plate leaves the grid [-1, 1]² on four sides, 2 × 1 each; the
    // caps lie on the box (their face and cell points 1e-3 of a cell
    // inside, where dual contouring keeps them).
    assert!(rel(area("plate|box"), 8.0) < 0.02, "{}", area("plate|box"));
    let cap = mesh.faces.iter().find(|f| f.name == "plate_box_cap");
    let cap = cap.expect("the plate's cap face");
    for &t in &cap.triangles {
        let p = t.map(|v| mesh.nodes[v as usize]);
        let on = (0..2).any(|a| p.iter().all(|q| (q[a].abs() - 1.0).abs() < 1e-4));
        assert!(on, "{p:?} is not on the box");
    }
}

/// A lone XML subdomain leaving its own box at x = 4 (the box primitive
/// spans 3..5): the cap is the 1 × 1 square there.
#[test]
fn a_lone_xml_subdomain_cut_by_its_box_has_a_box_fragment() {
    let dir = tempfile::tempdir().expect("temp dir");
    let xml = r#"<?xml version="1.0"?>
<geometry version="1">
<rfunction name="far" rsystem="minmax" x_min="4" x_max="6" nx="20" ny="20" nz="20"> <box x0="3" y0="-0.5" z0="-0.5" w="2" h="1" d="1"/> </rfunction>
<subdomain name="lone"> <solid ref="far"/> </subdomain>
</geometry>
"#;
    let path = dir.path().join("lone.xml");
    std::fs::write(&path, xml).expect("write the model");
    let c = check_file(&path, &Options::default()).expect("read the model");
    assert!(c.is_valid(), "{:#?}", c.diagnostics.items);
    let mut mesh = Mesh::default();
    append(&mut mesh, &c.implicit, None, None);
    let areas = fragment_areas(&mesh);
    let names: Vec<&str> = areas.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, ["lone|exterior", "lone|box"]);
    // Samples on y, z = ±0.5 have f = 0 exactly and count as outside, so
    // the cap is the square of the samples inside: 0.8 × 0.8.
    assert!(rel(areas[1].1, 0.64) < 1e-9, "cap {}", areas[1].1);
    // The rest: the five faces inside the box (area 5) cut back to where
    // the strip from that square meets them; measured 4.627.
    assert!(areas[0].1 > 4.5 && areas[0].1 < 5.0, "rest {}", areas[0].1);
}
