//! geomc's `.frag.xml` reader on arbitrary bytes: diagnostics, never a panic.
//! The description is read from memory; the mesh files it may name are the
//! ones `run.sh` writes into `fuzz/frag_meshes/` (ball_in_box in every mesh
//! format), so accepted inputs exercise matching faces, subdomains and
//! fragments onto a real mesh. A name outside that folder must be refused.
#![no_main]

use geomc::formats::read::load_frag_bytes;
use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let path = Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/frag_meshes/fuzz.frag.xml"
    ));
    if let Ok(loaded) = load_frag_bytes(path, data) {
        let mesh = &loaded.mesh;
        let n = mesh.nodes.len();
        for face in &mesh.faces {
            for t in &face.triangles {
                assert!(
                    t.iter().all(|&i| (i as usize) < n),
                    "triangle {t:?} of {n} nodes"
                );
            }
        }
        for s in &mesh.subdomains {
            for &(f, _) in &s.faces {
                assert!((f as usize) < mesh.faces.len(), "subdomain face {f}");
            }
        }
        let mut sink = Vec::new();
        if let Some(w) = geomc::formats::writer_for_path(Path::new("x.msh")) {
            let _ = w.write(mesh, &Default::default(), &mut sink);
        }
    }
});
