//! `geomc inspect --mesh` and the exact measures behind it: exact volumes and
//! areas of primitives and boolean subdomains against closed forms, a box
//! meshed with zero error, curved solids within the tolerance bound, the
//! text and JSON reports, and E501 for bad meshing options.

use geomc::driver::{Options, check_source};
use geomc::ir::Model;
use geomc::meshing::exact::subdomain_measures;
use geomc::meshing::{MeshOptions, MeshReport, Tolerance, mesh_model};
use geomc::span::SourceFile;
use std::f64::consts::PI;
use std::path::Path;
use std::process::Command;

fn model(xml: &str) -> Model {
    let checked = check_source(SourceFile::new("t.xml", xml), &Options::default());
    assert!(checked.is_valid(), "{:#?}", checked.diagnostics.items);
    checked.lowered.expect("a model").model
}

fn solid(shape: &str) -> String {
    format!(
        r#"<geometry version="1">{shape}<subdomain name="s"><solid ref="a"/></subdomain></geometry>"#
    )
}

fn report(model: &Model, tolerance: f64) -> MeshReport {
    let options = MeshOptions {
        tolerance: Tolerance::Absolute(tolerance),
        ..MeshOptions::default()
    };
    let mesh = mesh_model(model, &options).expect("meshable");
    MeshReport::of(model, &mesh, tolerance, None, options.min_angle_degrees)
}

fn close(a: f64, b: f64, relative: f64) -> bool {
    (a - b).abs() <= relative * b.abs().max(1e-300)
}

/// (volume, area) of the only subdomain, exactly.
fn exact(xml: &str) -> (f64, f64) {
    let m = subdomain_measures(&model(xml))[0].expect("an exact measure");
    (m.volume, m.area)
}

#[test]
fn exact_measures_of_primitives_match_closed_forms() {
    // A ball away from the origin: the hemispheres' fluxes differ, so their
    // sides must be told apart correctly.
    let (v, a) = exact(&solid(
        r#"<sphere name="a"><center x="3" y="-2" z="5"/><radius value="1.5"/></sphere>"#,
    ));
    assert!(close(v, 4.0 / 3.0 * PI * 1.5f64.powi(3), 1e-12), "{v}");
    assert!(close(a, 4.0 * PI * 2.25, 1e-12), "{a}");

    let (v, a) = exact(&solid(
        r#"<parallelepiped name="a"><first_point x="1" y="1" z="1"/><second_point x="2" y="3" z="4"/></parallelepiped>"#,
    ));
    assert!(close(v, 6.0, 1e-14) && close(a, 22.0, 1e-14), "{v} {a}");

    let (r0, r1, h): (f64, f64, f64) = (1.0, 0.5, 2.0);
    let (v, a) = exact(&solid(
        r#"<truncated_cone name="a"><bottom_center x="1" y="0" z="-1"/><top_center x="1" y="0" z="1"/><bottom_radius value="1"/><top_radius value="0.5"/></truncated_cone>"#,
    ));
    let slant = (h * h + (r0 - r1).powi(2)).sqrt();
    assert!(
        close(v, PI * h / 3.0 * (r0 * r0 + r0 * r1 + r1 * r1), 1e-12),
        "{v}"
    );
    assert!(
        close(a, PI * (r0 + r1) * slant + PI * (r0 * r0 + r1 * r1), 1e-12),
        "{a}"
    );

    // A full cone: its apex has no cap.
    let (v, a) = exact(&solid(
        r#"<truncated_cone name="a"><bottom_center x="0" y="0" z="0"/><top_center x="0" y="0" z="2"/><bottom_radius value="1"/><top_radius value="0"/></truncated_cone>"#,
    ));
    assert!(close(v, PI * 2.0 / 3.0, 1e-12) && close(a, PI * 5f64.sqrt() + PI, 1e-12));

    let (v, a) = exact(&solid(
        r#"<torus name="a"><center x="0" y="1" z="0"/><major_radius value="2"/><minor_radius value="0.5"/></torus>"#,
    ));
    assert!(close(v, 2.0 * PI * PI * 2.0 * 0.25, 1e-12), "{v}");
    assert!(close(a, 4.0 * PI * PI * 2.0 * 0.5, 1e-12), "{a}");

    // An ellipsoid's area has no elementary closed form; a prolate spheroid's does.
    let (v, a) = exact(&solid(
        r#"<ellipsoid name="a"><center x="0" y="0" z="1"/><semi_axes x="1" y="1" z="2"/></ellipsoid>"#,
    ));
    let e = (1.0f64 - 1.0 / 4.0).sqrt();
    let spheroid = 2.0 * PI * (1.0 + 2.0 / e * e.asin());
    assert!(close(v, 4.0 / 3.0 * PI * 2.0, 1e-12), "{v}");
    assert!(close(a, spheroid, 1e-12), "{a} vs {spheroid}");
}

