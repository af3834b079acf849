//! The mesh writers on hand-built meshes, read back in-process: counts per
//! group in every format, byte-identical output on repeat, warnings, format
//! detection, atomic writes and the `.frag.xml` round trip.

mod writers_common;

use geomc::formats::{
    Encoding, WRITERS, WriteError, WriteOptions, read_frag_xml, write_atomic, writer_for_path,
};
use geomc::mesh::Mesh;
use std::collections::BTreeMap;
use std::path::Path;
use writers_common::*;

fn bytes(ext: &str, mesh: &Mesh, options: &WriteOptions) -> (Vec<u8>, Vec<String>) {
    let writer = writer_for_path(Path::new(&format!("out.{ext}"))).expect("a writer");
    let mut out = Vec::new();
    let warnings = writer
        .write(mesh, options, &mut out)
        .unwrap_or_else(|e| panic!("{ext}: {e}"));
    (out, warnings.iter().map(ToString::to_string).collect())
}

fn text(ext: &str, mesh: &Mesh, options: &WriteOptions) -> (String, Vec<String>) {
    let (b, w) = bytes(ext, mesh, options);
    (String::from_utf8(b).expect("UTF-8"), w)
}

fn ascii() -> WriteOptions {
    WriteOptions {
        encoding: Some(Encoding::Ascii),
        ..WriteOptions::default()
    }
}

fn binary() -> WriteOptions {
    WriteOptions {
        encoding: Some(Encoding::Binary),
        ..WriteOptions::default()
    }
}

fn meshes() -> Vec<(&'static str, Mesh)> {
    vec![
        ("cube", unit_cube()),
        ("two_cubes", two_cubes()),
        ("split_square", split_square()),
        ("cube_with_probe", cube_with_probe()),
    ]
}

#[test]
fn formats_are_detected_by_extension() {
    let name = |p: &str| writer_for_path(Path::new(p)).map(|w| w.name());
    assert_eq!(name("a/b.gltf"), Some("gltf"));
    assert_eq!(name("b.GLB"), Some("glb"));
    assert_eq!(name("b.obj"), Some("obj"));
    assert_eq!(name("b.stl"), Some("stl"));
    assert_eq!(name("b.msh"), Some("msh"));
    assert_eq!(name("b.vtu"), Some("vtu"));
    assert_eq!(name("b.frag.xml"), Some("frag.xml"));
    assert_eq!(name("b.xml"), None);
    assert_eq!(name("frag.xml"), None, "a bare extension is no file name");
    assert_eq!(name("b.ply"), None);
    assert_eq!(WRITERS.len(), 8);
    let err =
        geomc::formats::write_mesh_file(Path::new("x.ply"), &unit_cube(), &WriteOptions::default())
            .expect_err("unknown format");
    assert!(err.to_string().contains(".frag.xml"), "{err}");
}

#[test]
fn every_writer_is_deterministic() {
    for (name, mesh) in meshes() {
        for writer in WRITERS {
            for options in [WriteOptions::default(), ascii(), binary()] {
                let mut a = Vec::new();
                let mut b = Vec::new();
                writer.write(&mesh, &options, &mut a).expect("write");
                writer
                    .write(&mesh.clone(), &options, &mut b)
                    .expect("write");
                assert!(!a.is_empty(), "{name}.{}", writer.name());
                assert!(a == b, "{name}.{}: two writes differ", writer.name());
            }
        }
    }
}

#[test]
fn invalid_meshes_are_errors_not_panics() {
    let mut mesh = unit_cube();
    mesh.faces[0].triangles[0][1] = 99;
    let mut nan = unit_cube();
    nan.nodes[3][2] = f64::NAN;
    let mut bad_fragment = two_cubes();
    bad_fragment.fragments[0].other = Some(7);
    for m in [mesh, nan, bad_fragment] {
        for writer in WRITERS {
            let err = writer
                .write(&m, &WriteOptions::default(), &mut Vec::new())
                .expect_err("invalid mesh");
            assert!(
                matches!(err, WriteError::InvalidMesh(_)),
                "{}: {err}",
                writer.name()
            );
        }
    }
}

