//! The `.rfs` language (lexer → parser → expansion) on arbitrary text: it must
//! return diagnostics, never panic. A program it accepts is evaluated on a
//! small grid, so the compiled tape runs on whatever the program computes.
#![no_main]

use geomc::span::SourceFile;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let source = SourceFile::new("fuzz.rfs", String::from_utf8_lossy(data).into_owned());
    let (model, diagnostics) = geomc::implicit::lang::compile(&source);
    for d in &diagnostics.items {
        // Every span must render (inside the source, on a character boundary).
        let _ = geomc::diag::render_human(&source, d);
    }
    if let Some(model) = model {
        assert!(!diagnostics.has_errors(), "a model despite errors");
        // 4³ cells: the Geom grid of the program could ask for 1024³.
        let surface = model.polygonize(Some([4, 4, 4]));
        let n = surface.positions.len();
        for t in &surface.triangles {
            assert!(
                t.iter().all(|&i| (i as usize) < n),
                "triangle {t:?} of {n} nodes"
            );
        }
    }
});