#[test]
fn hemispheres_are_told_apart() {
    // Unit ball at z = 5: ⅓∫x·n dA is (5π + 2π)/3 over the north half and
    // (−5π + 2π)/3 over the south half.
    let m = model(&solid(
        r#"<sphere name="a"><center x="0" y="0" z="5"/><radius value="1"/></sphere>"#,
    ));
    let faces = geomc::meshing::exact::face_measures(&m);
    for (face, measure) in m.faces.iter().zip(&faces) {
        let measure = measure.expect("exact");
        let expected = match face.name.to_string().as_str() {
            "a.north" => 7.0 * PI / 3.0,
            "a.south" => -PI,
            other => panic!("unexpected face {other}"),
        };
        assert!(
            close(measure.flux, expected, 1e-12),
            "{}: {}",
            face.name,
            measure.flux
        );
        assert!(close(measure.area, 2.0 * PI, 1e-12));
    }
}

#[test]
fn exact_measures_follow_booleans_rotations_and_2d() {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/ball_in_box.xml"),
    )
    .expect("example");
    let measures = subdomain_measures(&model(&text));
    let (matrix, inclusion) = (measures[0].expect("matrix"), measures[1].expect("ball"));
    assert!(close(matrix.volume, 64.0 - 4.0 / 3.0 * PI, 1e-12));
    assert!(close(matrix.area, 96.0 + 4.0 * PI, 1e-12));
    assert!(close(inclusion.volume, 4.0 / 3.0 * PI, 1e-12));

    let rotated = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/valid/coordinate_system_rotated.xml"),
    )
    .expect("fixture");
    let measures = subdomain_measures(&model(&rotated));
    let ring = measures[0].expect("torus");
    assert!(close(ring.volume, 2.0 * PI * PI * 2.0 * 0.25, 1e-12));
    let peg = measures[1].expect("cone");
    let (r0, r1) = (0.25f64, 0.1f64);
    assert!(close(
        peg.volume,
        PI / 3.0 * (r0 * r0 + r0 * r1 + r1 * r1),
        1e-12
    ));

    let disk = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/valid/2d_disk_in_square.xml"),
    )
    .expect("fixture");
    let measures = subdomain_measures(&model(&disk));
    assert!(close(measures[0].expect("outer").area, 16.0 - PI, 1e-12));
    assert!(close(measures[1].expect("inner").area, PI, 1e-12));

    // An explicit face on a cylinder has no exact measure, so neither has its subdomain.
    let half = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/valid/explicit_half_cylinder.xml"),
    )
    .expect("fixture");
    assert_eq!(subdomain_measures(&model(&half)), vec![None]);
}

