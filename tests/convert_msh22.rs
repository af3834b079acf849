//! Gmsh MSH 2.2 output (`--to msh22`) and the bounding surfaces of volume
//! entities in MSH 4.1 output, checked against gmsh and meshio: a gmsh-made
//! MSH 4.1 volume mesh (two tetrahedralized boxes, physical volumes `left`
//! and `right`, surfaces `outer` and `interface`, `tests/tools/
//! make_volume_meshes.py`) is converted and read back by geomc, gmsh and
//! meshio (`tests/tools/check_mesh.py`).

mod writers_common;

use geomc::formats::read::{Loaded, load_mesh};
use geomc::formats::{Encoding, WRITERS, WriteOptions, write_atomic, write_mesh_file};
use geomc::mesh::CellKind;
use serde_json::Value;
use std::collections::BTreeMap;
use std::path::Path;
use std::process::Command;
use writers_common::run_json;

fn load(path: &Path) -> Loaded {
    load_mesh(path).unwrap_or_else(|d| panic!("{}: {d:?}", path.display()))
}

fn options(encoding: Encoding) -> WriteOptions {
    WriteOptions {
        encoding: Some(encoding),
        ..WriteOptions::default()
    }
}

/// Each face group's triangles as sorted corner coordinates (bit patterns),
/// and each volume group's cells the same way: membership independent of
/// node numbering.
type Members = BTreeMap<String, Vec<Vec<[u64; 3]>>>;

fn members(l: &Loaded) -> (Members, Members) {
    let corners = |nodes: &[u32]| {
        let mut c: Vec<[u64; 3]> = nodes
            .iter()
            .map(|&n| l.mesh.nodes[n as usize].map(f64::to_bits))
            .collect();
        c.sort_unstable();
        c
    };
    let mut faces = Members::new();
    for f in &l.mesh.faces {
        let e = faces.entry(f.name.clone()).or_default();
        e.extend(f.triangles.iter().map(|t| corners(t)));
        e.sort_unstable();
    }
    let mut cells = Members::new();
    for v in &l.mesh.volumes {
        let e = cells.entry(v.name.clone()).or_default();
        e.extend(v.cells().map(corners));
        e.sort_unstable();
    }
    (faces, cells)
}

fn gmsh_group<'a>(report: &'a Value, name: &str) -> &'a Value {
    report["gmsh"]["groups"]
        .as_array()
        .and_then(|a| a.iter().find(|g| g["name"] == name))
        .unwrap_or_else(|| panic!("gmsh has no group `{name}`: {report:#}"))
}

#[test]
fn msh22_round_trip_and_external_readers() {
    let dir = tempfile::tempdir().expect("temp dir");
    let facts = run_json("python3", "make_volume_meshes.py", &[dir.path()]);
    let at = |name: &str| dir.path().join(name);
    let source = load(&at("tets41.msh"));
    let f = &facts["tets41.msh"];
    let count = |group: &str, element: &str| f["groups"][group]["elements"][element].clone();
    let msh22 = *WRITERS
        .iter()
        .find(|w| w.name() == "msh22")
        .expect("an msh22 writer");
    assert!(msh22.keeps_volume_cells());

    for (name, encoding) in [("a22.msh", Encoding::Ascii), ("b22.msh", Encoding::Binary)] {
        let path = at(name);
        write_atomic(&path, |w| msh22.write(&source.mesh, &options(encoding), w))
            .expect("write MSH 2.2");
        let bytes = std::fs::read(&path).expect("read back");
        let head = if encoding == Encoding::Binary {
            "$MeshFormat\n2.2 1 8\n"
        } else {
            "$MeshFormat\n2.2 0 8\n"
        };
        assert!(bytes.starts_with(head.as_bytes()), "{name}");

        // geomc reads it back as it was.
        let back = load(&path);
        assert_eq!(back.binary, Some(encoding == Encoding::Binary), "{name}");
        assert_eq!(back.mesh.nodes, source.mesh.nodes, "{name}: coordinates");
        assert_eq!(members(&back), members(&source), "{name}: groups");
        let kinds: Vec<(&str, CellKind, usize)> = back
            .mesh
            .volumes
            .iter()
            .map(|v| (v.name.as_str(), v.kind, v.count()))
            .collect();
        assert_eq!(
            kinds,
            [
                (
                    "left",
                    CellKind::Tetrahedron,
                    count("left", "tetrahedron").as_u64().unwrap_or(0) as usize
                ),
                (
                    "right",
                    CellKind::Tetrahedron,
                    count("right", "tetrahedron").as_u64().unwrap_or(0) as usize
                ),
            ],
            "{name}"
        );

        // gmsh: the physical groups with gmsh's own element counts.
        let report = run_json("python3", "check_mesh.py", &[&path]);
        for (group, element) in [
            ("left", "tetrahedron"),
            ("right", "tetrahedron"),
            ("outer", "triangle"),
            ("interface", "triangle"),
        ] {
            assert_eq!(
                gmsh_group(&report, group)["elements"][element],
                count(group, element),
                "{name}: gmsh, {group}"
            );
        }
        assert_eq!(
            report["gmsh"]["nodes"], f["nodes"],
            "{name}: gmsh node count"
        );
        // meshio: the same cells, and the named sets.
        let tets = count("left", "tetrahedron").as_u64().unwrap_or(0)
            + count("right", "tetrahedron").as_u64().unwrap_or(0);
        let tris = count("outer", "triangle").as_u64().unwrap_or(0)
            + count("interface", "triangle").as_u64().unwrap_or(0);
        assert_eq!(report["meshio"]["cells"]["tetra"], tets, "{name}");
        assert_eq!(report["meshio"]["cells"]["triangle"], tris, "{name}");
        assert_eq!(report["meshio"]["points"], f["nodes"], "{name}");
        // meshio keeps MSH 2.2 names as field data (name -> [tag, dim]) and
        // each cell's physical tag: every group has its name and its cells.
        for (group, element) in [
            ("left", "tetrahedron"),
            ("right", "tetrahedron"),
            ("outer", "triangle"),
            ("interface", "triangle"),
        ] {
            let field = &report["meshio_physical"]["field_data"][group];
            let key = format!("{}:{}", field[1], field[0]);
            assert_eq!(
                report["meshio_physical"]["physical_cells"][&key],
                count(group, element),
                "{name}: meshio, {group} ({key})"
            );
        }
    }

    // The command line: `--to msh22` on a `.msh` output, binary on request.
    let out = Command::new(env!("CARGO_BIN_EXE_geomc"))
        .current_dir(dir.path())
        .args([
            "convert",
            "--to",
            "msh22",
            "--binary",
            "tets41.msh",
            "cli22.msh",
        ])
        .output()
        .expect("run geomc");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let cli = std::fs::read(at("cli22.msh")).expect("cli output");
    assert!(cli.starts_with(b"$MeshFormat\n2.2 1 8\n"));
    assert_eq!(cli, std::fs::read(at("b22.msh")).expect("b22"));
}

