//! Issue 6: 2D R-function regions. In a `dimension="2"` model an
//! `<rfunction>` subdomain is the region f(x, y) ≥ 0; its zero contour is
//! traced, graded and meshed by the 2D mesher with the requested minimum
//! angle. Checked on areas against closed forms, angles, boundary nodes on
//! the true curve, diagnostics, MSH files read by gmsh and meshio, and a
//! scikit-fem solve (the tools are installed by ./scripts/test.sh).

mod mesh2d_common;

use geomc::diag::Code;
use geomc::driver::{Options, check_source};
use geomc::mesh::Mesh;
use geomc::meshing::{MeshOptions, mesh_model};
use geomc::span::SourceFile;
use mesh2d_common::{at_30_degrees, gmsh_group, python};
use std::f64::consts::PI;
use std::path::Path;
use std::process::Command;

fn model_xml(body: &str) -> String {
    format!(r#"<geometry version="1" dimension="2">{body}</geometry>"#)
}

const DISK: &str = r#"
  <rfunction name="round" nx="32" ny="32" x_min="-1.5" x_max="1.5" y_min="-1.5" y_max="1.5">
    <disk r="1" x0="0" y0="0"/>
  </rfunction>
  <subdomain name="inside" material="steel"> <solid ref="round"/> </subdomain>"#;

const ANNULUS: &str = r#"
  <rfunction name="ring" nx="40" ny="40" x_min="-1.2" x_max="1.2" y_min="-1.2" y_max="1.2">
    <difference> <disk r="1" x0="0" y0="0"/> <disk r="0.5" x0="0" y0="0"/> </difference>
  </rfunction>
  <subdomain name="ring"> <solid ref="ring"/> </subdomain>"#;

/// Two unit disks 1 apart, joined by Rvachev's R-disjunction.
const PAIR: &str = r#"
  <rfunction name="pair" nx="64" ny="64" x_min="-1.2" x_max="2.2" y_min="-1.2" y_max="1.2">
    <union> <disk r="1" x0="0" y0="0"/> <disk r="1" x0="1" y0="0"/> </union>
  </rfunction>
  <subdomain name="pair"> <solid ref="pair"/> </subdomain>"#;

fn mesh(body: &str, options: &MeshOptions) -> Mesh {
    let checked = check_source(
        SourceFile::new("t.xml", model_xml(body)),
        &Options::default(),
    );
    assert!(checked.is_valid(), "{:#?}", checked.diagnostics.items);
    assert!(
        checked.implicit.is_empty(),
        "2D regions leave nothing to polygonize"
    );
    let model = checked.lowered.expect("a model").model;
    mesh_model(&model, options).expect("meshes")
}

fn triangles(m: &Mesh) -> Vec<[u32; 3]> {
    m.faces
        .iter()
        .flat_map(|f| f.triangles.iter().copied())
        .collect()
}

fn area(m: &Mesh) -> f64 {
    triangles(m)
        .iter()
        .map(|t| {
            let [p, q, r] = t.map(|n| m.nodes[n as usize]);
            0.5 * ((q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]))
        })
        .inspect(|&a| assert!(a > 0.0, "a triangle runs clockwise"))
        .sum()
}

fn min_angle(m: &Mesh) -> f64 {
    let mut smallest = 180.0f64;
    for t in triangles(m) {
        let p = t.map(|n| m.nodes[n as usize]);
        for k in 0..3 {
            let (a, b, c) = (p[k], p[(k + 1) % 3], p[(k + 2) % 3]);
            let (u, v) = ([b[0] - a[0], b[1] - a[1]], [c[0] - a[0], c[1] - a[1]]);
            let cos = (u[0] * v[0] + u[1] * v[1]) / (u[0].hypot(u[1]) * v[0].hypot(v[1]));
            smallest = smallest.min(cos.clamp(-1.0, 1.0).acos().to_degrees());
        }
    }
    smallest
}

