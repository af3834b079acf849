//! Round trips A → B → A through every pair of formats: the triangle groups
//! (names and triangle counts), poly_lines and point sets where both formats
//! hold them, node counts and coordinates survive. Binary STL, which has no
//! groups, merges them with a warning.

mod writers_common;

use geomc::formats::read::{Loaded, load_mesh};
use geomc::formats::{Encoding, WriteOptions, write_mesh_file};
use geomc::mesh::Mesh;
use std::collections::BTreeMap;
use std::path::Path;
use writers_common::{cube_with_probe, two_cubes, unit_cube};

/// A format as the test writes it: file ending, encoding, and what it holds.
#[derive(Clone, Copy, Debug)]
struct Fmt {
    ext: &'static str,
    encoding: Option<Encoding>,
    groups: bool,
    lines: bool,
}

const FORMATS: [Fmt; 9] = [
    Fmt {
        ext: "stl",
        encoding: Some(Encoding::Ascii),
        groups: true,
        lines: false,
    },
    Fmt {
        ext: "stl",
        encoding: Some(Encoding::Binary),
        groups: false,
        lines: false,
    },
    Fmt {
        ext: "obj",
        encoding: None,
        groups: true,
        lines: true,
    },
    Fmt {
        ext: "gltf",
        encoding: None,
        groups: true,
        lines: true,
    },
    Fmt {
        ext: "glb",
        encoding: None,
        groups: true,
        lines: true,
    },
    Fmt {
        ext: "msh",
        encoding: Some(Encoding::Ascii),
        groups: true,
        lines: true,
    },
    Fmt {
        ext: "msh",
        encoding: Some(Encoding::Binary),
        groups: true,
        lines: true,
    },
    Fmt {
        ext: "vtu",
        encoding: Some(Encoding::Ascii),
        groups: true,
        lines: true,
    },
    Fmt {
        ext: "vtu",
        encoding: Some(Encoding::Binary),
        groups: true,
        lines: true,
    },
];

fn write(dir: &Path, stem: &str, mesh: &Mesh, f: Fmt) -> (std::path::PathBuf, Vec<String>) {
    let tag = match f.encoding {
        Some(Encoding::Ascii) => "a",
        Some(Encoding::Binary) => "b",
        None => "x",
    };
    let path = dir.join(format!("{stem}_{tag}.{}", f.ext));
    let options = WriteOptions {
        encoding: f.encoding,
        ..WriteOptions::default()
    };
    let warnings = write_mesh_file(&path, mesh, &options)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    (path, warnings.iter().map(ToString::to_string).collect())
}

fn load(path: &Path) -> Loaded {
    load_mesh(path).unwrap_or_else(|d| panic!("{}: {d:?}", path.display()))
}

/// Triangle groups: name → triangle count.
fn triangle_groups(mesh: &Mesh) -> BTreeMap<String, usize> {
    mesh.faces
        .iter()
        .map(|f| (f.name.clone(), f.triangles.len()))
        .collect()
}

/// Line and point groups: name → element count.
fn other_groups(mesh: &Mesh) -> BTreeMap<String, usize> {
    let mut out = BTreeMap::new();
    for p in &mesh.polylines {
        *out.entry(format!("line {}", p.name)).or_default() += p.nodes.len() - 1;
    }
    for p in &mesh.point_sets {
        *out.entry(format!("points {}", p.name)).or_default() += p.nodes.len();
    }
    out
}

/// Sorted triangles as coordinate triples, rotated to start at the smallest
/// corner so orientation is compared too.
fn geometry(mesh: &Mesh) -> Vec<[[i64; 3]; 3]> {
    let q = |n: u32| mesh.nodes[n as usize].map(|c| (c * 1e5).round() as i64);
    let mut out: Vec<[[i64; 3]; 3]> = mesh
        .faces
        .iter()
        .flat_map(|f| &f.triangles)
        .map(|t| {
            let c = t.map(q);
            let k = (0..3).min_by_key(|&k| c[k]).unwrap_or(0);
            [c[k], c[(k + 1) % 3], c[(k + 2) % 3]]
        })
        .collect();
    out.sort();
    out
}