#[test]
fn binary_stl_is_84_plus_50_per_triangle_and_warns_about_merged_groups() {
    let (b, w) = bytes("stl", &unit_cube(), &WriteOptions::default());
    assert_eq!(b.len(), 84 + 50 * 12);
    assert_eq!(u32::from_le_bytes([b[80], b[81], b[82], b[83]]), 12);
    assert!(
        !b.starts_with(b"solid"),
        "a binary header must not look like ASCII STL"
    );
    assert_eq!(
        w,
        ["stl: binary STL has no groups: 3 fragments merged (write ASCII STL to keep them)"]
    );
    // The first facet (inlet, x = 0) has the outward normal −x.
    let f = |o: usize| f32::from_le_bytes([b[o], b[o + 1], b[o + 2], b[o + 3]]);
    assert_eq!([f(84), f(88), f(92)], [-1.0, 0.0, 0.0]);

    let (b, w) = bytes("stl", &two_cubes(), &WriteOptions::default());
    assert_eq!(b.len(), 84 + 50 * 22, "the interface is written once");
    assert_eq!(w.len(), 1);

    let (b, w) = bytes("stl", &split_square(), &WriteOptions::default());
    assert_eq!(b.len(), 84 + 50 * 6);
    assert_eq!(
        w,
        [
            "stl: STL holds only triangles: 3 fragments (edges) not written",
            "stl: binary STL has no groups: 2 regions merged (write ASCII STL to keep them)"
        ]
    );
    let (_, w) = bytes("stl", &cube_with_probe(), &WriteOptions::default());
    assert_eq!(
        w[0],
        "stl: STL holds only triangles: 1 poly_line, 1 point set not written"
    );
}

#[test]
fn ascii_stl_has_one_solid_per_fragment() {
    let (t, w) = text("stl", &unit_cube(), &ascii());
    assert!(w.is_empty(), "{w:?}");
    let mut facets: BTreeMap<String, usize> = BTreeMap::new();
    let mut current = String::new();
    for line in t.lines() {
        let line = line.trim();
        if let Some(name) = line.strip_prefix("solid ") {
            current = name.to_string();
        } else if line.starts_with("facet normal") {
            *facets.entry(current.clone()).or_default() += 1;
        }
    }
    assert_eq!(
        facets,
        BTreeMap::from([
            ("inlet".into(), 2),
            ("outlet".into(), 2),
            ("walls".into(), 8)
        ])
    );
    assert_eq!(t.matches("endsolid").count(), 3);
}

/// Per `o` object of an OBJ file: (faces, line elements, points), and the
/// number of `v` and `vn` lines.
fn parse_obj(t: &str) -> (BTreeMap<String, (usize, usize, usize)>, usize, usize) {
    let mut objects: BTreeMap<String, (usize, usize, usize)> = BTreeMap::new();
    let (mut v, mut vn) = (0, 0);
    let mut current = String::new();
    for line in t.lines() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("o") => current = words.next().unwrap_or("").to_string(),
            Some("v") => v += 1,
            Some("vn") => vn += 1,
            Some("f") => {
                // Every corner is v//vn with both in range.
                for corner in words {
                    let (a, b) = corner.split_once("//").expect("v//vn");
                    let a: usize = a.parse().expect("v index");
                    let b: usize = b.parse().expect("vn index");
                    assert!(a >= 1 && a <= v && b >= 1 && b <= vn, "{line}");
                }
                objects.entry(current.clone()).or_default().0 += 1;
            }
            Some("l") => objects.entry(current.clone()).or_default().1 += words.count() - 1,
            Some("p") => objects.entry(current.clone()).or_default().2 += words.count(),
            _ => {}
        }
    }
    (objects, v, vn)
}