/// The nodes of the boundary: every node of an edge polyline, once.
fn boundary_nodes(m: &Mesh) -> Vec<[f64; 3]> {
    let mut ids: Vec<u32> = m
        .edges
        .iter()
        .flat_map(|e| e.nodes.iter().copied())
        .collect();
    ids.sort_unstable();
    ids.dedup();
    ids.into_iter().map(|n| m.nodes[n as usize]).collect()
}

fn boundary_segments(m: &Mesh) -> usize {
    m.edges.iter().map(|e| e.nodes.len() - 1).sum()
}

#[test]
fn disk_region_has_pi_area_30_degrees_and_nodes_on_the_circle() {
    let m = mesh(DISK, &at_30_degrees(Some(0.01)));
    let a = area(&m);
    assert!((a - PI).abs() / PI < 2e-3, "area {a}");
    // The polygon is inscribed: a little under π.
    assert!(a < PI);
    let angle = min_angle(&m);
    assert!(angle >= 30.0 - 1e-9, "min angle {angle}");
    let nodes = boundary_nodes(&m);
    for p in &nodes {
        let r = p[0].hypot(p[1]);
        assert!(
            (r - 1.0).abs() < 1e-9,
            "boundary node off the circle: r = {r}"
        );
    }
    // A closed loop: as many segments as nodes. The chord tolerance is
    // 0.5e-3 of the box diagonal (3√2): chords of 2√(2·tol) = 0.130 need at
    // least 48 segments; grading (neighbours within 1.5×) adds some, never
    // triples them.
    assert_eq!(boundary_segments(&m), nodes.len());
    assert!(
        (48..=144).contains(&nodes.len()),
        "{} boundary nodes",
        nodes.len()
    );
    // One subdomain with its material, one exterior fragment over every edge.
    assert_eq!(m.subdomains.len(), 1);
    assert_eq!(m.subdomains[0].name, "inside");
    assert_eq!(m.subdomains[0].material.as_deref(), Some("steel"));
    let outer: Vec<_> = m
        .fragments
        .iter()
        .filter(|f| f.name == "inside|exterior")
        .collect();
    assert_eq!(outer.len(), 1);
    assert_eq!(outer[0].edges.len(), m.edges.len());
    // The area limit holds.
    assert!(triangles(&m).len() as f64 >= PI / 0.01);
}

/// An area limit far below the contour's spacing makes refinement split
/// contour pieces: the new nodes go on the circle (f = 0), not on the chords
/// (up to 2e-3 inside the circle here).
#[test]
fn contour_pieces_split_by_refinement_get_their_nodes_on_the_circle() {
    let coarse = mesh(DISK, &at_30_degrees(Some(0.01)));
    let m = mesh(DISK, &at_30_degrees(Some(1e-4)));
    let (traced, refined) = (boundary_segments(&coarse), boundary_segments(&m));
    assert!(
        refined >= 2 * traced,
        "{traced} -> {refined} boundary segments"
    );
    let nodes = boundary_nodes(&m);
    assert_eq!(nodes.len(), refined);
    for p in &nodes {
        let r = p[0].hypot(p[1]);
        assert!(
            (r - 1.0).abs() < 1e-9,
            "boundary node off the circle: r = {r}"
        );
    }
    let angle = min_angle(&m);
    assert!(angle >= 30.0 - 1e-9, "min angle {angle}");
    let a = area(&m);
    assert!((a - PI).abs() / PI < 1e-4, "area {a}");
}

