//! Determinism (issue 10): every valid fixture (fixtures/valid/*.xml and
//! fixtures/rfs/*.rfs) compiled to every output format with 1 and with 4
//! threads, twice each, gives byte-identical files. `-j N` sizes the pool the
//! whole compile runs in (inputs, faces, implicit sampling) and
//! RAYON_NUM_THREADS the global one. To keep a debug build fast the meshes are
//! coarse (--tolerance 2%, --cells 16 for .rfs): determinism does not depend
//! on the mesh size, and tests/crash_safe_output.rs writes a large one.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

fn inputs() -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures");
    let mut files = Vec::new();
    for (folder, ending) in [("valid", "xml"), ("rfs", "rfs")] {
        for entry in std::fs::read_dir(root.join(folder)).expect("fixture folder") {
            let path = entry.expect("entry").path();
            if path.extension().is_some_and(|e| e == ending) {
                files.push(path);
            }
        }
    }
    files.sort();
    files
}

/// Compiles every input into a fresh folder; returns each file's bytes by name.
fn compile_all(threads: usize, formats: &[&str], extra: &[&str]) -> BTreeMap<String, Vec<u8>> {
    let dir = tempfile::tempdir().expect("temporary folder");
    let out = format!("{}/", dir.path().display());
    let status = Command::new(env!("CARGO_BIN_EXE_geomc"))
        .env("RAYON_NUM_THREADS", threads.to_string())
        .arg("compile")
        .args(inputs())
        .args(["-o", &out, "-j", &threads.to_string(), "--quiet"])
        .args(["--tolerance", "2%", "--cells", "16"])
        .args(formats.iter().flat_map(|f| ["--to", f]))
        .args(extra)
        .status()
        .expect("geomc runs");
    assert!(
        status.success(),
        "compiling the valid fixtures failed: {status:?}"
    );
    let mut files = BTreeMap::new();
    for entry in std::fs::read_dir(dir.path()).expect("output folder") {
        let entry = entry.expect("entry");
        let name = entry.file_name().to_string_lossy().into_owned();
        files.insert(name, std::fs::read(entry.path()).expect("output"));
    }
    files
}

fn assert_same(a: &BTreeMap<String, Vec<u8>>, b: &BTreeMap<String, Vec<u8>>, what: &str) {
    assert_eq!(
        a.keys().collect::<Vec<_>>(),
        b.keys().collect::<Vec<_>>(),
        "{what}: different files"
    );
    let differing: Vec<&String> = a.keys().filter(|k| a[*k] != b[*k]).collect();
    assert!(
        differing.is_empty(),
        "{what}: bytes differ in {differing:?}"
    );
}

#[test]
fn every_valid_fixture_compiles_to_the_same_bytes_on_1_and_4_threads() {
    let formats = ["gltf", "glb", "obj", "stl", "msh", "vtu", "frag.xml"];
    let one = compile_all(1, &formats, &[]);
    let inputs = inputs().len();
    // Every input gives every format (glTF adds its .bin beside it).
    assert!(inputs >= 70, "only {inputs} valid fixtures");
    assert!(one.len() >= inputs * formats.len(), "{} files", one.len());
    assert!(one.values().all(|b| !b.is_empty()));
    assert_same(&one, &compile_all(1, &formats, &[]), "1 thread, twice");
    let four = compile_all(4, &formats, &[]);
    assert_same(&one, &four, "1 thread against 4");
    assert_same(&four, &compile_all(4, &formats, &[]), "4 threads, twice");
}

#[test]
fn text_encodings_are_the_same_on_1_and_4_threads() {
    let formats = ["stl", "msh", "vtu"];
    let one = compile_all(1, &formats, &["--ascii"]);
    assert_same(
        &one,
        &compile_all(4, &formats, &["--ascii"]),
        "--ascii, 1 thread against 4",
    );
}