#[test]
fn a_box_is_meshed_exactly() {
    let m = model(&solid(
        r#"<parallelepiped name="a"><first_point x="0" y="0" z="0"/><second_point x="1" y="1" z="1"/></parallelepiped>"#,
    ));
    let r = report(&m, 1e-3);
    assert_eq!((r.nodes, r.triangles, r.edge_segments), (8, 12, 12));
    // Right isosceles triangles: 45° smallest angle, aspect (√2)/(2√3·r) with r = (2 − √2)/2.
    assert_eq!(r.min_angle_histogram[9], 12);
    assert!((r.min_angle - 45.0).abs() < 1e-9);
    let aspect = 2f64.sqrt() / (3f64.sqrt() * (2.0 - 2f64.sqrt()));
    assert!((r.max_aspect_ratio - aspect).abs() < 1e-12);
    assert!((r.mean_aspect_ratio - aspect).abs() < 1e-12);
    let s = &r.subdomains[0];
    assert_eq!(s.triangles, 12);
    assert_eq!((s.exact_volume, s.exact_area), (Some(1.0), Some(6.0)));
    assert!(s.volume_error.expect("exact") < 1e-15);
    assert!(s.area_error.expect("exact") < 1e-15);
}

#[test]
fn a_ball_stays_within_the_tolerance_bound() {
    let m = model(&solid(
        r#"<sphere name="a"><center x="1" y="2" z="3"/><radius value="1"/></sphere>"#,
    ));
    let mut last = (f64::INFINITY, f64::INFINITY);
    for tolerance in [0.01, 0.0025] {
        let r = report(&m, tolerance);
        let s = &r.subdomains[0];
        let (dv, da) = (s.volume_error.expect("exact"), s.area_error.expect("exact"));
        // Bound: tolerance · area / volume = 3 · tolerance for the unit ball.
        assert!(close(
            s.volume_bound.expect("bound"),
            3.0 * tolerance,
            1e-12
        ));
        assert!(dv > 0.0 && dv <= 3.0 * tolerance, "volume error {dv}");
        // Inscribed triangles lose area; at most 2·tolerance/radius of it.
        assert!(da > 0.0 && da <= 2.0 * tolerance, "area error {da}");
        assert!(s.mesh_volume.expect("3D") < s.exact_volume.expect("exact"));
        assert!(dv < last.0 && da < last.1);
        last = (dv, da);
        assert_eq!(r.triangles, s.triangles);
        assert_eq!(r.min_angle_histogram.iter().sum::<usize>(), r.triangles);
        assert!(r.min_angle >= 20.0 && r.min_angle == s.min_angle);
        // Closed surface of genus 0: V − E + F = 2 with E = 3F/2.
        assert_eq!(r.nodes as i64 - r.triangles as i64 / 2, 2);
    }
}

fn geomc(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_geomc"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("geomc runs")
}

#[test]
fn inspect_mesh_prints_text_and_json() {
    let out = geomc(&["inspect", "--mesh", "examples/ball_in_box.xml"]);
    assert_eq!(out.status.code(), Some(0));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("mesh: tolerance 0.00692820323  max edge none"),
        "{text}"
    );
    assert!(
        text.contains("subdomains (mesh | exact | relative error):"),
        "{text}"
    );
    assert!(text.contains("    area   "), "{text}");
    assert!(text.contains("| 4.188790205 |"), "{text}");

    let out = geomc(&[
        "inspect",
        "--mesh",
        "--format",
        "json",
        "--tolerance",
        "0.02",
        "--max-edge",
        "1",
        "examples/ball_in_box.xml",
    ]);
    assert_eq!(out.status.code(), Some(0));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON");
    assert_eq!(json["vertices"], 9);
    let mesh = &json["mesh"];
    assert_eq!(mesh["tolerance"], 0.02);
    assert_eq!(mesh["max_edge"], 1.0);
    let subs = mesh["subdomains"].as_array().expect("subdomains");
    assert_eq!(subs.len(), 2);
    assert_eq!(subs[1]["name"], "inclusion");
    let exact = subs[1]["exact_volume"].as_f64().expect("number");
    assert!(close(exact, 4.0 / 3.0 * PI, 1e-12));
    let error = subs[1]["volume_error"].as_f64().expect("number");
    let bound = subs[1]["volume_bound"].as_f64().expect("number");
    assert!(error > 0.0 && error <= bound, "{error} {bound}");
    let histogram = mesh["min_angle_histogram"].as_array().expect("bins");
    assert_eq!(histogram.len(), 12);
    let total: u64 = histogram.iter().filter_map(|v| v.as_u64()).sum();
    assert_eq!(total, mesh["triangles"].as_u64().expect("count"));
}