#[test]
fn obj_has_an_object_per_fragment_with_normals_per_face() {
    let (t, w) = text("obj", &unit_cube(), &WriteOptions::default());
    assert_eq!(
        w,
        ["obj: OBJ has no volumes: 1 subdomain carried only as the sides of the fragment objects"]
    );
    let (objects, v, vn) = parse_obj(&t);
    assert_eq!(v, 8);
    assert_eq!(vn, 24, "4 normals per face: flat across the cube's edges");
    assert_eq!(objects["inlet"], (2, 0, 0));
    assert_eq!(objects["outlet"], (2, 0, 0));
    assert_eq!(objects["walls"], (8, 0, 0));
    assert_eq!(objects.len(), 3 + 12, "plus one line object per edge");
    assert_eq!(objects["e0"], (0, 1, 0));
    assert_eq!(
        t.matches("\ng ").count(),
        6,
        "a g per face inside the fragments"
    );

    let (t, _) = text("obj", &cube_with_probe(), &WriteOptions::default());
    let (objects, v, _) = parse_obj(&t);
    assert_eq!(v, 13);
    assert_eq!(objects["probe"], (0, 2, 0));
    assert_eq!(objects["sensors"], (0, 0, 2));

    let (t, w) = text("obj", &split_square(), &WriteOptions::default());
    assert!(w.is_empty(), "{w:?}");
    let (objects, _, _) = parse_obj(&t);
    assert_eq!(objects["left"], (3, 0, 0));
    assert_eq!(objects["right"], (3, 0, 0));
    assert_eq!(objects["left|exterior"], (0, 3, 0));
    assert_eq!(objects["left|right"], (0, 2, 0));
}

/// What an ASCII MSH 4.1 file holds: physical names by (dim, tag), element
/// counts by physical name, the number of nodes, and the entity counts.
struct MshSummary {
    groups: BTreeMap<String, (i32, usize)>,
    nodes: usize,
    entities: [usize; 4],
    elements: usize,
    volume_boundaries: Vec<Vec<i32>>,
}

fn parse_msh(t: &str) -> MshSummary {
    let section = |name: &str| -> Vec<&str> {
        let start = t
            .find(&format!("${name}\n"))
            .unwrap_or_else(|| panic!("no ${name}"));
        let end = t.find(&format!("$End{name}")).expect("section end");
        t[start..end].lines().skip(1).collect()
    };
    assert_eq!(section("MeshFormat"), ["4.1 0 8"]);
    let mut names: BTreeMap<(i32, i32), String> = BTreeMap::new();
    for line in section("PhysicalNames").iter().skip(1) {
        let mut w = line.splitn(3, ' ');
        let dim = w.next().and_then(|x| x.parse().ok()).expect("dim");
        let tag = w.next().and_then(|x| x.parse().ok()).expect("tag");
        names.insert(
            (dim, tag),
            w.next().expect("name").trim_matches('"').to_string(),
        );
    }
    let ints = |line: &str| -> Vec<f64> {
        line.split_whitespace()
            .map(|x| x.parse().expect("number"))
            .collect()
    };
    let entity_lines = section("Entities");
    let counts = ints(entity_lines[0]);
    let entities = [0, 1, 2, 3].map(|d| counts[d] as usize);
    // Physical tags per (dim, entity tag); volume boundaries.
    let mut physicals: BTreeMap<(i32, i32), Vec<i32>> = BTreeMap::new();
    let mut volume_boundaries = Vec::new();
    let mut line = 1;
    for (dim, &count) in entities.iter().enumerate() {
        for _ in 0..count {
            let v = ints(entity_lines[line]);
            line += 1;
            let at = if dim == 0 { 4 } else { 7 };
            let n = v[at] as usize;
            let tags = v[at + 1..at + 1 + n].iter().map(|x| *x as i32).collect();
            physicals.insert((dim as i32, v[0] as i32), tags);
            if dim == 3 {
                let m = v[at + 1 + n] as usize;
                volume_boundaries.push(
                    v[at + 2 + n..at + 2 + n + m]
                        .iter()
                        .map(|x| *x as i32)
                        .collect(),
                );
            }
        }
    }
    let mut groups: BTreeMap<String, (i32, usize)> = names
        .iter()
        .map(|((d, _), n)| (n.clone(), (*d, 0)))
        .collect();
    let el = section("Elements");
    let header = ints(el[0]);
    let mut i = 1;
    for _ in 0..header[0] as usize {
        let b = ints(el[i]);
        let n = b[3] as usize;
        for p in &physicals[&(b[0] as i32, b[1] as i32)] {
            groups
                .get_mut(&names[&(b[0] as i32, *p)])
                .expect("named group")
                .1 += n;
        }
        i += 1 + n;
    }
    assert_eq!(i, el.len(), "element blocks fill the section");
    MshSummary {
        groups,
        nodes: ints(section("Nodes")[0])[1] as usize,
        entities,
        elements: header[1] as usize,
        volume_boundaries,
    }
}

