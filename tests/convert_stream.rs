//! Binary STL files are read from disk in pieces: the mesh is the same as
//! when the whole file is read from memory, across piece boundaries, and a
//! bad value in a later piece is reported at its byte offset.

use geomc::diag::Code;
use geomc::formats::read::{ReadFormat, load_bytes, load_mesh};
use std::path::Path;

/// A strip of `n` triangles over a zigzag of points, as binary STL bytes.
fn strip(n: usize) -> Vec<u8> {
    let mut bytes = vec![b' '; 80];
    bytes.extend_from_slice(&(n as u32).to_le_bytes());
    let p = |i: usize| [(i / 2) as f32 * 0.5, (i % 2) as f32, -0.0f32];
    for t in 0..n {
        bytes.extend_from_slice(&[0u8; 12]);
        let corners = if t % 2 == 0 {
            [p(t), p(t + 1), p(t + 2)]
        } else {
            [p(t + 1), p(t), p(t + 2)]
        };
        for c in corners.iter().flatten() {
            bytes.extend_from_slice(&c.to_le_bytes());
        }
        bytes.extend_from_slice(&[0, 0]);
    }
    bytes
}

#[test]
fn streamed_binary_stl_equals_the_in_memory_read() {
    let dir = tempfile::tempdir().expect("temp dir");
    let n = 50_001;
    let bytes = strip(n);
    let path = dir.path().join("strip.stl");
    std::fs::write(&path, &bytes).expect("write");
    let streamed = load_mesh(&path).expect("streamed");
    let whole = load_bytes(ReadFormat::Stl, &bytes, Path::new("")).expect("in memory");
    assert_eq!(streamed.mesh, whole.mesh);
    assert_eq!(streamed.binary, Some(true));
    assert_eq!(streamed.mesh.nodes.len(), n + 2);
    assert_eq!(streamed.mesh.faces[0].triangles.len(), n);
    assert_eq!(
        streamed.mesh.faces[0].triangles[n - 1],
        [n as u32 - 1, n as u32, n as u32 + 1]
    );

    // A NaN in triangle 30,000 (the second piece), its second corner's y.
    let mut bad = bytes.clone();
    let at = 84 + 50 * 29_999 + 12 + 12 + 4;
    bad[at..at + 4].copy_from_slice(&f32::NAN.to_le_bytes());
    let path = dir.path().join("bad.stl");
    std::fs::write(&path, &bad).expect("write");
    let errors = load_mesh(&path).expect_err("NaN");
    assert_eq!(errors.len(), 1);
    assert_eq!(errors[0].code, Code::MeshNonFinite);
    assert!(
        errors[0].message.starts_with(&format!(
            "at byte {at}: triangle 30000 has a coordinate `NaN`"
        )),
        "{}",
        errors[0].message
    );
}
