//! Meshes of primitive solids built through the real front end: exact
//! measures for boxes, convergence of volumes and areas for curved solids as
//! the tolerance shrinks, conformity of shared faces, and determinism.

use geomc::driver::{Options, check_source};
use geomc::ir::Model;
use geomc::mesh::Mesh;
use geomc::meshing::{MeshOptions, Quality, Tolerance, mesh_model, quality, sanity_check};
use geomc::span::SourceFile;
use std::f64::consts::PI;

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
    sanity_check(&mesh).expect("sane mesh");
    let q = quality(&mesh);
    (mesh, q)
}

fn solid(shape: &str) -> String {
    format!(
        r#"<geometry version="1">{shape}<subdomain name="s"><solid ref="a"/></subdomain></geometry>"#
    )
}

/// Volume and area errors at tolerances 0.02, 0.005, 0.00125: each must
/// shrink and stay within area · tolerance (volume) and a multiple of it (area).
fn converges(xml: &str, volume: f64, area: f64) -> Vec<(f64, f64, f64)> {
    let model = model(xml);
    let mut errors = Vec::new();
    for tolerance in [0.02, 0.005, 0.00125] {
        let (_, q) = mesh(&model, tolerance);
        let s = &q.subdomains[0];
        let (dv, da) = ((s.volume - volume).abs(), (s.area - area).abs());
        eprintln!(
            "tol {tolerance}: volume {} (err {dv:.2e}), area {} (err {da:.2e})",
            s.volume, s.area
        );
        assert!(
            dv <= area * tolerance,
            "volume error {dv} at tolerance {tolerance}"
        );
        assert!(
            da <= 4.0 * area * tolerance,
            "area error {da} at tolerance {tolerance}"
        );
        errors.push((tolerance, dv, da));
    }
    for w in errors.windows(2) {
        assert!(
            w[1].1 < w[0].1 && w[1].2 < w[0].2,
            "errors must decrease: {errors:?}"
        );
    }
    errors
}

#[test]
fn cube_is_exact_with_eight_nodes() {
    let m = model(&solid(
        r#"<parallelepiped name="a"><first_point x="0" y="0" z="0"/><second_point x="1" y="1" z="1"/></parallelepiped>"#,
    ));
    let (mesh, q) = mesh(&m, 1e-3);
    assert_eq!(mesh.nodes.len(), 8);
    assert_eq!(
        mesh.faces.iter().map(|f| f.triangles.len()).sum::<usize>(),
        12
    );
    assert!((q.subdomains[0].volume - 1.0).abs() < 1e-12);
    assert!((q.subdomains[0].area - 6.0).abs() < 1e-12);
    assert!(q.min_angle >= 25.0);
}

#[test]
fn long_box_adds_nodes_only_for_angles() {
    // A 1×3 rectangle cut once has 18.4° angles, so its long edges are split
    // (and the splits shared with the neighbouring faces).
    let m = model(&solid(
        r#"<parallelepiped name="a"><first_point x="0" y="0" z="0"/><second_point x="1" y="2" z="3"/></parallelepiped>"#,
    ));
    let (mesh, q) = mesh(&m, 1e-3);
    assert!(mesh.nodes.len() > 8);
    assert!((q.subdomains[0].volume - 6.0).abs() < 1e-12);
    assert!((q.subdomains[0].area - 22.0).abs() < 1e-12);
    assert!(q.min_angle >= 25.0, "min angle {}", q.min_angle);
}

#[test]
fn box_with_max_edge_keeps_planar_faces_and_angles() {
    let m = model(&solid(
        r#"<parallelepiped name="a"><first_point x="0" y="0" z="0"/><second_point x="1" y="2" z="3"/></parallelepiped>"#,
    ));
    let options = MeshOptions {
        max_edge: Some(0.3),
        ..MeshOptions::default()
    };
    let mesh = mesh_model(&m, &options).expect("meshable");
    sanity_check(&mesh).expect("sane");
    let q = quality(&mesh);
    assert!((q.subdomains[0].volume - 6.0).abs() < 1e-9);
    assert!((q.subdomains[0].area - 22.0).abs() < 1e-9);
    assert!(q.min_angle >= 25.0, "min angle {}", q.min_angle);
    // Every triangle lies in its face's plane: one coordinate is 0 or the side length.
    for face in &mesh.faces {
        let first = mesh.nodes[face.triangles[0][0] as usize];
        let axis = (0..3)
            .find(|&k| {
                face.triangles
                    .iter()
                    .flatten()
                    .all(|&i| mesh.nodes[i as usize][k] == first[k])
            })
            .expect("a planar face");
        assert!([0.0, 1.0, 2.0, 3.0].contains(&first[axis]));
        for t in &face.triangles {
            for k in 0..3 {
                let (p, q) = (
                    mesh.nodes[t[k] as usize],
                    mesh.nodes[t[(k + 1) % 3] as usize],
                );
                let length = (0..3).map(|c| (p[c] - q[c]).powi(2)).sum::<f64>().sqrt();
                assert!(length <= 0.3 + 1e-9, "edge of length {length}");
            }
        }
    }
}

const BALL: &str = r#"<sphere name="a"><center x="0" y="0" z="0"/><radius value="1"/></sphere>"#;

#[test]
fn ball_volume_and_area_converge() {
    converges(&solid(BALL), 4.0 / 3.0 * PI, 4.0 * PI);
}

