//! The density-volume reader (raw samples and NRRD headers, attached or
//! detached) on arbitrary bytes, through the XML front end that reads it:
//! diagnostics, never a panic; an accepted volume is polygonized. The case is written to a folder of this
//! process's own under the system temp folder (see shared/density_case.rs).
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::PathBuf;
use std::sync::OnceLock;

#[path = "../shared/density_case.rs"]
mod density_case;

fn folder() -> &'static PathBuf {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("geomc-fuzz-density-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("a temp folder for the fuzz case");
        dir
    })
}

fuzz_target!(|data: &[u8]| {
    let checked = density_case::check(folder(), data);
    for d in &checked.diagnostics.items {
        let _ = geomc::diag::render_human(&checked.source, d);
    }
    // An accepted volume is polygonized on its own grid, as compile does.
    for subdomain in &checked.implicit {
        let _ = subdomain.polygonize(None);
    }
});
