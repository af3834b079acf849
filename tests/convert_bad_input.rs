//! Bad mesh files: each gives its exact code and position (line:column for
//! text, the byte offset for binary data), and no truncation of a valid
//! file makes a reader panic.

mod writers_common;

use geomc::diag::{Code, Diagnostic};
use geomc::formats::read::{ReadFormat, load_bytes, load_mesh};
use geomc::formats::{Encoding, WriteOptions, writer_for_path};
use geomc::span::SourceFile;
use std::path::Path;
use writers_common::cube_with_probe;

fn errors(format: ReadFormat, bytes: &[u8]) -> Vec<Diagnostic> {
    match load_bytes(format, bytes, Path::new(".")) {
        Ok(l) => panic!("{format:?} accepted bad input; warnings {:?}", l.warnings),
        Err(d) => d,
    }
}

/// The single error's code and its line:column.
fn at(format: ReadFormat, text: &str) -> (Code, u32, u32, String) {
    let d = errors(format, text.as_bytes());
    assert_eq!(d.len(), 1, "{d:?}");
    let span = d[0].span.unwrap_or_else(|| panic!("no span: {:?}", d[0]));
    let lc = SourceFile::new("t", text).line_col(span.start as usize);
    (d[0].code, lc.line, lc.column, d[0].message.clone())
}

/// The single error's code and message (binary data: the offset is in the message).
fn binary(format: ReadFormat, bytes: &[u8]) -> (Code, String) {
    let d = errors(format, bytes);
    assert_eq!(d.len(), 1, "{d:?}");
    assert!(d[0].span.is_none(), "{:?}", d[0]);
    (d[0].code, d[0].message.clone())
}

fn stl_binary(n_declared: u32, triangles: &[[[f32; 3]; 3]]) -> Vec<u8> {
    let mut b = vec![b' '; 80];
    b.extend_from_slice(&n_declared.to_le_bytes());
    for t in triangles {
        b.extend_from_slice(&[0u8; 12]);
        for p in t {
            for c in p {
                b.extend_from_slice(&c.to_le_bytes());
            }
        }
        b.extend_from_slice(&[0, 0]);
    }
    b
}

