//! Every crash a fuzz target ever found stays fixed: the inputs kept under
//! `fuzz/regressions/<target>/` are replayed through the same library calls
//! the target makes (fuzz/fuzz_targets/), asserting the expected outcome
//! (a diagnostic, not a panic). `docs/reliability.md` lists what each was.

use geomc::formats::read::{ReadFormat, load_bytes, load_frag_bytes};
use geomc::span::SourceFile;
use std::path::{Path, PathBuf};

fn inputs(target: &str) -> Vec<(PathBuf, Vec<u8>)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fuzz/regressions")
        .join(target);
    let mut out: Vec<(PathBuf, Vec<u8>)> = std::fs::read_dir(&dir)
        .map(|entries| {
            entries
                .filter_map(Result::ok)
                .map(|e| e.path())
                .filter(|p| p.is_file())
                .map(|p| {
                    let bytes = std::fs::read(&p).expect("readable regression input");
                    (p, bytes)
                })
                .collect()
        })
        .unwrap_or_default();
    out.sort();
    out
}

fn replay_reader(target: &str, format: ReadFormat) -> usize {
    let found = inputs(target);
    for (path, bytes) in &found {
        let result = load_bytes(format, bytes, Path::new("/nonexistent/geomc-fuzz"));
        if let Err(diagnostics) = result {
            assert!(
                !diagnostics.is_empty(),
                "{}: an error without a diagnostic",
                path.display()
            );
        }
    }
    found.len()
}

#[test]
fn mesh_reader_crashes_stay_fixed() {
    let n = replay_reader("read_stl", ReadFormat::Stl)
        + replay_reader("read_obj", ReadFormat::Obj)
        + replay_reader("read_gltf", ReadFormat::Glb)
        + replay_reader("read_msh", ReadFormat::Msh)
        + replay_reader("read_vtu", ReadFormat::Vtu);
    eprintln!("{n} mesh reader regression inputs replayed");
}

#[test]
fn frag_reader_crashes_stay_fixed() {
    for (path, bytes) in inputs("read_frag") {
        let frag = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/regressions/fuzz.frag.xml");
        if let Err(diagnostics) = load_frag_bytes(&frag, &bytes) {
            assert!(!diagnostics.is_empty(), "{}", path.display());
        }
    }
}

#[test]
fn rfs_language_crashes_stay_fixed() {
    for (path, bytes) in inputs("rfs_language") {
        let source = SourceFile::new("fuzz.rfs", String::from_utf8_lossy(&bytes).into_owned());
        let (model, diagnostics) = geomc::implicit::lang::compile(&source);
        for d in &diagnostics.items {
            let _ = geomc::diag::render_human(&source, d);
        }
        if let Some(model) = model {
            let surface = model.polygonize(Some([4, 4, 4]));
            assert!(
                surface
                    .triangles
                    .iter()
                    .flatten()
                    .all(|&i| (i as usize) < surface.positions.len()),
                "{}",
                path.display()
            );
        }
    }
}

#[test]
fn xml_front_end_crashes_stay_fixed() {
    let options = geomc::driver::Options::default();
    for (path, bytes) in inputs("xml_front_end") {
        let checked = geomc::driver::check_bytes(path.display().to_string(), bytes, &options);
        for d in &checked.diagnostics.items {
            let _ = geomc::diag::render_human(&checked.source, d);
        }
    }
}
