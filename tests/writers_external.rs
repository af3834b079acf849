//! The writers' output judged by independent tools: the Khronos glTF
//! validator (npm `gltf-validator`, through `tests/tools/validate_gltf.js`),
//! gmsh and meshio (through `tests/tools/check_mesh.py`, which also has gmsh
//! tetrahedralize every subdomain) and xmllint with `schema/frag.xsd`.
//! A missing checker fails the test with the hint to run `./scripts/test.sh`.

mod writers_common;

use geomc::formats::{Encoding, WriteOptions};
use serde_json::{Value, json};
use std::path::Path;
use std::process::Command;
use writers_common::*;

fn binary() -> WriteOptions {
    WriteOptions {
        encoding: Some(Encoding::Binary),
        ..WriteOptions::default()
    }
}

fn validate_gltf(path: &Path) {
    let report = run_json("node", "validate_gltf.js", &[path]);
    assert_eq!(
        (report["numErrors"].as_u64(), report["numWarnings"].as_u64()),
        (Some(0), Some(0)),
        "{}: {:#}",
        path.display(),
        report["messages"]
    );
}

#[test]
fn gltf_validator_accepts_every_mesh() {
    let dir = tempfile::tempdir().expect("temp dir");
    for (name, mesh) in [
        ("cube", unit_cube()),
        ("two_cubes", two_cubes()),
        ("split_square", split_square()),
        ("cube_with_probe", cube_with_probe()),
    ] {
        let (glb, _) = write(
            dir.path(),
            &format!("{name}.glb"),
            &mesh,
            &WriteOptions::default(),
        );
        validate_gltf(&glb);
        let (gltf, _) = write(
            dir.path(),
            &format!("{name}.gltf"),
            &mesh,
            &WriteOptions::default(),
        );
        validate_gltf(&gltf);
        // Written to a stream (no file name): the buffer is a data URI.
        let mut embedded = Vec::new();
        let writer = geomc::formats::writer_for_path(Path::new("x.gltf")).expect("gltf writer");
        writer
            .write(&mesh, &WriteOptions::default(), &mut embedded)
            .expect("write");
        let path = dir.path().join(format!("{name}_embedded.gltf"));
        std::fs::write(&path, embedded).expect("write embedded");
        validate_gltf(&path);
    }
}

fn check(path: &Path, tetra: bool) -> Value {
    let flag = Path::new("--tetra");
    let args: Vec<&Path> = if tetra { vec![path, flag] } else { vec![path] };
    run_json("python3", "check_mesh.py", &args)
}

/// (name, dim, element counts) of gmsh's physical groups.
fn gmsh_groups(groups: &Value) -> Vec<(String, u64, Value)> {
    groups
        .as_array()
        .expect("groups")
        .iter()
        .map(|g| {
            (
                g["name"].as_str().expect("name").to_string(),
                g["dim"].as_u64().expect("dim"),
                g["elements"].clone(),
            )
        })
        .collect()
}

#[test]
fn gmsh_and_meshio_read_msh_and_gmsh_fills_every_subdomain() {
    let dir = tempfile::tempdir().expect("temp dir");
    let fragments = vec![
        ("left|exterior".to_string(), 2, json!({"triangle": 10})),
        ("left|right".to_string(), 2, json!({"triangle": 2})),
        ("right|exterior".to_string(), 2, json!({"triangle": 10})),
    ];
    for (file, options) in [
        ("two.msh", WriteOptions::default()),
        ("two_bin.msh", binary()),
    ] {
        let (path, warnings) = write(dir.path(), file, &two_cubes(), &options);
        assert!(warnings.is_empty(), "{warnings:?}");
        let r = check(&path, true);
        let mut expected = fragments.clone();
        expected.push(("left".into(), 3, json!({})));
        expected.push(("right".into(), 3, json!({})));
        assert_eq!(gmsh_groups(&r["gmsh"]["groups"]), expected, "{file}");
        assert_eq!(r["gmsh"]["nodes"], 12);
        assert_eq!(
            r["gmsh"]["entities"],
            json!({"0": 12, "1": 20, "2": 11, "3": 2})
        );
        assert_eq!(
            r["gmsh"]["volume_boundaries"]["2"],
            json!([-2, 7, 8, 9, 10, 11])
        );
        assert_eq!(
            r["meshio"],
            json!({
                "points": 12,
                "cells": {"triangle": 22},
                "cell_sets": {"left|exterior": 10, "left|right": 2, "right|exterior": 10, "left": 0, "right": 0},
            }),
            "{file}"
        );
        // Tetrahedralized: both subdomains filled, the fragments untouched.
        let t = &r["tetra"];
        assert_eq!(t["ok"], true, "{file}: {t}");
        let groups = gmsh_groups(&t["groups"]);
        assert_eq!(
            groups[..3],
            fragments[..],
            "{file}: fragment groups after meshing"
        );
        for (name, tets) in t["tetrahedra"].as_object().expect("tetrahedra") {
            assert!(
                tets.as_u64().unwrap_or(0) > 0,
                "{file}: {name} has no tetrahedra"
            );
        }
        assert_eq!(t["tetrahedra"].as_object().map(|o| o.len()), Some(2));
    }

    let (path, _) = write(
        dir.path(),
        "cube.msh",
        &unit_cube(),
        &WriteOptions::default(),
    );
    let r = check(&path, true);
    assert_eq!(r["tetra"]["ok"], true, "{}", r["tetra"]);
    assert_eq!(
        r["meshio"]["cell_sets"],
        json!({"inlet": 2, "outlet": 2, "walls": 8, "cube": 0})
    );
}