/// `area=` on a region's subdomain limits its triangles' area, as on a
/// kernel subdomain; a limit that is not positive is E300.
#[test]
fn area_attribute_of_a_region_subdomain_limits_its_triangles() {
    let limited = DISK.replace(
        r#"<subdomain name="inside" material="steel">"#,
        r#"<subdomain name="inside" material="steel" area="2e-3">"#,
    );
    let m = mesh(&limited, &at_30_degrees(None));
    let largest = triangles(&m)
        .iter()
        .map(|t| {
            let [p, q, r] = t.map(|n| m.nodes[n as usize]);
            0.5 * ((q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]))
        })
        .fold(0.0f64, f64::max);
    assert!(largest <= 2e-3, "largest triangle {largest}");
    assert!(triangles(&m).len() as f64 >= PI / 2e-3);
    let unlimited = mesh(DISK, &at_30_degrees(None));
    assert!(triangles(&unlimited).len() < triangles(&m).len() / 2);
    let bad = DISK.replace(
        r#"<subdomain name="inside" material="steel">"#,
        r#"<subdomain name="inside" material="steel" area="-1">"#,
    );
    assert_eq!(codes(&bad), vec![Code::NonPositiveSize]);
}

#[test]
fn annulus_region_has_two_loops_on_their_circles() {
    let m = mesh(ANNULUS, &at_30_degrees(None));
    let exact = PI * (1.0 - 0.25);
    let a = area(&m);
    assert!((a - exact).abs() / exact < 2e-3, "area {a} against {exact}");
    assert!(min_angle(&m) >= 30.0 - 1e-9, "min angle {}", min_angle(&m));
    let nodes = boundary_nodes(&m);
    let outer = nodes
        .iter()
        .filter(|p| (p[0].hypot(p[1]) - 1.0).abs() < 1e-9)
        .count();
    let inner = nodes
        .iter()
        .filter(|p| (p[0].hypot(p[1]) - 0.5).abs() < 1e-9)
        .count();
    assert_eq!(
        outer + inner,
        nodes.len(),
        "every boundary node on one of the circles"
    );
    assert!(outer > inner && inner >= 24, "outer {outer}, inner {inner}");
}

#[test]
fn union_of_two_disks_keeps_its_corners_and_the_angle_bound() {
    let m = mesh(PAIR, &at_30_degrees(None));
    // Two unit disks at distance 1: 2π − the lens (2π/3 − √3/2).
    let exact = 2.0 * PI - (2.0 * PI / 3.0 - 3f64.sqrt() / 2.0);
    let a = area(&m);
    assert!((a - exact).abs() / exact < 2e-3, "area {a} against {exact}");
    assert!(min_angle(&m) >= 30.0 - 1e-9, "min angle {}", min_angle(&m));
    // The two notches (0.5, ±√3/2) are boundary nodes.
    let nodes = boundary_nodes(&m);
    for y in [3f64.sqrt() / 2.0, -(3f64.sqrt()) / 2.0] {
        let nearest = nodes
            .iter()
            .map(|p| (p[0] - 0.5).hypot(p[1] - y))
            .fold(f64::INFINITY, f64::min);
        assert!(nearest < 1e-9, "notch at y = {y}: nearest node {nearest}");
    }
}

#[test]
fn region_beside_a_kernel_circle_and_with_a_size_field() {
    let body = format!(
        r#"{DISK}
      <circle name="c"><center x="4" y="0"/><radius value="0.5"/></circle>
      <subdomain name="kernel"><solid ref="c"/></subdomain>"#
    );
    let m = mesh(&body, &at_30_degrees(Some(0.02)));
    assert_eq!(m.subdomains.len(), 2);
    let a = area(&m);
    let exact = PI + PI * 0.25;
    assert!((a - exact).abs() / exact < 2e-3, "area {a} against {exact}");
}

fn codes(body: &str) -> Vec<Code> {
    let checked = check_source(
        SourceFile::new("t.xml", model_xml(body)),
        &Options::default(),
    );
    checked.diagnostics.items.iter().map(|d| d.code).collect()
}