#[test]
fn msh_carries_topology_and_every_group() {
    let (t, w) = text("msh", &unit_cube(), &WriteOptions::default());
    assert!(w.is_empty(), "{w:?}");
    let s = parse_msh(&t);
    assert_eq!(s.entities, [8, 12, 6, 1]);
    assert_eq!(s.nodes, 8);
    assert_eq!(s.elements, 12);
    assert_eq!(s.groups["inlet"], (2, 2));
    assert_eq!(s.groups["outlet"], (2, 2));
    assert_eq!(s.groups["walls"], (2, 8));
    assert_eq!(
        s.groups["cube"],
        (3, 0),
        "a volume group with no elements yet"
    );
    assert_eq!(s.volume_boundaries, [vec![1, 2, 3, 4, 5, 6]]);

    let s = parse_msh(&text("msh", &two_cubes(), &WriteOptions::default()).0);
    assert_eq!(s.entities, [12, 20, 11, 2]);
    assert_eq!(s.groups["left|right"], (2, 2));
    assert_eq!(s.groups["left|exterior"], (2, 10));
    assert_eq!(s.groups["right|exterior"], (2, 10));
    assert_eq!(s.groups["left"], (3, 0));
    // The shared face (surface 2) bounds `right` inward.
    assert_eq!(s.volume_boundaries[1], [-2, 7, 8, 9, 10, 11]);

    let s = parse_msh(&text("msh", &split_square(), &WriteOptions::default()).0);
    assert_eq!(s.entities, [6, 7, 2, 0]);
    assert_eq!(s.nodes, 7);
    assert_eq!(s.groups["left"], (2, 3));
    assert_eq!(s.groups["right"], (2, 3));
    assert_eq!(s.groups["left|exterior"], (1, 3));
    assert_eq!(s.groups["left|right"], (1, 2));
    assert_eq!(s.groups["right|exterior"], (1, 3));

    let s = parse_msh(&text("msh", &cube_with_probe(), &WriteOptions::default()).0);
    assert_eq!(s.entities, [10, 13, 6, 1]);
    assert_eq!(s.nodes, 13);
    assert_eq!(s.groups["probe"], (1, 2));
    assert_eq!(s.groups["sensors"], (0, 2));
}

#[test]
fn binary_msh_has_the_binary_header_and_ascii_names() {
    let (b, _) = bytes("msh", &two_cubes(), &binary());
    assert!(b.starts_with(b"$MeshFormat\n4.1 1 8\n\x01\x00\x00\x00\n$EndMeshFormat\n"));
    let t = String::from_utf8_lossy(&b);
    assert!(
        t.contains("$PhysicalNames\n5\n2 1 \"left|exterior\"\n"),
        "{t}"
    );
    assert!(t.ends_with("\n$EndElements\n"));
}

#[test]
fn vtu_has_cells_and_id_fields() {
    let (t, w) = text("vtu", &two_cubes(), &WriteOptions::default());
    assert_eq!(
        w,
        [
            "vtu: VTU carries fragment and subdomain numbers, not names: write a .frag.xml beside it for the names"
        ]
    );
    assert!(
        t.contains("<Piece NumberOfPoints=\"12\" NumberOfCells=\"42\">"),
        "22 triangles + 20 edges"
    );
    for field in [
        "fragment_id",
        "subdomain_id",
        "other_subdomain_id",
        "face_id",
        "edge_id",
    ] {
        assert!(t.contains(&format!("Name=\"{field}\"")), "{field}");
    }
    let (b, _) = text("vtu", &two_cubes(), &binary());
    // Every data array is binary; only the short FieldData names stay text.
    assert!(b.contains("format=\"binary\"") && !b.contains("format=\"ascii\">\n"));
}