fn check_pair(mesh: &Mesh, stem: &str, a: Fmt, b: Fmt) {
    let dir = tempfile::tempdir().expect("temp dir");
    let (pa, _) = write(dir.path(), &format!("{stem}_1"), mesh, a);
    let first = load(&pa);
    let (pb, warnings_b) = write(dir.path(), &format!("{stem}_2"), &first.mesh, b);
    let second = load(&pb);
    let (pa2, _) = write(dir.path(), &format!("{stem}_3"), &second.mesh, a);
    let third = load(&pa2);
    let what = format!(
        "{stem}: {} {:?} -> {} {:?} -> back",
        a.ext, a.encoding, b.ext, b.encoding
    );

    // Coordinates and triangles survive every trip (within f32 rounding).
    assert_eq!(
        geometry(&first.mesh),
        geometry(&third.mesh),
        "{what}: triangles"
    );
    assert_eq!(
        geometry(&first.mesh),
        geometry(mesh),
        "{what}: the first read"
    );
    if b.lines || other_groups(&first.mesh).is_empty() {
        assert_eq!(
            first.mesh.nodes.len(),
            third.mesh.nodes.len(),
            "{what}: nodes"
        );
    } else {
        // Only the triangles' nodes pass through a format without lines.
        let used: std::collections::BTreeSet<u32> = first
            .mesh
            .faces
            .iter()
            .flat_map(|f| f.triangles.iter().flatten().copied())
            .collect();
        assert_eq!(third.mesh.nodes.len(), used.len(), "{what}: nodes");
        assert!(other_groups(&second.mesh).is_empty(), "{what}");
    }

    let groups = triangle_groups(&first.mesh);
    if b.groups {
        assert_eq!(triangle_groups(&second.mesh), groups, "{what}: groups in B");
        assert_eq!(
            triangle_groups(&third.mesh),
            groups,
            "{what}: groups back in A"
        );
    } else if groups.len() > 1 {
        let total: usize = groups.values().sum();
        assert_eq!(
            triangle_groups(&second.mesh),
            BTreeMap::from([("surface".to_string(), total)]),
            "{what}"
        );
        assert!(
            warnings_b
                .iter()
                .any(|w| w.contains("binary STL has no groups")),
            "{what}: no warning about merged groups: {warnings_b:?}"
        );
    }
    if a.lines && b.lines {
        assert_eq!(
            other_groups(&second.mesh),
            other_groups(&first.mesh),
            "{what}: lines and points"
        );
        assert_eq!(
            other_groups(&third.mesh),
            other_groups(&first.mesh),
            "{what}: lines and points back"
        );
    }
}

#[test]
fn every_pair_of_formats_keeps_groups_and_counts() {
    for (stem, mesh) in [
        ("cube", unit_cube()),
        ("probe", cube_with_probe()),
        ("two", two_cubes()),
    ] {
        for a in FORMATS {
            for b in FORMATS {
                check_pair(&mesh, stem, a, b);
            }
        }
    }
}

#[test]
fn the_unit_cube_reads_back_with_its_fragments() {
    let dir = tempfile::tempdir().expect("temp dir");
    let mesh = unit_cube();
    let expected = BTreeMap::from([
        ("inlet".to_string(), 2),
        ("outlet".to_string(), 2),
        ("walls".to_string(), 8),
    ]);
    for f in FORMATS.iter().filter(|f| f.groups) {
        let (path, _) = write(dir.path(), "cube", &mesh, *f);
        let loaded = load(&path);
        assert_eq!(
            triangle_groups(&loaded.mesh),
            expected,
            "{}",
            path.display()
        );
        assert_eq!(loaded.mesh.nodes.len(), 8, "{}", path.display());
        // A closed, consistently oriented cube: no surface warnings.
        assert!(
            loaded.report.whole.watertight(),
            "{}: {:?}",
            path.display(),
            loaded.report.whole
        );
        assert_eq!(loaded.report.whole.edges, 18, "{}", path.display());
    }
    // glTF carries the subdomain pair of each fragment in its extras.
    let (glb, _) = write(dir.path(), "cube", &mesh, FORMATS[4]);
    let loaded = load(&glb);
    assert_eq!(loaded.mesh.subdomains.len(), 1);
    assert_eq!(loaded.mesh.subdomains[0].name, "cube");
    assert_eq!(loaded.mesh.fragments.len(), 3);
    assert!(loaded.mesh.fragments.iter().all(|f| f.other.is_none()));
}

#[test]
fn a_frag_xml_puts_faces_subdomains_and_fragments_back_on_its_mesh() {
    let dir = tempfile::tempdir().expect("temp dir");
    let mesh = two_cubes();
    for mesh_name in ["two.vtu", "two.msh"] {
        let mesh_path = dir.path().join(mesh_name);
        write_mesh_file(&mesh_path, &mesh, &WriteOptions::default()).expect("mesh");
        let frag = dir.path().join(format!("{mesh_name}.frag.xml"));
        let options = WriteOptions {
            mesh_file: Some(mesh_name.to_string()),
            ..WriteOptions::default()
        };
        write_mesh_file(&frag, &mesh, &options).expect("frag");
        let loaded = load(&frag);
        let names: Vec<&str> = loaded
            .mesh
            .subdomains
            .iter()
            .map(|s| s.name.as_str())
            .collect();
        assert_eq!(names, ["left", "right"], "{mesh_name}");
        let fragments: BTreeMap<&str, (u32, Option<u32>)> = loaded
            .mesh
            .fragments
            .iter()
            .map(|f| (f.name.as_str(), (f.subdomain, f.other)))
            .collect();
        assert_eq!(
            fragments,
            BTreeMap::from([
                ("left|exterior", (0, None)),
                ("left|right", (0, Some(1))),
                ("right|exterior", (1, None)),
            ]),
            "{mesh_name}"
        );
        // Each subdomain's boundary: 6 faces' worth of triangles.
        for s in &loaded.mesh.subdomains {
            let n: usize = s
                .faces
                .iter()
                .map(|&(f, _)| loaded.mesh.faces[f as usize].triangles.len())
                .sum();
            assert_eq!(n, 12, "{mesh_name}: {}", s.name);
        }
    }
}
