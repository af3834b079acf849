//! Binary MSH 4.1 node and element blocks read at once (in parallel pieces):
//! the same nodes, triangles and numbering as value by value, over several
//! blocks and sparse tags, and a bad block's first error (which node, which
//! code, which byte) as the value-by-value reader gives it. The expected
//! offsets and messages are those of main's reader before the change.

use geomc::diag::Code;
use geomc::formats::read::{ReadFormat, load_bytes};
use std::path::Path;

const C: [[f64; 3]; 4] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
];

/// A binary MSH 4.1 file: node blocks (tags, coordinates) and one block of
/// linear triangles (node tags), no `$Entities`.
fn msh(blocks: &[(&[u64], &[[f64; 3]])], triangles: &[[u64; 3]]) -> Vec<u8> {
    let mut b = b"$MeshFormat\n4.1 1 8\n".to_vec();
    b.extend_from_slice(&1i32.to_le_bytes());
    b.extend_from_slice(b"\n$EndMeshFormat\n$Nodes\n");
    let all: Vec<u64> = blocks.iter().flat_map(|(t, _)| t.iter().copied()).collect();
    let (lo, hi) = (all.iter().min().unwrap(), all.iter().max().unwrap());
    for v in [blocks.len() as u64, all.len() as u64, *lo, *hi] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    for (tags, coordinates) in blocks {
        for v in [2i32, 1, 0] {
            b.extend_from_slice(&v.to_le_bytes());
        }
        b.extend_from_slice(&(tags.len() as u64).to_le_bytes());
        for t in *tags {
            b.extend_from_slice(&t.to_le_bytes());
        }
        for c in coordinates.iter().flatten() {
            b.extend_from_slice(&c.to_le_bytes());
        }
    }
    b.extend_from_slice(b"\n$EndNodes\n$Elements\n");
    let n = triangles.len() as u64;
    for v in [1, n, 1, n] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    for v in [2i32, 1, 2] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    b.extend_from_slice(&n.to_le_bytes());
    for (i, t) in triangles.iter().enumerate() {
        b.extend_from_slice(&(i as u64 + 1).to_le_bytes());
        for v in t {
            b.extend_from_slice(&v.to_le_bytes());
        }
    }
    b.extend_from_slice(b"\n$EndElements\n");
    b
}

/// The single error's code and message (with its byte offset).
fn error(bytes: &[u8]) -> (Code, String) {
    match load_bytes(ReadFormat::Msh, bytes, Path::new(".")) {
        Ok(_) => panic!("bad MSH accepted"),
        Err(d) => {
            assert_eq!(d.len(), 1, "{d:?}");
            (d[0].code, d[0].message.clone())
        }
    }
}

#[test]
fn blocks_keep_node_order_numbering_and_coordinates() {
    let nodes_a: [[f64; 3]; 2] = [C[0], C[1]];
    let nodes_b: [[f64; 3]; 3] = [C[2], C[3], [2.5, -1.0, 0.125]];
    // Two node blocks, one tag beyond the dense table (a map entry).
    let bytes = msh(
        &[(&[1, 2], &nodes_a), (&[3, 1_000_000_000_000, 7], &nodes_b)],
        &[[1, 2, 3], [1_000_000_000_000, 7, 2], [3, 7, 1]],
    );
    let loaded = load_bytes(ReadFormat::Msh, &bytes, Path::new(".")).expect("valid MSH");
    let mesh = &loaded.mesh;
    assert_eq!(mesh.nodes.len(), 5);
    assert_eq!(mesh.nodes[1], [1.0, 0.0, 0.0]);
    assert_eq!(mesh.nodes[4], [2.5, -1.0, 0.125]);
    assert_eq!(mesh.faces.len(), 1);
    assert_eq!(mesh.faces[0].name, "surface 1");
    assert_eq!(
        mesh.faces[0].triangles,
        vec![[0, 1, 2], [3, 4, 1], [2, 4, 0]]
    );
}

#[test]
fn a_non_finite_coordinate_names_its_byte() {
    let bytes = msh(
        &[(&[1, 2, 3, 4], &[C[0], C[1], [0.0, f64::NAN, 0.0], C[3]])],
        &[[1, 2, 3]],
    );
    assert_eq!(
        error(&bytes),
        (
            Code::MeshNonFinite,
            "at byte 187: a node coordinate is NaN, not a finite number".to_string()
        )
    );
}