/// The glTF JSON of a `.glb`.
fn glb_json(b: &[u8]) -> serde_json::Value {
    assert_eq!(&b[0..4], b"glTF");
    assert_eq!(
        u32::from_le_bytes([b[8], b[9], b[10], b[11]]) as usize,
        b.len()
    );
    let n = u32::from_le_bytes([b[12], b[13], b[14], b[15]]) as usize;
    assert_eq!(&b[16..20], b"JSON");
    serde_json::from_slice(&b[20..20 + n]).expect("JSON chunk")
}

#[test]
fn gltf_has_a_node_per_fragment_and_subdomain_with_extras() {
    let (b, w) = bytes("glb", &two_cubes(), &WriteOptions::default());
    assert!(w.is_empty(), "{w:?}");
    let j = glb_json(&b);
    let nodes = j["nodes"].as_array().expect("nodes");
    let by_name = |name: &str| {
        nodes
            .iter()
            .filter(|n| n["name"] == name && n.get("mesh").is_some())
            .collect::<Vec<_>>()
    };
    let interface = by_name("left|right");
    assert_eq!(interface.len(), 1);
    assert_eq!(interface[0]["extras"]["subdomain"], "left");
    assert_eq!(interface[0]["extras"]["other"], "right");
    assert_eq!(by_name("left|exterior")[0]["extras"]["other"], "exterior");
    // `left` and `right` each: a subdomain surface node of 12 triangles.
    let left = by_name("left");
    assert_eq!(left.len(), 1);
    assert_eq!(left[0]["extras"]["material"], "steel");
    let mesh = &j["meshes"][left[0]["mesh"].as_u64().expect("mesh") as usize];
    let prim = &mesh["primitives"][0];
    let indices = &j["accessors"][prim["indices"].as_u64().expect("indices") as usize];
    assert_eq!(indices["count"], 36);
    let position =
        &j["accessors"][prim["attributes"]["POSITION"].as_u64().expect("position") as usize];
    assert_eq!(
        position["count"], 24,
        "4 vertices per face: normals flat across edges"
    );
    assert_eq!(position["min"], serde_json::json!([0.0, 0.0, 0.0]));
    assert_eq!(position["max"], serde_json::json!([1.0, 1.0, 1.0]));
    let parents: Vec<&str> = j["scenes"][0]["nodes"]
        .as_array()
        .expect("scene")
        .iter()
        .map(|i| {
            nodes[i.as_u64().expect("index") as usize]["name"]
                .as_str()
                .expect("name")
        })
        .collect();
    assert_eq!(parents, ["surfaces", "subdomains", "lines"]);

    // Points and lines of the probe mesh.
    let j = glb_json(&bytes("glb", &cube_with_probe(), &WriteOptions::default()).0);
    let mode = |name: &str| {
        let node = j["nodes"]
            .as_array()
            .expect("nodes")
            .iter()
            .find(|n| n["name"] == name)
            .expect("node");
        j["meshes"][node["mesh"].as_u64().expect("mesh") as usize]["primitives"][0]["mode"].clone()
    };
    assert_eq!(mode("probe"), 1);
    assert_eq!(mode("sensors"), 0);
    assert_eq!(mode("walls"), 4);
}

#[test]
fn gltf_without_a_file_name_embeds_its_buffer_and_with_one_writes_a_bin() {
    let (t, _) = text("gltf", &unit_cube(), &WriteOptions::default());
    assert!(t.contains("\"uri\": \"data:application/octet-stream;base64,"));
    let dir = tempfile::tempdir().expect("temp dir");
    let (path, _) = write(
        dir.path(),
        "my cube.gltf",
        &unit_cube(),
        &WriteOptions::default(),
    );
    let j: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&path).expect("gltf")).expect("JSON");
    assert_eq!(j["buffers"][0]["uri"], "my%20cube.bin");
    let bin = std::fs::read(dir.path().join("my cube.bin")).expect("the .bin side file");
    assert_eq!(j["buffers"][0]["byteLength"], bin.len());
}

