//! `geomc compile` end to end: every valid fixture to every format, a
//! committed golden set checked byte for byte and by the real readers (the
//! Khronos glTF validator, gmsh with tetrahedralization, meshio), determinism
//! across thread counts, and a failing input that leaves no output behind.
//! Regenerate the golden set with `GEOMC_BLESS=1 cargo test --test compile`.

mod writers_common;

use geomc::driver::{Options, check_file};
use geomc::formats::{WRITERS, WriteOptions, write_mesh_file};
use geomc::meshing::{MeshOptions, mesh_model, sanity_check};
use std::path::{Path, PathBuf};
use std::process::Command;
use writers_common::run_json;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn valid_fixtures() -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(root().join("fixtures/valid"))
        .expect("fixtures")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "xml"))
        .collect();
    files.sort();
    files
}

fn geomc(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_geomc"))
        .args(args)
        .current_dir(root())
        .output()
        .expect("geomc runs")
}

#[test]
fn every_valid_fixture_compiles_to_every_format() {
    let dir = tempfile::tempdir().expect("temporary folder");
    let mut failures = Vec::new();
    for path in valid_fixtures() {
        let checked = check_file(&path, &Options::default()).expect("readable");
        let model = &checked.lowered.expect("a model").model;
        let mesh = match mesh_model(model, &MeshOptions::default()) {
            Ok(mesh) => mesh,
            Err(e) => {
                failures.push(format!("{}: {e}", path.display()));
                continue;
            }
        };
        if !mesh.subdomains.is_empty()
            && let Err(e) = sanity_check(&mesh)
        {
            failures.push(format!("{}: {e}", path.display()));
        }
        let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or("x");
        // Writers reached by file ending (MSH 2.2 only by name, `--to msh22`).
        for writer in WRITERS.iter().filter(|w| !w.extensions().is_empty()) {
            let out = dir
                .path()
                .join(format!("{stem}.{}", writer.extensions()[0]));
            if let Err(e) = write_mesh_file(&out, &mesh, &WriteOptions::default()) {
                failures.push(format!("{} → {}: {e}", path.display(), out.display()));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The golden set: inputs and the formats each is compiled to.
const GOLDEN: &[(&str, &[&str])] = &[
    (
        "examples/ball_in_box.xml",
        &["msh", "glb", "obj", "vtu", "frag.xml"],
    ),
    (
        "fixtures/valid/subdomain_shared_face.xml",
        &["msh", "gltf", "stl"],
    ),
    ("fixtures/valid/2d_disk_in_square.xml", &["msh", "glb"]),
];

#[test]
fn golden_outputs_are_unchanged_and_accepted_by_external_readers() {
    let bless = std::env::var_os("GEOMC_BLESS").is_some();
    let dir = tempfile::tempdir().expect("temporary folder");
    let mut changed = Vec::new();
    for (input, formats) in GOLDEN {
        let stem = Path::new(input)
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or("x");
        let mut args = vec!["compile".to_string(), input.to_string(), "-q".to_string()];
        for f in *formats {
            args.push("-o".into());
            args.push(dir.path().join(format!("{stem}.{f}")).display().to_string());
        }
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let out = geomc(&args);
        assert_eq!(
            out.status.code(),
            Some(0),
            "{input}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let mut written: Vec<PathBuf> = std::fs::read_dir(dir.path())
            .expect("outputs")
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| {
                p.file_name()
                    .and_then(|n| n.to_str())
                    .is_some_and(|n| n.starts_with(&format!("{stem}.")))
            })
            .collect();
        written.sort();
        for file in written {
            let name = file
                .file_name()
                .and_then(|n| n.to_str())
                .unwrap_or_default()
                .to_string();
            let golden = root().join("tests/golden").join(&name);
            let bytes = std::fs::read(&file).expect("output");
            if bless {
                std::fs::write(&golden, &bytes).expect("bless");
            } else if std::fs::read(&golden).ok().as_deref() != Some(bytes.as_slice()) {
                changed.push(name.clone());
            }
            match name.rsplit('.').next() {
                Some("glb") | Some("gltf") => {
                    let report = run_json("node", "validate_gltf.js", &[&file]);
                    assert_eq!(
                        (report["numErrors"].as_u64(), report["numWarnings"].as_u64()),
                        (Some(0), Some(0)),
                        "{name}: {report}"
                    );
                }
                Some("msh") => {
                    let report =
                        run_json("python3", "check_mesh.py", &[&file, Path::new("--tetra")]);
                    assert_eq!(
                        report["meshio"]["points"], report["gmsh"]["nodes"],
                        "{name}: {report}"
                    );
                    let groups = report["gmsh"]["groups"]
                        .as_array()
                        .cloned()
                        .unwrap_or_default();
                    assert!(!groups.is_empty(), "{name}: no physical groups");
                    if let Some(tetra) = report["tetra"]["tetrahedra"].as_object() {
                        for (volume, n) in tetra {
                            assert!(
                                n.as_u64().unwrap_or(0) > 0,
                                "{name}: gmsh left volume {volume} empty: {report}"
                            );
                        }
                    }
                }
                _ => {}
            }
        }
    }
    assert!(
        changed.is_empty(),
        "golden outputs changed: {changed:?}; review and bless with GEOMC_BLESS=1"
    );
}

#[test]
fn outputs_are_identical_across_runs_and_thread_counts() {
    let inputs = [
        "examples/ball_in_box.xml",
        "fixtures/valid/torus.xml",
        "fixtures/valid/subdomain_union_disjoint.xml",
        "fixtures/valid/2d_circle.xml",
    ];
    let mut folders = Vec::new();
    for jobs in ["1", "2", "2"] {
        let dir = tempfile::tempdir().expect("temporary folder");
        let target = format!("{}/", dir.path().display());
        let mut args = vec![
            "compile", "-q", "-j", jobs, "-o", &target, "--to", "msh", "--to", "glb", "--to",
            "frag.xml",
        ];
        args.extend(inputs);
        let out = geomc(&args);
        assert_eq!(
            out.status.code(),
            Some(0),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        folders.push(dir);
    }
    let listing = |dir: &Path| -> Vec<(String, Vec<u8>)> {
        let mut files: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
            .expect("folder")
            .filter_map(|e| e.ok())
            .map(|e| {
                (
                    e.file_name().to_string_lossy().into_owned(),
                    std::fs::read(e.path()).expect("read"),
                )
            })
            .collect();
        files.sort();
        files
    };
    let first = listing(folders[0].path());
    assert_eq!(first.len(), inputs.len() * 3);
    for other in &folders[1..] {
        assert!(
            listing(other.path()) == first,
            "outputs differ between runs"
        );
    }
}

#[test]
fn a_failing_input_does_not_stop_the_others_and_leaves_no_output() {
    let dir = tempfile::tempdir().expect("temporary folder");
    let target = format!("{}/", dir.path().display());
    let out = geomc(&[
        "compile",
        "-o",
        &target,
        "--to",
        "msh",
        "fixtures/invalid/e408_overlapping_balls_union.xml",
        "examples/ball_in_box.xml",
    ]);
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("error[E408]"), "{stderr}");
    assert!(
        stderr.contains(
            "compiled 1 of 2 inputs; failed: fixtures/invalid/e408_overlapping_balls_union.xml"
        ),
        "{stderr}"
    );
    assert!(dir.path().join("ball_in_box.msh").exists());
    assert!(!dir.path().join("e408_overlapping_balls_union.msh").exists());
    let leftovers: Vec<String> = std::fs::read_dir(dir.path())
        .expect("folder")
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n != "ball_in_box.msh")
        .collect();
    assert!(leftovers.is_empty(), "unexpected files: {leftovers:?}");
}