#[test]
fn a_duplicate_tag_names_its_byte_and_comes_before_a_later_bad_coordinate() {
    let dup = msh(&[(&[1, 2, 2, 4], &C)], &[[1, 2, 4]]);
    let expected = (
        Code::MeshCountMismatch,
        "at byte 115: node tag 2 is given twice".to_string(),
    );
    assert_eq!(error(&dup), expected);
    let later_inf = msh(
        &[(
            &[1, 2, 2, 4],
            &[C[0], C[1], C[2], [f64::INFINITY, 0.0, 0.0]],
        )],
        &[[1, 2, 4]],
    );
    assert_eq!(error(&later_inf), expected);
}

#[test]
fn a_bad_coordinate_comes_before_its_own_nodes_duplicate_tag() {
    let same_node = msh(
        &[(
            &[1, 2, 2, 4],
            &[C[0], C[1], [0.0, 0.0, f64::NEG_INFINITY], C[3]],
        )],
        &[[1, 2, 4]],
    );
    assert_eq!(
        error(&same_node),
        (
            Code::MeshNonFinite,
            "at byte 195: a node coordinate is -inf, not a finite number".to_string()
        )
    );
    let earlier = msh(
        &[(&[1, 2, 3, 2], &[C[0], [f64::NAN, 0.0, 0.0], C[2], C[3]])],
        &[[1, 2, 3]],
    );
    assert_eq!(
        error(&earlier),
        (
            Code::MeshNonFinite,
            "at byte 155: a node coordinate is NaN, not a finite number".to_string()
        )
    );
}

#[test]
fn a_triangle_on_an_unknown_node_names_its_byte() {
    let bytes = msh(&[(&[1, 2, 3, 4], &C)], &[[1, 2, 3], [1, 3, 9]]);
    assert_eq!(
        error(&bytes),
        (
            Code::MeshIndexOutOfRange,
            "at byte 356: an element refers to node 9, which `$Nodes` does not define".to_string()
        )
    );
}

/// With node tags running on (1–4), a triangle's corners are found by
/// subtracting the first tag: a tag below the run (0, which wraps past every
/// index) or past it (5) is still refused at its own byte.
#[test]
fn a_triangle_below_or_past_the_node_run_names_its_byte() {
    let past = msh(&[(&[1, 2, 3, 4], &C)], &[[5, 2, 3]]);
    assert_eq!(
        error(&past),
        (
            Code::MeshIndexOutOfRange,
            "at byte 308: an element refers to node 5, which `$Nodes` does not define".to_string()
        )
    );
    let below = msh(&[(&[1, 2, 3, 4], &C)], &[[1, 2, 3], [0, 3, 4]]);
    assert_eq!(
        error(&below),
        (
            Code::MeshIndexOutOfRange,
            "at byte 340: an element refers to node 0, which `$Nodes` does not define".to_string()
        )
    );
    let loaded = load_bytes(
        ReadFormat::Msh,
        &msh(&[(&[1, 2, 3, 4], &C)], &[[4, 1, 2]]),
        Path::new("."),
    )
    .expect("valid MSH");
    assert_eq!(loaded.mesh.faces[0].triangles, vec![[3, 0, 1]]);
}

/// Blocks whose tags run on from the block before are read whole (in
/// parallel pieces); a block that skips a tag, or repeats one from an
/// earlier block, is read node by node with the same numbering and errors.
#[test]
fn blocks_that_run_on_then_skip_or_repeat_a_tag() {
    let three: [[f64; 3]; 2] = [[2.0, 0.0, 0.0], [0.0, 3.0, 0.0]];
    let bytes = msh(
        &[
            (&[1, 2], &[C[0], C[1]]),
            (&[3, 4], &[C[2], C[3]]),
            (&[6, 7], &three),
        ],
        &[[1, 2, 3], [3, 4, 6], [7, 6, 4]],
    );
    let loaded = load_bytes(ReadFormat::Msh, &bytes, Path::new(".")).expect("valid MSH");
    let mesh = &loaded.mesh;
    assert_eq!(mesh.nodes.len(), 6);
    assert_eq!(mesh.nodes[3], C[3]);
    assert_eq!(mesh.nodes[5], [0.0, 3.0, 0.0]);
    assert_eq!(
        mesh.faces[0].triangles,
        vec![[0, 1, 2], [2, 3, 4], [5, 4, 3]]
    );
    // The third block's first tag repeats the second block's last: its
    // tags start at byte 267 (header 79, two blocks of 20 + 64 bytes, 20).
    let repeated = msh(
        &[
            (&[1, 2], &[C[0], C[1]]),
            (&[3, 4], &[C[2], C[3]]),
            (&[4, 5], &three),
        ],
        &[[1, 2, 3]],
    );
    assert_eq!(
        error(&repeated),
        (
            Code::MeshCountMismatch,
            "at byte 267: node tag 4 is given twice".to_string()
        )
    );
}