#[test]
fn msh41_volume_entities_list_their_bounding_surfaces() {
    let dir = tempfile::tempdir().expect("temp dir");
    let facts = run_json("python3", "make_volume_meshes.py", &[dir.path()]);
    let at = |name: &str| dir.path().join(name);
    let source = load(&at("tets41.msh"));
    let face = |name: &str| {
        source
            .mesh
            .faces
            .iter()
            .position(|f| f.name == name)
            .unwrap_or_else(|| panic!("no face `{name}`")) as i64
            + 1
    };
    let (outer, interface) = (face("outer"), face("interface"));
    let names: Vec<&str> = source
        .mesh
        .volumes
        .iter()
        .map(|v| v.name.as_str())
        .collect();
    assert_eq!(names, ["left", "right"]);
    for (name, encoding) in [("a41.msh", Encoding::Ascii), ("b41.msh", Encoding::Binary)] {
        let path = at(name);
        write_mesh_file(&path, &source.mesh, &options(encoding)).expect("write MSH 4.1");
        let report = run_json("python3", "check_mesh.py", &[&path]);
        let bounds = |tag: &str| -> Vec<i64> {
            report["gmsh"]["volume_boundaries"][tag]
                .as_array()
                .map(|a| a.iter().filter_map(Value::as_i64).collect())
                .unwrap_or_default()
        };
        // Volume entity 1 holds `left`, 2 `right`: each is bounded by the
        // outer surface and by the interface, which points out of one box
        // and into the other.
        let (left, right) = (bounds("1"), bounds("2"));
        let abs = |v: &[i64]| {
            let mut a: Vec<i64> = v.iter().map(|t| t.abs()).collect();
            a.sort_unstable();
            a
        };
        let mut both = vec![outer, interface];
        both.sort_unstable();
        assert_eq!(abs(&left), both, "{name}: left {left:?}");
        assert_eq!(abs(&right), both, "{name}: right {right:?}");
        let sign = |v: &[i64]| v.iter().find(|t| t.abs() == interface).map(|t| t.signum());
        assert_eq!(
            sign(&left),
            sign(&right).map(|s| -s),
            "{name}: interface sides"
        );
        // meshio still reads the file, cells and sets.
        let f = &facts["tets41.msh"];
        let tets = f["groups"]["left"]["elements"]["tetrahedron"]
            .as_u64()
            .unwrap_or(0)
            + f["groups"]["right"]["elements"]["tetrahedron"]
                .as_u64()
                .unwrap_or(0);
        assert_eq!(report["meshio"]["cells"]["tetra"], tets, "{name}");
        assert_eq!(
            report["meshio"]["cell_sets"]["interface"],
            f["groups"]["interface"]["elements"]["triangle"],
            "{name}"
        );
        // And geomc reads its own file back with the same groups.
        assert_eq!(members(&load(&path)), members(&source), "{name}");
    }
}