#[test]
fn cylinder_volume_and_area_converge() {
    let xml = solid(
        r#"<truncated_cone name="a"><bottom_center x="0" y="0" z="0"/><top_center x="0" y="0" z="2"/><bottom_radius value="1"/><top_radius value="1"/></truncated_cone>"#,
    );
    converges(&xml, 2.0 * PI, 2.0 * PI + 4.0 * PI);
}

#[test]
fn cone_frustum_volume_and_area_converge() {
    let (r0, r1, h): (f64, f64, f64) = (1.0, 0.5, 2.0);
    let xml = solid(
        r#"<truncated_cone name="a"><bottom_center x="0" y="0" z="0"/><top_center x="0" y="0" z="2"/><bottom_radius value="1"/><top_radius value="0.5"/></truncated_cone>"#,
    );
    let volume = PI * h / 3.0 * (r0 * r0 + r0 * r1 + r1 * r1);
    let slant = (h * h + (r0 - r1).powi(2)).sqrt();
    let area = PI * (r0 + r1) * slant + PI * (r0 * r0 + r1 * r1);
    converges(&xml, volume, area);
}

#[test]
fn full_cone_with_apex_converges() {
    let xml = solid(
        r#"<truncated_cone name="a"><bottom_center x="0" y="0" z="0"/><top_center x="0" y="0" z="2"/><bottom_radius value="1"/><top_radius value="0"/></truncated_cone>"#,
    );
    let slant = 5f64.sqrt();
    converges(&xml, PI * 2.0 / 3.0, PI * slant + PI);
}

#[test]
fn torus_volume_and_area_converge() {
    let xml = solid(
        r#"<torus name="a"><center x="0" y="0" z="0"/><major_radius value="2"/><minor_radius value="0.5"/></torus>"#,
    );
    converges(&xml, 2.0 * PI * PI * 2.0 * 0.25, 4.0 * PI * PI * 2.0 * 0.5);
}

#[test]
fn ellipsoid_volume_converges() {
    let xml = solid(
        r#"<ellipsoid name="a"><center x="0" y="0" z="0"/><semi_axes x="2" y="1" z="0.5"/></ellipsoid>"#,
    );
    // Knud Thomsen's approximation of the area (±1 %) bounds only the volume test's slack.
    let (a, b, c): (f64, f64, f64) = (2.0, 1.0, 0.5);
    let p = 1.6075;
    let area =
        4.0 * PI * (((a * b).powf(p) + (a * c).powf(p) + (b * c).powf(p)) / 3.0).powf(1.0 / p);
    let m = model(&xml);
    let mut last = f64::INFINITY;
    for tolerance in [0.02, 0.005, 0.00125] {
        let (_, q) = mesh(&m, tolerance);
        let dv = (q.subdomains[0].volume - 4.0 / 3.0 * PI * a * b * c).abs();
        eprintln!("tol {tolerance}: volume err {dv:.2e}");
        assert!(dv <= 1.1 * area * tolerance && dv < last);
        last = dv;
    }
}

#[test]
fn curved_faces_keep_reasonable_angles() {
    // Conformal charts carry the plane's Delaunay angles onto the surface
    // up to the distortion across one triangle.
    let shapes = [
        BALL.to_string(),
        r#"<torus name="a"><center x="0" y="0" z="0"/><major_radius value="2"/><minor_radius value="0.5"/></torus>"#.to_string(),
        r#"<truncated_cone name="a"><bottom_center x="0" y="0" z="0"/><top_center x="0" y="0" z="2"/><bottom_radius value="1"/><top_radius value="0.5"/></truncated_cone>"#.to_string(),
    ];
    for shape in shapes {
        let (mesh, q) = mesh(&model(&solid(&shape)), 0.005);
        let triangles: usize = mesh.faces.iter().map(|f| f.triangles.len()).sum();
        eprintln!(
            "{} triangles, min angle {:.1}°, max aspect {:.2}, histogram {:?}",
            triangles, q.min_angle, q.max_aspect_ratio, q.min_angle_histogram
        );
        assert!(q.min_angle >= 20.0, "min angle {}", q.min_angle);
    }
}

#[test]
fn sanity_check_finds_holes_and_flips() {
    let m = model(&solid(BALL));
    let (mesh, _) = mesh(&m, 0.02);
    let mut open = mesh.clone();
    open.faces[0].triangles.pop();
    assert!(sanity_check(&open).is_err());
    let mut flipped = mesh.clone();
    if let Some(t) = flipped.faces[0].triangles.first_mut() {
        t.swap(1, 2);
    }
    assert!(sanity_check(&flipped).is_err());
    let mut out_of_range = mesh;
    out_of_range.faces[1].triangles[0][0] = u32::MAX;
    assert!(sanity_check(&out_of_range).is_err());
}

#[test]
fn bad_options_are_errors_not_panics() {
    let m = model(&solid(BALL));
    for options in [
        MeshOptions {
            tolerance: Tolerance::Absolute(0.0),
            ..MeshOptions::default()
        },
        MeshOptions {
            max_edge: Some(-1.0),
            ..MeshOptions::default()
        },
        MeshOptions {
            min_angle_degrees: 45.0,
            ..MeshOptions::default()
        },
    ] {
        assert!(mesh_model(&m, &options).is_err(), "{options:?}");
    }
}
