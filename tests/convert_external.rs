//! Files made by other tools read correctly: gmsh (MSH 4.1 and 2.2, ASCII
//! and binary), meshio (VTU, compressed binary and ASCII) and trimesh 5.2.0
//! (binary and ASCII STL, OBJ, GLB), written by `tests/tools/make_meshes.py`
//! together with what each tool says the file holds. Converted results are
//! then read back by gmsh and meshio (`tests/tools/check_mesh.py`).

mod writers_common;

use geomc::diag::Code;
use geomc::formats::read::{Loaded, load_mesh};
use geomc::formats::{Encoding, WriteOptions, write_mesh_file};
use geomc::mesh::CellKind;
use geomc::mesh::volume::cell_volume;
use serde_json::Value;
use std::collections::BTreeMap;
use std::path::Path;
use writers_common::run_json;

fn load(path: &Path) -> Loaded {
    load_mesh(path).unwrap_or_else(|d| panic!("{}: {d:?}", path.display()))
}

fn groups(l: &Loaded) -> BTreeMap<String, u64> {
    l.mesh
        .faces
        .iter()
        .map(|f| (f.name.clone(), f.triangles.len() as u64))
        .collect()
}

fn expected_groups(v: &Value) -> BTreeMap<String, u64> {
    v.as_object()
        .map(|o| {
            o.iter()
                .map(|(k, v)| (k.clone(), v.as_u64().unwrap_or(0)))
                .collect()
        })
        .unwrap_or_default()
}

fn volume(l: &Loaded) -> f64 {
    let n = &l.mesh.nodes;
    l.mesh
        .faces
        .iter()
        .flat_map(|f| &f.triangles)
        .map(|&[a, b, c]| {
            let (p, q, r) = (n[a as usize], n[b as usize], n[c as usize]);
            (p[0] * (q[1] * r[2] - q[2] * r[1]) - p[1] * (q[0] * r[2] - q[2] * r[0])
                + p[2] * (q[0] * r[1] - q[1] * r[0]))
                / 6.0
        })
        .sum()
}

/// The volume of every volume cell, summed.
fn cells_volume(l: &Loaded) -> f64 {
    l.mesh
        .volumes
        .iter()
        .flat_map(|v| v.cells().map(|c| cell_volume(v.kind, &l.mesh.nodes, c)))
        .sum()
}

