//! Volume cells through `geomc convert`: meshes tetrahedralized, extruded
//! (hexahedra, prisms) and hand-built (a pyramid) by gmsh itself
//! (`tests/tools/make_volume_meshes.py`) keep their cells, physical volumes
//! and volumes from MSH 4.1 / 2.2 to VTU and MSH 4.1 and back; gmsh and
//! meshio read the results (`tests/tools/check_mesh.py`); surface formats
//! say how many cells they drop.

mod writers_common;

use geomc::formats::read::{Loaded, load_mesh};
use geomc::formats::{Encoding, WriteOptions, write_mesh_file};
use geomc::mesh::CellKind;
use geomc::mesh::volume::cell_volume;
use serde_json::Value;
use std::collections::BTreeMap;
use std::path::Path;
use std::process::Command;
use writers_common::run_json;

fn load(path: &Path) -> Loaded {
    load_mesh(path).unwrap_or_else(|d| panic!("{}: {d:?}", path.display()))
}

/// (group, kind) → (cells, summed volume, smallest cell volume).
fn volumes(l: &Loaded) -> BTreeMap<(String, CellKind), (usize, f64, f64)> {
    let mut out: BTreeMap<(String, CellKind), (usize, f64, f64)> = BTreeMap::new();
    for v in &l.mesh.volumes {
        let e = out
            .entry((v.name.clone(), v.kind))
            .or_insert((0, 0.0, f64::MAX));
        for c in v.cells() {
            let vol = cell_volume(v.kind, &l.mesh.nodes, c);
            e.0 += 1;
            e.1 += vol;
            e.2 = e.2.min(vol);
        }
    }
    out
}

/// Every cell as (group, kind, corner coordinates), in order.
fn cell_points(l: &Loaded) -> Vec<(String, CellKind, Vec<[f64; 3]>)> {
    l.mesh
        .volumes
        .iter()
        .flat_map(|v| {
            v.cells().map(|c| {
                let corners = c.iter().map(|&n| l.mesh.nodes[n as usize]).collect();
                (v.name.clone(), v.kind, corners)
            })
        })
        .collect()
}

/// gmsh's element count of a physical group for one element name.
fn gmsh_count(facts: &Value, group: &str, element: &str) -> usize {
    facts["groups"][group]["elements"][element]
        .as_u64()
        .unwrap_or(0) as usize
}

fn binary() -> WriteOptions {
    WriteOptions {
        encoding: Some(Encoding::Binary),
        ..WriteOptions::default()
    }
}

/// The two boxes: per volume group, gmsh's tetrahedra, filling exactly 1.
fn assert_boxes(l: &Loaded, facts: &Value, what: &str) {
    let v = volumes(l);
    assert_eq!(v.len(), 2, "{what}: {v:?}");
    for name in ["left", "right"] {
        let (n, sum, min) = v[&(name.to_string(), CellKind::Tetrahedron)];
        assert_eq!(n, gmsh_count(facts, name, "tetrahedron"), "{what}: {name}");
        assert!((sum - 1.0).abs() < 1e-9, "{what}: {name} fills {sum}");
        assert!(
            min > 0.0,
            "{what}: {name} has a tetrahedron of volume {min}"
        );
    }
}

