//! The msh mesh reader on arbitrary bytes: diagnostics, never a panic; a mesh
//! it accepts must pass the writers' checks.
#![no_main]

use geomc::formats::read::{ReadFormat, load_bytes};
use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    // A folder that does not exist: no fuzz input can make a reader open files.
    if let Ok(loaded) = load_bytes(ReadFormat::Msh, data, Path::new("/nonexistent/geomc-fuzz")) {
        let mut sink = Vec::new();
        let writer = geomc::formats::writer_for_path(Path::new("x.msh"));
        if let Some(w) = writer {
            let _ = w.write(&loaded.mesh, &Default::default(), &mut sink);
        }
    }
});