#[test]
fn frag_xml_round_trips_and_holds_the_incidence_matrices() {
    for (name, mesh) in meshes() {
        let options = WriteOptions {
            mesh_file: Some(format!("{name}.msh")),
            ..WriteOptions::default()
        };
        let (t, w) = text("frag.xml", &mesh, &options);
        assert!(w.is_empty(), "{w:?}");
        let read = read_frag_xml("x.frag.xml", &t).unwrap_or_else(|e| panic!("{name}: {e}"));
        let expected = geomc::formats::frag::frag_document(&mesh, Some(format!("{name}.msh")))
            .expect("document");
        assert_eq!(read, expected, "{name}");
    }
    let doc = geomc::formats::frag::frag_document(&two_cubes(), None).expect("document");
    assert_eq!(
        (doc.m_ve.rows, doc.m_ve.cols, doc.m_ve.entries.len()),
        (12, 20, 40)
    );
    assert_eq!(
        (doc.m_ef.rows, doc.m_ef.cols, doc.m_ef.entries.len()),
        (20, 11, 44)
    );
    assert_eq!(
        (doc.m_fd.rows, doc.m_fd.cols, doc.m_fd.entries.len()),
        (11, 2, 12)
    );
    assert!(
        doc.m_fd.entries.contains(&(1, 1, -1)),
        "the shared face is inward for `right`"
    );
    let interface = &doc.fragments[1];
    assert_eq!(
        (interface.name.as_str(), interface.other),
        ("left|right", Some(1))
    );
    assert_eq!((interface.elements, interface.measure), (2, 1.0));
    assert_eq!(doc.faces[0].area, 1.0);

    let square = geomc::formats::frag::frag_document(&split_square(), None).expect("document");
    assert_eq!(
        square.fragments[1].elements, 2,
        "the middle edge has two segments"
    );
    assert_eq!(square.edges[6].segments, 2);

    let (_, w) = text("frag.xml", &unit_cube(), &WriteOptions::default());
    assert_eq!(
        w,
        ["frag.xml: no mesh file given: the document refers to none"]
    );
    let mut odd = unit_cube();
    odd.faces[0].name = "a<b>&\"c\"\u{1}".into();
    let (t, w) = text("frag.xml", &odd, &WriteOptions::default());
    assert_eq!(w.len(), 2, "{w:?}");
    let read = read_frag_xml("odd", &t).expect("escaped names read back");
    assert_eq!(read.faces[0].name, "a<b>&\"c\"\u{FFFD}");

    let err = read_frag_xml(
        "bad.frag.xml",
        "<frag version=\"1\" dimension=\"3\" nodes=\"x\"/>",
    )
    .expect_err("bad");
    assert!(err.to_string().starts_with("bad.frag.xml:1:1:"), "{err}");
}

#[test]
fn atomic_writes_leave_nothing_partial() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("out.stl");
    std::fs::write(&path, b"old").expect("seed");
    let err = write_atomic(&path, |w| {
        w.write_all(b"half")?;
        Err::<(), _>(WriteError::Unsupported("stop".into()))
    });
    assert!(err.is_err());
    assert_eq!(
        std::fs::read(&path).expect("old file"),
        b"old",
        "the old file stays"
    );
    let leftovers: Vec<_> = std::fs::read_dir(dir.path()).expect("dir").collect();
    assert_eq!(leftovers.len(), 1, "no temporary file is left");

    // An invalid mesh through the registry: no output at all, no side file.
    let mut bad = unit_cube();
    bad.faces[0].triangles[0][0] = 1000;
    let gltf = dir.path().join("bad.gltf");
    assert!(geomc::formats::write_mesh_file(&gltf, &bad, &WriteOptions::default()).is_err());
    assert!(!gltf.exists() && !dir.path().join("bad.bin").exists());
    assert_eq!(std::fs::read_dir(dir.path()).expect("dir").count(), 1);

    let (path, _) = write(
        dir.path(),
        "cube.stl",
        &unit_cube(),
        &WriteOptions::default(),
    );
    assert_eq!(
        std::fs::metadata(path).expect("written").len(),
        84 + 50 * 12
    );
}
