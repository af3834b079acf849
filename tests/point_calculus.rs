//! Paper 003's point calculus through the real front end: faces bounded by
//! conic arcs and a 9-point patch lid compile watertight with the right
//! volumes, standalone curves become sampled line elements with exact ends,
//! and the point-equation parallelepiped equals paper 000's form exactly.

use geomc::driver::{Options, check_source};
use geomc::geom::point_calculus::PcCurve;
use geomc::geom::{Curve, Point3};
use geomc::ir::Model;
use geomc::mesh::Mesh;
use geomc::meshing::{MeshOptions, Quality, Tolerance, mesh_model, quality, sanity_check};
use geomc::span::SourceFile;
use std::f64::consts::PI;

fn fixture(name: &str) -> String {
    let path = format!("{}/fixtures/valid/{name}", env!("CARGO_MANIFEST_DIR"));
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"))
}

fn model(xml: &str) -> Model {
    let checked = check_source(SourceFile::new("t.xml", xml), &Options::default());
    assert!(checked.is_valid(), "{:#?}", checked.diagnostics.items);
    checked.lowered.expect("a model").model
}

fn mesh(model: &Model, tolerance: f64) -> (Mesh, Quality) {
    let options = MeshOptions {
        tolerance: Tolerance::Absolute(tolerance),
        ..MeshOptions::default()
    };
    let mesh = mesh_model(model, &options).expect("meshable");
    sanity_check(&mesh).expect("watertight, conforming mesh");
    let q = quality(&mesh);
    (mesh, q)
}

#[test]
fn cylinder_bounded_by_conic_arcs_is_watertight() {
    let m = model(&fixture("pointcalc_conic_cylinder.xml"));
    assert_eq!((m.vertices.len(), m.edges.len(), m.faces.len()), (6, 9, 5));
    // The six arcs are conic edges with k = 2/3 (120° circular arcs).
    let conics = m
        .edges
        .iter()
        .filter(|e| matches!(&*e.curve(&m.solids), Curve::PointCalculus(c) if matches!(**c, PcCurve::Conic { k, .. } if (k - 2.0 / 3.0).abs() < 1e-15)))
        .count();
    assert_eq!(conics, 6);
    // The arcs are exact circles: every point at radius 1.
    for e in &m.edges[..6] {
        for p in e.curve(&m.solids).samples(50) {
            assert!((p.x.hypot(p.y) - 1.0).abs() < 1e-14, "{}: {p}", e.name);
        }
    }
    // Carried only through edges, the curves are no standalone lines.
    assert!(m.polylines.is_empty());
    let mut previous = f64::INFINITY;
    for tolerance in [0.01, 0.0025] {
        let (mesh, q) = mesh(&m, tolerance);
        let s = &q.subdomains[0];
        let (dv, da) = ((s.volume - PI).abs(), (s.area - 4.0 * PI).abs());
        assert!(
            dv <= 4.0 * PI * tolerance,
            "volume {} at {tolerance}",
            s.volume
        );
        assert!(
            da <= 16.0 * PI * tolerance,
            "area {} at {tolerance}",
            s.area
        );
        assert!(dv < previous);
        previous = dv;
        // Bottom and sides share the arc's nodes.
        let b01 = &mesh.edges[0];
        assert!(b01.nodes.len() > 3);
    }
}

#[test]
fn patch_lid_meshes_with_its_walls() {
    let m = model(&fixture("pointcalc_patch_pillow.xml"));
    let lid = m.faces.iter().find(|f| f.name == "lid").expect("lid");
    let lid_surface = lid.surface(&m.solids);
    assert!(matches!(*lid_surface, geomc::geom::Surface::Patch9(_)));
    // Exact volume: 4 · Σ Wᵢ Wⱼ zᵢⱼ with Simpson weights 1/6, 2/3, 1/6 = 5.6.
    let mut previous = f64::INFINITY;
    for tolerance in [0.02, 0.005] {
        let (mesh, q) = mesh(&m, tolerance);
        let s = &q.subdomains[0];
        let dv = (s.volume - 5.6).abs();
        assert!(dv <= 20.0 * tolerance, "volume {} at {tolerance}", s.volume);
        assert!(dv < previous, "{dv} after {previous}");
        previous = dv;
        // Lid nodes lie on the patch.
        let lid_mesh = mesh.faces.iter().find(|f| f.name == "lid").expect("lid");
        for t in &lid_mesh.triangles {
            for &n in t {
                let p = Point3::from(mesh.nodes[n as usize]);
                assert!(lid_surface.distance(&p) < 1e-9, "{p}");
            }
        }
        assert!(q.min_angle > 10.0, "{}", q.min_angle);
    }
}