#[test]
fn gmsh_and_meshio_read_2d_regions_and_points_and_lines() {
    let dir = tempfile::tempdir().expect("temp dir");
    for (file, options) in [
        ("square.msh", WriteOptions::default()),
        ("square_bin.msh", binary()),
    ] {
        let (path, _) = write(dir.path(), file, &split_square(), &options);
        let r = check(&path, false);
        assert_eq!(
            gmsh_groups(&r["gmsh"]["groups"]),
            vec![
                ("left|exterior".to_string(), 1, json!({"line": 3})),
                ("left|right".to_string(), 1, json!({"line": 2})),
                ("right|exterior".to_string(), 1, json!({"line": 3})),
                ("left".to_string(), 2, json!({"triangle": 3})),
                ("right".to_string(), 2, json!({"triangle": 3})),
            ],
            "{file}"
        );
        assert_eq!(r["gmsh"]["nodes"], 7);
        assert_eq!(r["meshio"]["cells"], json!({"line": 8, "triangle": 6}));
    }
    let (path, _) = write(dir.path(), "probe.msh", &cube_with_probe(), &binary());
    let r = check(&path, false);
    assert_eq!(r["gmsh"]["nodes"], 13);
    assert_eq!(
        r["meshio"]["cell_sets"],
        json!({"inlet": 2, "outlet": 2, "walls": 8, "cube": 0, "probe": 2, "sensors": 2})
    );
    assert_eq!(
        r["meshio"]["cells"],
        json!({"vertex": 2, "line": 2, "triangle": 12})
    );
}

#[test]
fn meshio_reads_vtu_with_its_id_fields() {
    let dir = tempfile::tempdir().expect("temp dir");
    for (file, options) in [
        ("two.vtu", WriteOptions::default()),
        ("two_bin.vtu", binary()),
    ] {
        let (path, _) = write(dir.path(), file, &two_cubes(), &options);
        let r = check(&path, false);
        let m = &r["meshio"];
        assert_eq!(m["points"], 12, "{file}");
        assert_eq!(m["cells"], json!({"triangle": 22, "line": 20}), "{file}");
        assert_eq!(
            m["cell_data"]["fragment_id"],
            json!([-1, 0, 1, 2]),
            "{file}"
        );
        assert_eq!(m["cell_data"]["subdomain_id"], json!([-1, 0, 1]), "{file}");
        assert_eq!(
            m["cell_data"]["other_subdomain_id"],
            json!([-1, 1]),
            "{file}"
        );
        assert_eq!(
            m["cell_data"]["face_id"].as_array().map(Vec::len),
            Some(12),
            "{file}"
        );
    }
    let (path, _) = write(dir.path(), "square.vtu", &split_square(), &binary());
    let m = &check(&path, false)["meshio"];
    assert_eq!(m["cells"], json!({"triangle": 6, "line": 8}));
    assert_eq!(m["cell_data"]["subdomain_id"], json!([0, 1]));
}

#[test]
fn xmllint_accepts_frag_xml_against_the_schema() {
    let dir = tempfile::tempdir().expect("temp dir");
    let schema = root().join("schema").join("frag.xsd");
    let options = WriteOptions {
        mesh_file: Some("mesh.msh".into()),
        ..WriteOptions::default()
    };
    for (name, mesh) in [
        ("cube", unit_cube()),
        ("two_cubes", two_cubes()),
        ("split_square", split_square()),
        ("cube_with_probe", cube_with_probe()),
    ] {
        let (path, _) = write(dir.path(), &format!("{name}.frag.xml"), &mesh, &options);
        let output = Command::new("xmllint")
            .args(["--noout", "--nonet", "--schema"])
            .arg(&schema)
            .arg(&path)
            .output()
            .unwrap_or_else(|e| {
                panic!("cannot run xmllint: {e}; run ./scripts/test.sh, which installs it")
            });
        assert!(
            output.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&output.stderr)
        );
    }
}