const TRI: [[f32; 3]; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

#[test]
fn binary_stl_whose_size_contradicts_its_count() {
    let bytes = stl_binary(3, &[TRI, TRI]);
    let (code, message) = binary(ReadFormat::Stl, &bytes);
    assert_eq!(code, Code::StlSizeMismatch);
    assert_eq!(
        message,
        "at byte 80: the binary STL header says 3 triangles, which take 234 bytes, but the file has 184 bytes"
    );
}

#[test]
fn binary_stl_with_a_nan() {
    let mut t = TRI;
    t[1][2] = f32::NAN;
    let bytes = stl_binary(2, &[TRI, t]);
    let (code, message) = binary(ReadFormat::Stl, &bytes);
    assert_eq!(code, Code::MeshNonFinite);
    // Triangle 2 starts at 134; its second vertex's z is 12 + 12 + 8 further.
    assert!(
        message.starts_with("at byte 166: triangle 2 has a coordinate `NaN`"),
        "{message}"
    );
}

#[test]
fn ascii_stl_errors_have_line_and_column() {
    let good = "solid a\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n   vertex 0 1 0\n  endloop\n endfacet\nendsolid a\n";
    assert!(load_bytes(ReadFormat::Stl, good.as_bytes(), Path::new(".")).is_ok());
    let (code, line, col, _) = at(ReadFormat::Stl, &good.replace("endloop", "endlop"));
    assert_eq!((code, line, col), (Code::MeshSyntax, 7, 3));
    let (code, line, col, msg) = at(
        ReadFormat::Stl,
        &good.replace("vertex 1 0 0", "vertex 1 inf 0"),
    );
    assert_eq!((code, line, col), (Code::MeshNonFinite, 5, 13), "{msg}");
    let (code, line, col, _) = at(
        ReadFormat::Stl,
        &good.replace("   vertex 0 1 0\n", "   vertex 0 1 0\n   vertex 1 1 0\n"),
    );
    assert_eq!((code, line, col), (Code::MeshUnsupportedElement, 7, 4));
    let (code, line, _, _) = at(
        ReadFormat::Stl,
        &good[..good.find("   vertex 0 1 0").unwrap_or(0)],
    );
    assert_eq!((code, line), (Code::MeshTruncated, 5));
}

#[test]
fn obj_index_out_of_range_and_bad_numbers() {
    let (code, line, col, msg) = at(ReadFormat::Obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n");
    assert_eq!((code, line, col), (Code::MeshIndexOutOfRange, 4, 7));
    assert_eq!(
        msg,
        "vertex index 4 is out of range: 3 vertices are defined before this line"
    );
    let (code, line, col, _) = at(ReadFormat::Obj, "v 0 0 0\nv 1 nan 0\n");
    assert_eq!((code, line, col), (Code::MeshNonFinite, 2, 5));
    let (code, line, col, _) = at(ReadFormat::Obj, "v 0 0 0\nv 1 x 0\n");
    assert_eq!((code, line, col), (Code::MeshSyntax, 2, 5));
    let (code, line, _, _) = at(ReadFormat::Obj, "v 0 0\n");
    assert_eq!((code, line), (Code::MeshCountMismatch, 1));
    let (code, line, col, _) = at(ReadFormat::Obj, "v 0 0 0\nv 1 0 0\nf 1 2\n");
    assert_eq!((code, line, col), (Code::MeshCountMismatch, 3, 1));
    let (code, line, col, _) = at(ReadFormat::Obj, "v 0 0 0\nf 1 -2 1\n");
    assert_eq!((code, line, col), (Code::MeshIndexOutOfRange, 2, 5));
}

const MSH41: &str = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 3 1 3\n2 1 0 3\n1\n2\n3\n0 0 0\n1 0 0\n0 1 0\n$EndNodes\n$Elements\n1 1 1 1\n2 1 2 1\n1 1 2 3\n$EndElements\n";

#[test]
fn msh_errors_have_line_and_column() {
    let ok = load_bytes(ReadFormat::Msh, MSH41.as_bytes(), Path::new(".")).expect("valid");
    assert_eq!(ok.mesh.faces.len(), 1);
    assert_eq!(ok.mesh.faces[0].name, "surface 1");
    // An element naming a node that $Nodes does not define.
    let (code, line, col, msg) = at(ReadFormat::Msh, &MSH41.replace("1 1 2 3\n", "1 1 2 7\n"));
    assert_eq!(
        (code, line, col),
        (Code::MeshIndexOutOfRange, 17, 7),
        "{msg}"
    );
    // An unknown element type.
    let (code, line, col, _) = at(ReadFormat::Msh, &MSH41.replace("2 1 2 1\n", "2 1 99 1\n"));
    assert_eq!((code, line, col), (Code::MeshUnsupportedElement, 16, 5));
    // More nodes announced than the file holds.
    let (code, line, col, _) = at(ReadFormat::Msh, &MSH41.replace("1 3 1 3\n", "1 900 1 3\n"));
    assert_eq!((code, line, col), (Code::MeshCountMismatch, 5, 3));
    // A non-finite coordinate.
    let (code, line, col, _) = at(ReadFormat::Msh, &MSH41.replace("1 0 0\n", "1 NaN 0\n"));
    assert_eq!((code, line, col), (Code::MeshNonFinite, 11, 3));
    // An unsupported version.
    let (code, line, col, _) = at(ReadFormat::Msh, &MSH41.replace("4.1 0 8", "3.0 0 8"));
    assert_eq!((code, line, col), (Code::MeshUnsupportedVersion, 2, 1));
    // Cut short inside $Elements.
    let cut = &MSH41[..MSH41.find("1 1 2 3").unwrap_or(0) + 4];
    let (code, _, _, _) = at(ReadFormat::Msh, cut);
    assert_eq!(code, Code::MeshTruncated);
    // MSH 2.2 with an unknown element type.
    let v22 = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n3\n1 0 0 0\n2 1 0 0\n3 0 1 0\n$EndNodes\n$Elements\n1\n1 42 2 0 1 1 2 3\n$EndElements\n";
    let (code, line, col, _) = at(ReadFormat::Msh, v22);
    assert_eq!((code, line, col), (Code::MeshUnsupportedElement, 12, 3));
    let fixed = v22.replace("1 42 2 0 1", "1 2 2 5 1");
    let ok = load_bytes(ReadFormat::Msh, fixed.as_bytes(), Path::new(".")).expect("valid 2.2");
    assert_eq!(ok.mesh.faces[0].name, "physical 2:5");
}

#[test]
fn binary_msh_cut_short_names_the_byte_offset() {
    let mesh = cube_with_probe();
    let writer = writer_for_path(Path::new("x.msh")).expect("msh");
    let mut bytes = Vec::new();
    let options = WriteOptions {
        encoding: Some(Encoding::Binary),
        ..WriteOptions::default()
    };
    writer.write(&mesh, &options, &mut bytes).expect("write");
    let nodes = bytes
        .windows(7)
        .position(|w| w == b"$Nodes\n")
        .expect("nodes")
        + 7;
    let cut = &bytes[..nodes + 40];
    let d = errors(ReadFormat::Msh, cut);
    assert_eq!(d[0].code, Code::MeshTruncated, "{d:?}");
    // The node count (13) stands 8 bytes into the $Nodes header.
    assert_eq!(
        d[0].message,
        format!(
            "at byte {}: the file says 13 nodes, but ends 8 bytes later: it is truncated",
            nodes + 8
        )
    );
}

#[test]
fn gltf_and_glb_errors() {
    // Malformed JSON: line and column.
    let (code, line, col, _) = at(
        ReadFormat::Gltf,
        "{\n  \"asset\": {\"version\": \"2.0\"},\n  \"nodes\": [,]\n}",
    );
    assert_eq!((code, line, col), (Code::MeshSyntax, 3, 13));
    // A mesh index that points nowhere.
    let d = errors(
        ReadFormat::Gltf,
        br#"{"asset":{"version":"2.0"},"scenes":[{"nodes":[0]}],"nodes":[{"mesh":3}]}"#,
    );
    assert_eq!(d[0].code, Code::GltfInvalid);
    assert_eq!(d[0].message, "meshes[3]: no such mesh");
    // An index out of range of its positions.
    let mesh = cube_with_probe();
    let writer = writer_for_path(Path::new("x.gltf")).expect("gltf");
    let mut text = Vec::new();
    writer
        .write(&mesh, &WriteOptions::default(), &mut text)
        .expect("write");
    let mut json: serde_json::Value = serde_json::from_slice(&text).expect("json");
    json["accessors"][0]["count"] = serde_json::json!(100000);
    let d = errors(ReadFormat::Gltf, &serde_json::to_vec(&json).expect("json"));
    assert_eq!(d[0].code, Code::MeshCountMismatch, "{d:?}");
    // GLB whose header length disagrees with the file.
    let writer = writer_for_path(Path::new("x.glb")).expect("glb");
    let mut glb = Vec::new();
    writer
        .write(&mesh, &WriteOptions::default(), &mut glb)
        .expect("write");
    let (code, message) = binary(ReadFormat::Glb, &glb[..glb.len() - 8]);
    assert_eq!(code, Code::MeshTruncated);
    assert!(
        message.starts_with("at byte 8: the GLB header says"),
        "{message}"
    );
}

#[test]
fn vtu_errors() {
    let vtu = |conn: &str, offsets: &str, types: &str| {
        format!(
            "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\">\n<UnstructuredGrid>\n<Piece NumberOfPoints=\"3\" NumberOfCells=\"1\">\n<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">0 0 0 1 0 0 0 1 0</DataArray>\n</Points>\n<Cells>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">{conn}</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">{offsets}</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">{types}</DataArray>\n</Cells>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n"
        )
    };
    let ok = load_bytes(
        ReadFormat::Vtu,
        vtu("0 1 2", "3", "5").as_bytes(),
        Path::new("."),
    )
    .expect("valid");
    assert_eq!(ok.mesh.faces[0].triangles, vec![[0, 1, 2]]);
    let (code, line, _, msg) = at(ReadFormat::Vtu, &vtu("0 1 5", "3", "5"));
    assert_eq!((code, line), (Code::MeshIndexOutOfRange, 9), "{msg}");
    let (code, line, _, _) = at(ReadFormat::Vtu, &vtu("0 1 2", "3 3", "5"));
    assert_eq!((code, line), (Code::MeshCountMismatch, 10));
    let (code, line, _, _) = at(ReadFormat::Vtu, &vtu("0 1 2", "3", "77"));
    assert_eq!((code, line), (Code::MeshUnsupportedElement, 11));
    let (code, line, col, _) = at(
        ReadFormat::Vtu,
        &vtu("0 1 2", "3", "5").replace("1 0 0 0 1 0", "1 0 0 0 x 0"),
    );
    assert_eq!((code, line, col), (Code::MeshSyntax, 6, 79));
}

#[test]
fn unknown_format_and_missing_files() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("mesh.dat");
    std::fs::write(&path, "hello").expect("write");
    let d = load_mesh(&path).expect_err("unknown");
    assert_eq!(d[0].code, Code::UnknownMeshFormat);
    let d = load_mesh(&dir.path().join("none.stl")).expect_err("missing");
    assert_eq!(d[0].code, Code::MeshReadFailed);
    // A .frag.xml whose mesh file has other faces.
    let frag = dir.path().join("a.frag.xml");
    let mesh = cube_with_probe();
    let options = WriteOptions {
        mesh_file: Some("a.stl".into()),
        ..WriteOptions::default()
    };
    geomc::formats::write_mesh_file(&frag, &mesh, &options).expect("frag");
    geomc::formats::write_mesh_file(&dir.path().join("a.stl"), &mesh, &WriteOptions::default())
        .expect("stl");
    let d = load_mesh(&frag).expect_err("mismatch");
    assert_eq!(d[0].code, Code::FragMeshMismatch, "{d:?}");
}

/// Every prefix of every format's file is read without a panic, and an
/// error always comes with a position (a span or a byte offset).
#[test]
fn no_truncation_panics() {
    let mesh = cube_with_probe();
    for (name, encoding, format) in [
        ("x.stl", Some(Encoding::Ascii), ReadFormat::Stl),
        ("x.stl", Some(Encoding::Binary), ReadFormat::Stl),
        ("x.obj", None, ReadFormat::Obj),
        ("x.gltf", None, ReadFormat::Gltf),
        ("x.glb", None, ReadFormat::Glb),
        ("x.msh", Some(Encoding::Ascii), ReadFormat::Msh),
        ("x.msh", Some(Encoding::Binary), ReadFormat::Msh),
        ("x.vtu", Some(Encoding::Ascii), ReadFormat::Vtu),
        ("x.vtu", Some(Encoding::Binary), ReadFormat::Vtu),
    ] {
        let writer = writer_for_path(Path::new(name)).expect("writer");
        let mut bytes = Vec::new();
        let options = WriteOptions {
            encoding,
            ..WriteOptions::default()
        };
        writer.write(&mesh, &options, &mut bytes).expect("write");
        let step = (bytes.len() / 300).max(1);
        for len in (0..bytes.len()).step_by(step) {
            if let Err(d) = load_bytes(format, &bytes[..len], Path::new(".")) {
                assert!(!d.is_empty());
                assert!(d.iter().all(|d| d.is_error()), "{name}[..{len}]: {d:?}");
            }
        }
        // Flipped bytes never panic either.
        for i in (0..bytes.len()).step_by(step) {
            let mut b = bytes.clone();
            b[i] ^= 0x5a;
            let _ = load_bytes(format, &b, Path::new("."));
        }
    }
}
