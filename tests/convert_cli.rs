//! `geomc convert` and `geomc inspect MESHFILE` on the command line: exit
//! codes, warnings with counts, no output file on bad input, the options.

mod writers_common;

use geomc::formats::read::load_mesh;
use geomc::formats::{Encoding, WriteOptions, write_mesh_file};
use std::path::Path;
use std::process::{Command, Output};
use writers_common::{cube_with_probe, unit_cube};

fn geomc(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_geomc"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("run geomc")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn setup() -> tempfile::TempDir {
    let dir = tempfile::tempdir().expect("temp dir");
    write_mesh_file(
        &dir.path().join("cube.msh"),
        &cube_with_probe(),
        &WriteOptions::default(),
    )
    .expect("msh");
    dir
}

#[test]
fn convert_keeps_groups_and_names_what_the_target_cannot_carry() {
    let dir = setup();
    let o = geomc(&["convert", "cube.msh", "cube.stl"], dir.path());
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(
        err.contains("warning[W116]: stl: binary STL has no groups: 3 faces merged"),
        "{err}"
    );
    assert!(
        err.contains("STL holds only triangles: 1 poly_line, 1 point set not written"),
        "{err}"
    );
    let o = geomc(
        &["convert", "--ascii", "cube.msh", "cube_a.stl"],
        dir.path(),
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let l = load_mesh(&dir.path().join("cube_a.stl")).expect("read");
    let names: Vec<&str> = l.mesh.faces.iter().map(|f| f.name.as_str()).collect();
    assert_eq!(names, ["inlet", "outlet", "walls"]);
    // --to overrides the ending.
    let o = geomc(
        &["convert", "--to", "glb", "cube.msh", "cube.bin3d"],
        dir.path(),
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let bytes = std::fs::read(dir.path().join("cube.bin3d")).expect("written");
    assert!(bytes.starts_with(b"glTF"));
}

#[test]
fn bad_input_exits_1_with_a_located_diagnostic_and_writes_nothing() {
    let dir = tempfile::tempdir().expect("temp dir");
    std::fs::write(
        dir.path().join("bad.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n",
    )
    .expect("write");
    let o = geomc(&["convert", "bad.obj", "out.msh"], dir.path());
    assert_eq!(o.status.code(), Some(1));
    let err = stderr(&o);
    assert!(
        err.starts_with("bad.obj:4:7: error[E524]: vertex index 9 is out of range"),
        "{err}"
    );
    assert!(!dir.path().join("out.msh").exists());
    // Binary STL with a wrong count: the byte offset.
    let mut stl = vec![b' '; 80];
    stl.extend_from_slice(&7u32.to_le_bytes());
    stl.extend_from_slice(&[0u8; 50]);
    std::fs::write(dir.path().join("bad.stl"), &stl).expect("write");
    let o = geomc(&["convert", "bad.stl", "out.glb"], dir.path());
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).starts_with(
            "bad.stl: error[E527]: at byte 80: the binary STL header says 7 triangles"
        ),
        "{}",
        stderr(&o)
    );
    assert!(!dir.path().join("out.glb").exists());
    // A missing input is an I/O problem: exit 2.
    let o = geomc(&["convert", "none.stl", "out.glb"], dir.path());
    assert_eq!(o.status.code(), Some(2));
}

#[test]
fn group_filter_and_transforms() {
    let dir = setup();
    let o = geomc(
        &[
            "convert",
            "cube.msh",
            "in.obj",
            "--group",
            "inlet",
            "--group",
            "probe",
            "--scale",
            "2",
            "--translate",
            "1,0,0",
        ],
        dir.path(),
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let l = load_mesh(&dir.path().join("in.obj")).expect("read");
    let names: Vec<&str> = l.mesh.faces.iter().map(|f| f.name.as_str()).collect();
    assert_eq!(names, ["inlet"]);
    assert_eq!(l.mesh.polylines.len(), 1);
    assert!(l.mesh.point_sets.is_empty());
    // The inlet x = 0 face, scaled by 2 and moved by 1: x = 1; y, z in [0, 2].
    let xs: Vec<f64> = l.mesh.faces[0]
        .triangles
        .iter()
        .flatten()
        .map(|&n| l.mesh.nodes[n as usize][0])
        .collect();
    assert!(xs.iter().all(|&x| x == 1.0), "{xs:?}");
    let hi = l.mesh.nodes.iter().map(|p| p[2]).fold(f64::MIN, f64::max);
    assert_eq!(hi, 2.0);
    // An unknown group: E532 with a suggestion.
    let o = geomc(
        &["convert", "cube.msh", "x.obj", "--group", "inlets"],
        dir.path(),
    );
    assert_eq!(o.status.code(), Some(1));
    let err = stderr(&o);
    assert!(
        err.contains("error[E532]: --group inlets: the mesh has no group `inlets`"),
        "{err}"
    );
    assert!(err.contains("did you mean `inlet`?"), "{err}");
    assert!(!dir.path().join("x.obj").exists());
    // A rotation of 90° about z maps x to y.
    let o = geomc(
        &["convert", "cube.msh", "r.msh", "--rotate", "0,0,90"],
        dir.path(),
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let l = load_mesh(&dir.path().join("r.msh")).expect("read");
    let lo_x = l.mesh.nodes.iter().map(|p| p[0]).fold(f64::MAX, f64::min);
    assert!((lo_x + 1.0).abs() < 1e-12, "{lo_x}");
}

#[test]
fn weld_and_normals_repair_a_triangle_soup() {
    let dir = tempfile::tempdir().expect("temp dir");
    // A cube as a soup: every triangle's corners apart by 1e-7, one face flipped.
    let mut mesh = unit_cube();
    let mut soup = mesh.clone();
    soup.nodes.clear();
    for f in &mut soup.faces {
        for (k, t) in f.triangles.iter_mut().enumerate() {
            for v in t.iter_mut() {
                let mut p = mesh.nodes[*v as usize];
                p[0] += 1e-7 * (k as f64);
                soup.nodes.push(p);
                *v = (soup.nodes.len() - 1) as u32;
            }
        }
    }
    for t in &mut soup.faces[0].triangles {
        t.swap(1, 2);
    }
    soup.vertices.clear();
    soup.edges.clear();
    for f in &mut soup.faces {
        f.boundary.clear();
    }
    mesh = soup;
    let options = WriteOptions {
        encoding: Some(Encoding::Ascii),
        ..WriteOptions::default()
    };
    write_mesh_file(&dir.path().join("soup.msh"), &mesh, &options).expect("msh");
    let o = geomc(&["inspect", "soup.msh"], dir.path());
    let text = String::from_utf8_lossy(&o.stdout).into_owned();
    assert!(text.contains("counts: 36 nodes, 12 triangles"), "{text}");
    assert!(text.contains("36 open"), "{text}");
    let o = geomc(
        &[
            "convert",
            "soup.msh",
            "fixed.msh",
            "--weld",
            "1e-6",
            "--normals",
        ],
        dir.path(),
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(
        err.contains("--weld 0.000001: 28 nodes merged into others, 0 collapsed triangles removed"),
        "{err}"
    );
    assert!(
        err.contains("--normals: 2 of 12 triangles reversed (1 connected surfaces, 1 closed)"),
        "{err}"
    );
    let l = load_mesh(&dir.path().join("fixed.msh")).expect("read");
    assert_eq!(l.mesh.nodes.len(), 8);
    assert!(l.report.whole.watertight(), "{:?}", l.report.whole);
}

#[test]
fn inspect_lists_groups_watertightness_and_json() {
    let dir = setup();
    let o = geomc(&["inspect", "cube.msh"], dir.path());
    assert_eq!(o.status.code(), Some(0));
    let text = String::from_utf8_lossy(&o.stdout).into_owned();
    let expected = "format: msh (ascii)
counts: 13 nodes, 12 triangles, 2 line segments, 2 points
bounding box: [0, 0, 0] .. [1, 1, 1]
surface: 18 edges, 0 open, 0 non-manifold, 0 inconsistently oriented, 0 degenerate triangles: watertight
quality: smallest angle 45.00°, largest angle 90.00°, 0 triangles with an angle under 10°
groups (5):
  inlet: 2 triangles, open (4 open, 0 non-manifold edges)
  outlet: 2 triangles, open (4 open, 0 non-manifold edges)
  walls: 8 triangles, open (8 open, 0 non-manifold edges)
  probe: 2 line segments
  sensors: 2 points
";
    assert_eq!(text, expected);
    let o = geomc(&["inspect", "--format", "json", "cube.msh"], dir.path());
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("json");
    assert_eq!(v["triangles"], 12);
    assert_eq!(v["watertight"], true);
    assert_eq!(v["groups"][2]["name"], "walls");
    assert_eq!(v["groups"][2]["open_edges"], 8);
}