#[test]
fn gmsh_volume_meshes_keep_cells_tags_and_volumes() {
    let dir = tempfile::tempdir().expect("temp dir");
    let facts = run_json("python3", "make_volume_meshes.py", &[dir.path()]);
    let at = |name: &str| dir.path().join(name);

    // Read from every MSH version and encoding gmsh writes.
    for name in [
        "tets41.msh",
        "tets41_bin.msh",
        "tets22.msh",
        "tets22_bin.msh",
    ] {
        let l = load(&at(name));
        let f = &facts[name];
        assert_boxes(&l, f, name);
        assert_eq!(l.mesh.nodes.len() as u64, f["nodes"].as_u64().unwrap_or(0));
        let tris: BTreeMap<&str, usize> = l
            .mesh
            .faces
            .iter()
            .map(|f| (f.name.as_str(), f.triangles.len()))
            .collect();
        assert_eq!(tris["outer"], gmsh_count(f, "outer", "triangle"), "{name}");
        assert_eq!(
            tris["interface"],
            gmsh_count(f, "interface", "triangle"),
            "{name}"
        );
    }

    // MSH → VTU → MSH, both encodings: the cells, names and volumes survive.
    let tets = load(&at("tets41.msh"));
    let f = &facts["tets41.msh"];
    let total = gmsh_count(f, "left", "tetrahedron") + gmsh_count(f, "right", "tetrahedron");
    for (vtu, msh, options) in [
        ("a.vtu", "a.msh", WriteOptions::default()),
        ("b.vtu", "b.msh", binary()),
    ] {
        write_mesh_file(&at(vtu), &tets.mesh, &options).expect("vtu");
        let report = run_json("python3", "check_mesh.py", &[&at(vtu)]);
        assert_eq!(report["meshio"]["cells"]["tetra"], total, "{vtu}");
        assert_eq!(
            report["meshio"]["cell_data"]["volume_id"],
            serde_json::json!([-1, 0, 1])
        );
        let back = load(&at(vtu));
        assert_boxes(&back, f, vtu);

        write_mesh_file(&at(msh), &back.mesh, &options).expect("msh");
        let report = run_json("python3", "check_mesh.py", &[&at(msh)]);
        assert_eq!(report["meshio"]["cells"]["tetra"], total, "{msh}");
        for name in ["left", "right"] {
            assert_eq!(
                report["meshio"]["cell_sets"][name],
                gmsh_count(f, name, "tetrahedron"),
                "{msh}: {name}"
            );
        }
        let groups = report["gmsh"]["groups"]
            .as_array()
            .cloned()
            .unwrap_or_default();
        let dim3: Vec<(String, u64)> = groups
            .iter()
            .filter(|g| g["dim"] == 3)
            .map(|g| {
                (
                    g["name"].as_str().unwrap_or("").to_string(),
                    g["elements"]["tetrahedron"].as_u64().unwrap_or(0),
                )
            })
            .collect();
        assert_eq!(
            dim3,
            [
                (
                    "left".to_string(),
                    gmsh_count(f, "left", "tetrahedron") as u64
                ),
                (
                    "right".to_string(),
                    gmsh_count(f, "right", "tetrahedron") as u64
                )
            ],
            "{msh}"
        );
        assert_eq!(report["gmsh"]["nodes"], tets.mesh.nodes.len(), "{msh}");
        assert_boxes(&load(&at(msh)), f, msh);
    }

    // Hexahedra, prisms and a pyramid: counts, volumes (1, 1, 1/3) and the
    // exact corner lists through VTU (whose wedges are ordered the other way).
    let layers = load(&at("layers.msh"));
    let f = &facts["layers.msh"];
    let expected = [
        ("hex", CellKind::Hexahedron, "hexahedron", 1.0),
        ("prism", CellKind::Wedge, "prism", 1.0),
        ("pyramid", CellKind::Pyramid, "pyramid", 1.0 / 3.0),
    ];
    let check_layers = |l: &Loaded, what: &str| {
        let v = volumes(l);
        assert_eq!(v.len(), 3, "{what}: {v:?}");
        for (name, kind, element, volume) in expected {
            let (n, sum, min) = v[&(name.to_string(), kind)];
            assert_eq!(n, gmsh_count(f, name, element), "{what}: {name}");
            assert!((sum - volume).abs() < 1e-9, "{what}: {name} fills {sum}");
            assert!(min > 0.0, "{what}: {name}: a cell of volume {min}");
        }
    };
    check_layers(&layers, "layers.msh");
    write_mesh_file(&at("layers.vtu"), &layers.mesh, &binary()).expect("vtu");
    let report = run_json("python3", "check_mesh.py", &[&at("layers.vtu")]);
    assert_eq!(
        report["meshio"]["cells"],
        serde_json::json!({
            "hexahedron": gmsh_count(f, "hex", "hexahedron"),
            "wedge": gmsh_count(f, "prism", "prism"),
            "pyramid": 1
        })
    );
    let back = load(&at("layers.vtu"));
    check_layers(&back, "layers.vtu");
    assert_eq!(back.mesh.volumes, layers.mesh.volumes);
    write_mesh_file(&at("layers_out.msh"), &back.mesh, &WriteOptions::default()).expect("msh");
    let again = load(&at("layers_out.msh"));
    check_layers(&again, "layers_out.msh");
    // MSH numbers nodes per entity: compare the cells by their corners' coordinates.
    assert_eq!(cell_points(&again), cell_points(&layers));
    let report = run_json("python3", "check_mesh.py", &[&at("layers_out.msh")]);
    assert_eq!(
        report["meshio"]["cells"],
        serde_json::json!({
            "hexahedron": gmsh_count(f, "hex", "hexahedron"),
            "wedge": gmsh_count(f, "prism", "prism"),
            "pyramid": 1
        })
    );

    // Surface formats: the cells are dropped with a warning naming the count and format.
    for out in ["tets.stl", "tets.obj", "tets.glb"] {
        let o = Command::new(env!("CARGO_BIN_EXE_geomc"))
            .args(["convert", "tets41.msh", out])
            .current_dir(dir.path())
            .output()
            .expect("run geomc");
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(0), "{err}");
        let format = out.rsplit('.').next().unwrap_or("");
        let said = format!(
            "warning[W116]: {format}: {format} holds surfaces only: {total} tetrahedra in 2 volume groups not written"
        );
        assert!(err.contains(&said), "{out}: {err}");
    }
    let o = Command::new(env!("CARGO_BIN_EXE_geomc"))
        .args(["convert", "tets41.msh", "tets.vtu"])
        .current_dir(dir.path())
        .output()
        .expect("run geomc");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains(&format!("{total} tetrahedra")) && !err.contains("not written"),
        "{err}"
    );
}