#[test]
fn bad_meshing_options_are_e501_naming_the_value() {
    for (options, named) in [
        (vec!["--tolerance", "0"], "--tolerance 0:"),
        (vec!["--tolerance", "-0.5"], "--tolerance -0.5:"),
        (vec!["--tolerance", "NaN"], "--tolerance NaN:"),
        (vec!["--tolerance", "0%"], "--tolerance 0%:"),
        (vec!["--tolerance", "abc"], "--tolerance abc:"),
        (vec!["--max-edge", "0"], "--max-edge 0:"),
        (vec!["--max-edge", "-2"], "--max-edge -2:"),
        (vec!["--min-angle", "40"], "--min-angle 40:"),
    ] {
        for command in ["inspect", "compile"] {
            let mut args = vec![command, "examples/ball_in_box.xml"];
            args.extend(&options);
            if command == "inspect" {
                args.push("--mesh");
            } else {
                args.extend(["-o", "/nonexistent-geomc-dir/never.msh"]);
            }
            let out = geomc(&args);
            let stderr = String::from_utf8_lossy(&out.stderr);
            assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
            assert!(stderr.contains("error[E501]"), "{args:?}: {stderr}");
            assert!(stderr.contains(named), "{args:?}: {stderr}");
            assert!(!stderr.contains("internal error"), "{stderr}");
        }
    }
}

#[test]
fn e500_to_e503_are_explained() {
    for code in ["E500", "E501", "E502", "E503"] {
        let out = geomc(&["explain", code]);
        assert_eq!(out.status.code(), Some(0), "{code}");
        assert!(String::from_utf8_lossy(&out.stdout).contains(code));
    }
}

/// Paper 002's figure 5 through the CLI: per trimmed surface, the minimum
/// angle distribution and the largest centroid-to-surface distance.
#[test]
fn inspect_mesh_reports_trimmed_angles_and_centroid_distance() {
    let out = geomc(&[
        "inspect",
        "--mesh",
        "--format",
        "json",
        "fixtures/valid/trimmed_bezier_hole.xml",
    ]);
    assert_eq!(out.status.code(), Some(0));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON");
    let mesh = &json["mesh"];
    let tolerance = mesh["tolerance"].as_f64().expect("tolerance");
    let target = mesh["min_angle_target"].as_f64().expect("target");
    let trimmed = mesh["trimmed"].as_array().expect("trimmed surfaces");
    assert_eq!(trimmed.len(), 1);
    let panel = &trimmed[0];
    assert_eq!(panel["name"], "panel");
    // The panel is the only face: its triangles are the mesh's.
    let triangles = panel["triangles"].as_u64().expect("count");
    assert_eq!(triangles, mesh["triangles"].as_u64().expect("count"));
    let bins: Vec<u64> = panel["min_angle_histogram"]
        .as_array()
        .expect("bins")
        .iter()
        .filter_map(|v| v.as_u64())
        .collect();
    assert_eq!(bins.len(), 12);
    assert_eq!(bins.iter().sum::<u64>(), triangles);
    // No input angle is small here: nothing under the 25° target, and the
    // smallest angle lies in the first non-empty 5° bin.
    let min_angle = panel["min_angle"].as_f64().expect("angle");
    assert_eq!(target, 25.0);
    assert!(min_angle >= target, "{min_angle}");
    assert!(bins[..5].iter().all(|&n| n == 0), "{bins:?}");
    let first = bins.iter().position(|&n| n > 0).expect("a bin") as f64;
    assert!((5.0 * first..5.0 * first + 5.0).contains(&min_angle));
    let distance = panel["max_centroid_distance"].as_f64().expect("distance");
    assert!(
        distance > 0.0 && distance <= tolerance,
        "{distance} {tolerance}"
    );
}