#[test]
fn diagnostics_for_empty_cut_and_sampled_regions() {
    let empty = r#"<rfunction name="far" x_min="-1" x_max="1" y_min="-1" y_max="1">
        <disk r="0.5" x0="5" y0="5"/> </rfunction>
      <subdomain name="far"> <solid ref="far"/> </subdomain>"#;
    assert_eq!(codes(empty), vec![Code::RegionEmpty]);
    // f = −x² is zero along x = 0 only: a line, no area.
    let line = r#"<rfunction name="line" nx="8" ny="8"> <formula value="-x*x"/> </rfunction>
      <subdomain name="line"> <solid ref="line"/> </subdomain>"#;
    assert_eq!(codes(line), vec![Code::RegionEmpty]);
    // The disk sticks out of its box on the right: the side x = 0.5 bounds it.
    let cut = r#"<rfunction name="half" nx="32" ny="32" x_min="-1.5" x_max="0.5" y_min="-1.5" y_max="1.5">
        <disk r="1" x0="0" y0="0"/> </rfunction>
      <subdomain name="half"> <solid ref="half"/> </subdomain>"#;
    assert_eq!(codes(cut), vec![Code::RegionCutByBox]);
    let m = mesh(cut, &MeshOptions::default());
    // The disk left of x = 0.5: π − the segment beyond it.
    let segment = (1.0f64 / 2.0).acos() - 0.5 * (0.75f64).sqrt();
    let exact = PI - segment;
    assert!((area(&m) - exact).abs() / exact < 2e-3, "area {}", area(&m));
    let dir = tempfile::tempdir().expect("tempdir");
    std::fs::write(dir.path().join("v.raw"), [0u8; 8]).expect("write samples");
    let xml = model_xml(
        r#"<density_volume name="ct" file="v.raw" type="u8" dims="2 2 2" level="1"/>
      <subdomain name="ct"> <solid ref="ct"/> </subdomain>"#,
    );
    let path = dir.path().join("d.xml");
    std::fs::write(&path, &xml).expect("write model");
    let checked = check_source(
        SourceFile::new(path.to_string_lossy(), &xml),
        &Options::default(),
    );
    let found: Vec<Code> = checked.diagnostics.items.iter().map(|d| d.code).collect();
    assert_eq!(found, vec![Code::RegionNotFunction]);
}

fn compile(body: &str, dir: &Path, name: &str, args: &[&str]) -> std::path::PathBuf {
    let input = dir.join(format!("{name}.xml"));
    std::fs::write(&input, model_xml(body)).expect("write input");
    let output = dir.join(format!("{name}.msh"));
    let status = Command::new(env!("CARGO_BIN_EXE_geomc"))
        .args(["compile", "-q"])
        .arg(&input)
        .args(args)
        .arg("-o")
        .arg(&output)
        .status()
        .expect("run geomc");
    assert!(status.success(), "geomc compile {name}");
    output
}

#[test]
fn msh_of_a_region_is_read_by_gmsh_and_meshio_and_solved_by_scikit_fem() {
    let dir = tempfile::tempdir().expect("tempdir");
    let msh = compile(
        DISK,
        dir.path(),
        "disk",
        &["--min-angle", "30", "--max-area", "0.01"],
    );
    let expected = mesh(DISK, &at_30_degrees(Some(0.01)));
    let r = python("check_mesh.py", &[&msh], &[]);
    let segments = boundary_segments(&expected) as u64;
    assert_eq!(
        gmsh_group(&r, "inside|exterior")["elements"]["line"],
        segments
    );
    assert_eq!(
        gmsh_group(&r, "inside")["elements"]["triangle"],
        triangles(&expected).len() as u64
    );
    assert_eq!(r["gmsh"]["nodes"], expected.nodes.len() as u64);
    assert_eq!(r["meshio"]["cell_sets"]["inside|exterior"], segments);
    // −Δu = 1, u = 0 on the contour: max u = 1/4 at the centre.
    let s = python("fem_poisson.py", &[&msh], &["disk", "inside|exterior"]);
    let max_u = s["max_u"].as_f64().expect("max_u");
    assert!((max_u - 0.25).abs() < 5e-3, "max u {max_u}");
    assert!(s["max_error"].as_f64().expect("max_error") < 5e-3, "{s}");
    assert_eq!(s["fixed"].as_u64(), Some(segments));
}