#[test]
fn standalone_curves_are_sampled_line_elements() {
    let m = model(&fixture("pointcalc_curves.xml"));
    let names: Vec<&str> = m.polylines.iter().map(|l| l.name.as_str()).collect();
    assert_eq!(names, ["base", "hyperbola", "parabola", "ellipse", "cubic"]);
    let tolerance = 1e-3;
    let (mesh, _) = mesh(&m, tolerance);
    assert_eq!(mesh.polylines.len(), 5);
    for (line, sampled) in m.polylines.iter().zip(&mesh.polylines) {
        let Some(Curve::PointCalculus(c)) = &line.curve else {
            panic!("{} has no curve", line.name);
        };
        let nodes: Vec<Point3> = sampled
            .nodes
            .iter()
            .map(|&i| Point3::from(mesh.nodes[i as usize]))
            .collect();
        assert_eq!(nodes[0], c.begin(), "{}", line.name);
        assert_eq!(*nodes.last().expect("nodes"), c.end(), "{}", line.name);
        // Chords within the tolerance of the curve.
        for u in (0..=400).map(|i| i as f64 / 400.0) {
            let p = c.point(u);
            let d = nodes
                .windows(2)
                .map(|w| {
                    let d = w[1] - w[0];
                    let t = ((p - w[0]).dot(&d) / d.norm_squared()).clamp(0.0, 1.0);
                    (p - (w[0] + d * t)).norm()
                })
                .fold(f64::INFINITY, f64::min);
            assert!(d <= tolerance * 1.001, "{}: {d}", line.name);
        }
        if line.name == "base" {
            assert_eq!(
                nodes.len(),
                3,
                "a straight segment needs no more than its minimum"
            );
        } else {
            assert!(nodes.len() > 8, "{}: {}", line.name, nodes.len());
        }
    }
}

#[test]
fn point_equation_parallelepiped_equals_base_point_form() {
    let point_form = r#"<geometry version="1">
      <parameters><parameter name="w" value="1.5"/></parameters>
      <point name="corner"><value x="0.25" y="-1" z="0.5"/></point>
      <parallelepiped name="a">
        <point_a x="0.25 + w" y="-1" z="0.5"/><point_b x="0.75" y="0.1" z="0.5"/>
        <point_c x="0.3" y="-0.9" z="2.7"/><point_d point="corner"/>
      </parallelepiped>
      <subdomain name="s"><solid ref="a"/></subdomain></geometry>"#;
    let base_form = r#"<geometry version="1">
      <parameters><parameter name="w" value="1.5"/></parameters>
      <point name="corner"><value x="0.25" y="-1" z="0.5"/></point>
      <parallelepiped name="a">
        <base_point point="corner"/><vertex x="0.25 + w" y="-1" z="0.5"/>
        <vertex x="0.75" y="0.1" z="0.5"/><vertex x="0.3" y="-0.9" z="2.7"/>
      </parallelepiped>
      <subdomain name="s"><solid ref="a"/></subdomain></geometry>"#;
    let (a, b) = (model(point_form), model(base_form));
    assert_eq!(a.solids.len(), 1);
    assert_eq!(a.solids[0].shape, b.solids[0].shape);
    assert_eq!(a.vertices, b.vertices);
    assert_eq!(a.faces, b.faces);
}

#[test]
fn curves_compile_to_line_elements_in_obj_gltf_and_msh() {
    let dir = tempfile::tempdir().expect("temporary folder");
    let input = format!(
        "{}/fixtures/valid/pointcalc_curves.xml",
        env!("CARGO_MANIFEST_DIR")
    );
    let out = |ext: &str| dir.path().join(format!("curves.{ext}"));
    let status = std::process::Command::new(env!("CARGO_BIN_EXE_geomc"))
        .args(["compile", &input, "-o"])
        .arg(out("obj"))
        .arg("-o")
        .arg(out("gltf"))
        .arg("-o")
        .arg(out("msh"))
        .output()
        .expect("run geomc");
    assert!(
        status.status.success(),
        "{}",
        String::from_utf8_lossy(&status.stderr)
    );
    let obj = std::fs::read_to_string(out("obj")).expect("obj");
    assert_eq!(obj.lines().filter(|l| l.starts_with("l ")).count(), 5);
    for name in ["base", "hyperbola", "parabola", "ellipse", "cubic"] {
        assert!(obj.lines().any(|l| l == format!("o {name}")), "{name}");
    }
    let gltf: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out("gltf")).expect("gltf")).expect("json");
    let lines = gltf["meshes"]
        .as_array()
        .expect("meshes")
        .iter()
        .flat_map(|m| m["primitives"].as_array().cloned().unwrap_or_default())
        .filter(|p| p["mode"] == 1)
        .count();
    assert_eq!(lines, 5, "one LINES primitive per curve");
    let msh = std::fs::read_to_string(out("msh")).expect("msh");
    // MSH: one physical group of line elements (dimension 1) per curve, by name.
    for (tag, name) in ["base", "hyperbola", "parabola", "ellipse", "cubic"]
        .iter()
        .enumerate()
    {
        assert!(msh.contains(&format!("1 {} \"{name}\"", tag + 1)), "{name}");
    }
}
