//! `geomc inspect MODEL.rfs`: the polygonized surface reported like a mesh
//! file, and a broken program refused with its located code.

use std::process::Command;

fn geomc(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_geomc"))
        .args(args)
        .output()
        .expect("geomc runs")
}

#[test]
fn inspect_reports_the_seven_balls_surface_as_closed() {
    let out = geomc(&[
        "inspect",
        "fixtures/rfs/seven_balls.rfs",
        "--format",
        "json",
    ]);
    assert_eq!(out.status.code(), Some(0));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).expect("json report");
    assert_eq!(json["format"], "rfs");
    assert_eq!(json["watertight"], true);
    assert_eq!(json["open_edges"], 0);
    assert_eq!(json["non_manifold_edges"], 0);
    assert_eq!(json["inconsistent_edges"], 0);
    // A closed triangle surface has 3T = 2E, and the seven balls' union is one
    // sphere-like shell: V − E + T = 2.
    let (v, e, t) = (
        json["nodes"].as_i64().expect("nodes"),
        json["edges"].as_i64().expect("edges"),
        json["triangles"].as_i64().expect("triangles"),
    );
    assert!(t > 1000, "{t} triangles on the 20³ grid");
    assert_eq!(3 * t, 2 * e);
    assert_eq!(v - e + t, 2);
    assert_eq!(json["subdomains"][0], "balls");
    assert_eq!(json["groups"][0]["name"], "balls_boundary");
    // The Geom box is [-1, 1]³ and the balls reach every face of it.
    assert_eq!(json["bounding_box"][0][0].as_f64(), Some(-1.0));
    assert_eq!(json["bounding_box"][1][2].as_f64(), Some(1.0));
}

#[test]
fn inspect_refuses_a_broken_program_with_its_location() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("bad.rfs");
    std::fs::write(&path, "function f(x,y,z) { return 1 - ; }").expect("write");
    let out = geomc(&["inspect", path.to_str().expect("utf-8 path")]);
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("bad.rfs:1:32: error[E600]"), "{stderr}");
    assert!(out.stdout.is_empty());
}

#[test]
fn a_section_plane_outside_the_box_is_warned_with_its_code_and_the_file_still_written() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out_path = dir.path().join("balls.stl");
    let out = geomc(&[
        "compile",
        "fixtures/rfs/seven_balls.rfs",
        "-o",
        out_path.to_str().expect("utf-8 path"),
        "--section",
        "z=5",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    assert!(
        stderr.contains("warning[W133]: the section plane does not cut the surface of 'balls'"),
        "{stderr}"
    );
    assert!(stderr.contains("move the --section plane"), "{stderr}");
    assert!(out_path.exists());
}
