//! The XML front end on arbitrary bytes: it must return diagnostics, never panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let options = geomc::driver::Options::default();
    let checked = geomc::driver::check_bytes("fuzz.xml".into(), data.to_vec(), &options);
    for d in &checked.diagnostics.items {
        // Rendering must not panic either, whatever the spans.
        let _ = geomc::diag::render_human(&checked.source, d);
    }
});