#[test]
fn convert_options_carry_volume_cells() {
    let dir = tempfile::tempdir().expect("temp dir");
    run_json("python3", "make_volume_meshes.py", &[dir.path()]);
    let at = |name: &str| dir.path().join(name);
    let run = |args: &[&str]| {
        let o = Command::new(env!("CARGO_BIN_EXE_geomc"))
            .args(args)
            .current_dir(dir.path())
            .output()
            .expect("run geomc");
        assert_eq!(
            o.status.code(),
            Some(0),
            "{}",
            String::from_utf8_lossy(&o.stderr)
        );
    };
    let before = volumes(&load(&at("layers.msh")));

    // --group keeps one volume group and only the nodes it uses.
    run(&["convert", "layers.msh", "hex.msh", "--group", "hex"]);
    let hex = load(&at("hex.msh"));
    let v = volumes(&hex);
    assert_eq!(
        v.keys().cloned().collect::<Vec<_>>(),
        [("hex".to_string(), CellKind::Hexahedron)]
    );
    assert_eq!(hex.mesh.nodes.len(), 4 * 4 * 5);

    // A mirror keeps every cell's volume positive; a scale of 2 multiplies volumes by 8.
    run(&["convert", "layers.msh", "mirrored.vtu", "--scale", "-2,2,2"]);
    let m = volumes(&load(&at("mirrored.vtu")));
    for (key, (n, sum, min)) in &before {
        let (n2, sum2, min2) = m[key];
        assert_eq!(n2, *n, "{key:?}");
        assert!((sum2 - 8.0 * sum).abs() < 1e-9, "{key:?}: {sum2}");
        assert!(
            min2 > 0.0 && (min2 - 8.0 * min).abs() < 1e-9,
            "{key:?}: {min2}"
        );
    }

    // --weld on a mesh without duplicates changes nothing.
    run(&["convert", "layers.msh", "welded.msh", "--weld", "1e-9"]);
    assert_eq!(volumes(&load(&at("welded.msh"))), before);
}

/// A unit cube as five tetrahedra (the middle one touches no side), two in
/// volume `left` and three in `right`, with no surface elements at all.
const TETS_ONLY_MSH: &str = "$MeshFormat
4.1 0 8
$EndMeshFormat
$PhysicalNames
2
3 1 \"left\"
3 2 \"right\"
$EndPhysicalNames
$Entities
0 0 0 2
1 0 0 0 1 1 1 1 1 0
2 0 0 0 1 1 1 1 2 0
$EndEntities
$Nodes
1 8 1 8
3 1 0 8
1
2
3
4
5
6
7
8
0 0 0
1 0 0
1 1 0
0 1 0
0 0 1
1 0 1
1 1 1
0 1 1
$EndNodes
$Elements
2 5 1 5
3 1 4 2
1 1 2 4 5
2 2 3 4 7
3 2 4 3
3 2 7 5 6
4 4 5 7 8
5 2 4 7 5
$EndElements
";

#[test]
fn volume_only_meshes_give_their_boundary_to_surface_formats() {
    let dir = tempfile::tempdir().expect("temp dir");
    let at = |name: &str| dir.path().join(name);
    std::fs::write(at("tets_only.msh"), TETS_ONLY_MSH).expect("write msh");
    // ASCII STL: binary STL has no solids to carry the groups.
    for out in ["cube.stl", "cube.obj", "cube.glb"] {
        let o = Command::new(env!("CARGO_BIN_EXE_geomc"))
            .args(["convert", "tets_only.msh", out])
            .args(out.ends_with(".stl").then_some("--ascii"))
            .current_dir(dir.path())
            .output()
            .expect("run geomc");
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(0), "{out}: {err}");
        assert!(
            err.contains("the mesh has volume cells only: writing their boundary surface (12 triangles in 2 groups)"),
            "{out}: {err}"
        );
        assert!(
            err.contains("5 tetrahedra in 2 volume groups not written"),
            "{out}: {err}"
        );
        let back = load(&at(out));
        let faces = &back.mesh.faces;
        let triangles: usize = faces.iter().map(|f| f.triangles.len()).sum();
        assert_eq!(triangles, 12, "{out}");
        // The six sides, each two triangles; closed and outward: the
        // divergence theorem gives the cube's volume.
        let p = |n: u32| back.mesh.nodes[n as usize];
        let enclosed: f64 = faces
            .iter()
            .flat_map(|f| &f.triangles)
            .map(|&[a, b, c]| {
                let (a, b, c) = (p(a), p(b), p(c));
                (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                    + a[2] * (b[0] * c[1] - b[1] * c[0]))
                    / 6.0
            })
            .sum();
        assert!((enclosed - 1.0).abs() < 1e-6, "{out}: encloses {enclosed}");
        if out != "cube.glb" {
            // STL solids and OBJ groups keep the volume groups' names.
            let names: Vec<&str> = faces.iter().map(|f| f.name.as_str()).collect();
            assert_eq!(names, ["left", "right"], "{out}");
            assert_eq!(faces[0].triangles.len(), 6, "{out}");
        }
        if out == "cube.stl" {
            assert!(
                back.report.whole.watertight(),
                "{out}: {:?}",
                back.report.whole
            );
        }
    }
}