#[test]
fn meshes_made_by_gmsh_meshio_and_trimesh_read_correctly() {
    let dir = tempfile::tempdir().expect("temp dir");
    let facts = run_json("python3", "make_meshes.py", &[dir.path()]);
    let at = |name: &str| dir.path().join(name);

    for name in [
        "gmsh41.msh",
        "gmsh41_bin.msh",
        "gmsh22.msh",
        "gmsh22_bin.msh",
    ] {
        let l = load(&at(name));
        let f = &facts[name];
        assert_eq!(groups(&l), expected_groups(&f["groups"]), "{name}");
        assert_eq!(l.binary, Some(name.contains("bin")), "{name}");
        // The box's boundary is closed and outward: volume 1 × 2 × 3.
        assert!(l.report.whole.watertight(), "{name}: {:?}", l.report.whole);
        assert!((volume(&l) - 6.0).abs() < 1e-9, "{name}: {}", volume(&l));
        // The tetrahedra are kept, in the physical volume `solid`, and fill the box.
        let tets = f["tetrahedra"].as_u64().unwrap_or(0);
        let kept: Vec<(&str, CellKind, usize)> = l
            .mesh
            .volumes
            .iter()
            .map(|v| (v.name.as_str(), v.kind, v.count()))
            .collect();
        assert_eq!(
            kept,
            [("solid", CellKind::Tetrahedron, tets as usize)],
            "{name}"
        );
        let v = cells_volume(&l);
        assert!((v - 6.0).abs() < 1e-9, "{name}: tetrahedra fill {v}");
        assert!(
            !l.warnings.iter().any(|d| d.code == Code::InputNotCarried),
            "{name}: {:?}",
            l.warnings
        );
    }

    for name in ["meshio.vtu", "meshio_ascii.vtu"] {
        let l = load(&at(name));
        let f = &facts[name];
        let expected: BTreeMap<String, u64> = expected_groups(&f["triangles_by_tag"])
            .into_iter()
            .map(|(tag, n)| (format!("gmsh:physical {tag}"), n))
            .collect();
        assert_eq!(groups(&l), expected, "{name}");
        assert_eq!(
            l.mesh.nodes.len() as u64,
            f["points"].as_u64().unwrap_or(0),
            "{name}"
        );
        assert!((volume(&l) - 6.0).abs() < 1e-9, "{name}");
        // meshio's tetrahedra, tagged with the physical volume's number 3.
        let tets = facts["gmsh41.msh"]["tetrahedra"].as_u64().unwrap_or(0) as usize;
        let kept: Vec<(&str, usize)> = l
            .mesh
            .volumes
            .iter()
            .map(|v| (v.name.as_str(), v.count()))
            .collect();
        assert_eq!(kept, [("gmsh:physical 3:3", tets)], "{name}");
        assert!((cells_volume(&l) - 6.0).abs() < 1e-9, "{name}");
    }

    for name in ["trimesh_bin.stl", "trimesh_ascii.stl", "trimesh.obj"] {
        let l = load(&at(name));
        let f = &facts[name];
        let tris: usize = l.mesh.faces.iter().map(|f| f.triangles.len()).sum();
        assert_eq!(tris as u64, f["triangles"].as_u64().unwrap_or(0), "{name}");
        // STL repeats vertices per triangle: merging identical ones gives trimesh's count.
        assert_eq!(
            l.mesh.nodes.len() as u64,
            f["vertices"].as_u64().unwrap_or(0),
            "{name}"
        );
        let v = f["volume"].as_f64().unwrap_or(0.0);
        assert!(
            (volume(&l) - v).abs() < 1e-5,
            "{name}: {} vs {v}",
            volume(&l)
        );
        assert!(l.report.whole.watertight(), "{name}");
    }

    let l = load(&at("trimesh.glb"));
    assert_eq!(
        groups(&l),
        expected_groups(&facts["trimesh.glb"]["groups"]),
        "glb"
    );
    // The brick's node translation (3, 0, 0) is applied.
    let hi_x = l.mesh.nodes.iter().map(|p| p[0]).fold(f64::MIN, f64::max);
    let expected_hi = facts["trimesh.glb"]["bounds"][1][0].as_f64().unwrap_or(0.0);
    assert!((hi_x - expected_hi).abs() < 1e-6, "{hi_x} vs {expected_hi}");

    // Converted, the groups reach gmsh and meshio intact.
    let out = dir.path().join("from_glb.msh");
    let binary = WriteOptions {
        encoding: Some(Encoding::Binary),
        ..WriteOptions::default()
    };
    write_mesh_file(&out, &l.mesh, &binary).expect("write msh");
    let report = run_json("python3", "check_mesh.py", &[&out]);
    assert_eq!(report["meshio"]["cell_sets"]["ball"], 320);
    assert_eq!(report["meshio"]["cell_sets"]["brick"], 12);
    let names: Vec<&str> = report["gmsh"]["groups"]
        .as_array()
        .map(|a| a.iter().filter_map(|g| g["name"].as_str()).collect())
        .unwrap_or_default();
    assert_eq!(names, ["ball", "brick"]);

    // gmsh's mesh as GLB passes the Khronos glTF validator.
    let gm = load(&at("gmsh41.msh"));
    let glb = dir.path().join("from_gmsh.glb");
    write_mesh_file(&glb, &gm.mesh, &WriteOptions::default()).expect("write glb");
    let report = run_json("node", "validate_gltf.js", &[&glb]);
    assert_eq!(
        (report["numErrors"].as_u64(), report["numWarnings"].as_u64()),
        (Some(0), Some(0)),
        "{:#}",
        report["messages"]
    );
    let back = load(&glb);
    assert_eq!(
        groups(&back),
        expected_groups(&facts["gmsh41.msh"]["groups"])
    );

    let gm = load(&at("gmsh22_bin.msh"));
    let out = dir.path().join("from_gmsh.vtu");
    write_mesh_file(&out, &gm.mesh, &binary).expect("write vtu");
    let report = run_json("python3", "check_mesh.py", &[&out]);
    assert_eq!(report["meshio"]["cells"]["triangle"], 516);
    assert_eq!(report["meshio"]["points"], 302);
}
