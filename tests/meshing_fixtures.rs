//! Every valid fixture with subdomains meshes and passes the sanity check;
//! shared faces and interfaces conform; 2D regions measure what they should.

use geomc::driver::{Options, check_source};
use geomc::ir::{Model, SubdomainCells};
use geomc::mesh::Mesh;
use geomc::meshing::{MeshOptions, Tolerance, mesh_model, quality, sanity_check};
use geomc::span::SourceFile;
use std::f64::consts::PI;

fn model(name: &str, xml: &str) -> Model {
    let checked = check_source(SourceFile::new(name, xml), &Options::default());
    assert!(
        checked.is_valid(),
        "{name}: {:#?}",
        checked.diagnostics.items
    );
    checked.lowered.expect("a model").model
}

fn mesh(model: &Model) -> Mesh {
    let mesh = mesh_model(model, &MeshOptions::default()).expect("meshable");
    sanity_check(&mesh).expect("sane mesh");
    mesh
}

#[test]
fn every_valid_fixture_with_subdomains_is_sane() {
    let mut paths: Vec<_> = std::fs::read_dir("fixtures/valid")
        .expect("fixtures")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|x| x == "xml"))
        .collect();
    paths.sort();
    let mut meshed = 0;
    let mut failures = Vec::new();
    for path in paths {
        let xml = std::fs::read_to_string(&path).expect("readable");
        let name = path.display().to_string();
        let model = model(&name, &xml);
        if model.subdomains.is_empty() {
            continue;
        }
        match mesh_model(&model, &MeshOptions::default()) {
            Ok(mesh) => match sanity_check(&mesh) {
                Ok(()) => meshed += 1,
                Err(e) => failures.push(format!("{name}: {e}")),
            },
            Err(e) => failures.push(format!("{name}: {e}")),
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
    assert!(meshed >= 30, "only {meshed} fixtures meshed");
}

const BALL_IN_BOX: &str = r#"<geometry version="1">
  <parallelepiped name="box"><first_point x="0" y="0" z="0"/><second_point x="4" y="4" z="4"/></parallelepiped>
  <sphere name="ball"><center x="2" y="2" z="2"/><radius value="1"/></sphere>
  <subdomain name="outer"><difference><solid ref="box"/><solid ref="ball"/></difference></subdomain>
  <subdomain name="inner"><solid ref="ball"/></subdomain>
</geometry>"#;

#[test]
fn ball_in_a_box_shares_the_interface_triangles() {
    let model = model("t.xml", BALL_IN_BOX);
    let mesh = mesh(&model);
    let interface = mesh
        .fragments
        .iter()
        .find(|f| f.other.is_some())
        .expect("an interface fragment");
    assert_eq!(interface.faces.len(), 2);
    for &f in &interface.faces {
        let in_outer = mesh.subdomains[0].faces.iter().find(|(id, _)| *id == f);
        let in_inner = mesh.subdomains[1].faces.iter().find(|(id, _)| *id == f);
        // One face, one triangle list, referenced by both subdomains with
        // opposite orientations.
        let (Some(a), Some(b)) = (in_outer, in_inner) else {
            panic!("face {f} is not in both subdomains");
        };
        assert_ne!(a.1, b.1);
        assert!(!mesh.faces[f as usize].triangles.is_empty());
    }
    let q = quality(&mesh);
    let ball = 4.0 / 3.0 * PI;
    assert!((q.subdomains[0].volume - (64.0 - q.subdomains[1].volume)).abs() < 1e-9);
    assert!((q.subdomains[1].volume - ball).abs() <= 4.0 * PI * 4e-3 * 3f64.sqrt());
}

#[test]
fn two_boxes_sharing_a_face_conform() {
    let xml = r#"<geometry version="1">
      <parallelepiped name="a"><first_point x="0" y="0" z="0"/><second_point x="1" y="1" z="1"/></parallelepiped>
      <parallelepiped name="b"><first_point x="1" y="0" z="0"/><second_point x="2" y="1" z="1"/></parallelepiped>
      <subdomain name="A"><solid ref="a"/></subdomain>
      <subdomain name="B"><solid ref="b"/></subdomain>
    </geometry>"#;
    let model = model("t.xml", xml);
    let options = MeshOptions {
        max_edge: Some(0.2),
        ..MeshOptions::default()
    };
    let mesh = mesh_model(&model, &options).expect("meshable");
    sanity_check(&mesh).expect("closed, oriented and conforming");
    let q = quality(&mesh);
    for s in &q.subdomains {
        assert!(
            (s.volume - 1.0).abs() < 1e-9 && (s.area - 6.0).abs() < 1e-9,
            "{s:?}"
        );
    }
    assert!(q.min_angle >= 25.0, "min angle {}", q.min_angle);
    // The shared face's nodes on x = 1 are used by both subdomains' triangles.
    let shared: Vec<u32> = mesh
        .fragments
        .iter()
        .filter(|f| f.other.is_some())
        .flat_map(|f| f.faces.clone())
        .collect();
    assert_eq!(shared.len(), 1);
}

#[test]
fn disk_with_a_hole_has_the_annulus_area() {
    let xml = r#"<geometry version="1" dimension="2">
      <circle name="big"><center x="0" y="0"/><radius value="2"/></circle>
      <circle name="small"><center x="0.5" y="0"/><radius value="0.5"/></circle>
      <subdomain name="ring"><difference><solid ref="big"/><solid ref="small"/></difference></subdomain>
    </geometry>"#;
    let model = model("t.xml", xml);
    for tolerance in [1e-2, 1e-3] {
        let options = MeshOptions {
            tolerance: Tolerance::Absolute(tolerance),
            ..MeshOptions::default()
        };
        let mesh = mesh_model(&model, &options).expect("meshable");
        sanity_check(&mesh).expect("sane");
        let q = quality(&mesh);
        let exact = PI * (4.0 - 0.25);
        let error = (q.subdomains[0].area - exact).abs();
        eprintln!(
            "tol {tolerance}: area {} (err {error:.2e})",
            q.subdomains[0].area
        );
        // Chords cut at most `tolerance` off along both rims.
        assert!(error <= tolerance * 2.0 * PI * 2.5, "area error {error}");
        assert!(q.min_angle >= 25.0, "min angle {}", q.min_angle);
    }
}

#[test]
fn planar_faces_keep_the_minimum_angle() {
    let xml = std::fs::read_to_string("fixtures/valid/2d_disk_in_square.xml").expect("fixture");
    let model = model("2d.xml", &xml);
    let mesh = mesh(&model);
    let q = quality(&mesh);
    assert!(q.min_angle >= 25.0, "min angle {}", q.min_angle);
    let regions: usize = model
        .subdomains
        .iter()
        .filter(|s| matches!(s.cells, SubdomainCells::Region { .. }))
        .count();
    assert_eq!(regions, 2);
    let total: f64 = q.subdomains.iter().map(|s| s.area).sum();
    assert!(
        (total - 16.0).abs() < 1e-9,
        "regions tile the square: {total}"
    );
}

#[test]
fn meshing_is_deterministic() {
    let model = model("t.xml", BALL_IN_BOX);
    let a = mesh_model(&model, &MeshOptions::default()).expect("meshable");
    let b = mesh_model(&model, &MeshOptions::default()).expect("meshable");
    assert_eq!(a, b);
}
