//! Facts about 2D meshes shared by the 2D tests: chain lengths, how many
//! triangles use each edge, the smallest angle, and the Python checkers.
#![allow(dead_code)]

use geomc::driver::{Options, check_source};
use geomc::mesh::Mesh;
use geomc::meshing::{MeshOptions, mesh_model};
use geomc::span::SourceFile;
use std::collections::{BTreeSet, HashMap};
use std::path::{Path, PathBuf};
use std::process::Command;

/// The length of a node chain.
pub fn length(mesh: &Mesh, nodes: &[u32]) -> f64 {
    nodes
        .windows(2)
        .map(|w| {
            let [p, q] = [w[0], w[1]].map(|n| mesh.nodes[n as usize]);
            (q[0] - p[0]).hypot(q[1] - p[1])
        })
        .sum()
}

/// An undirected edge's key.
pub fn key(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

/// How many triangles use each edge.
pub fn edge_uses(mesh: &Mesh) -> HashMap<(u32, u32), usize> {
    let mut uses = HashMap::new();
    for t in mesh.faces.iter().flat_map(|f| &f.triangles) {
        for k in 0..3 {
            *uses.entry(key(t[k], t[(k + 1) % 3])).or_default() += 1;
        }
    }
    uses
}

/// The smallest angle of any triangle, in degrees.
pub fn min_angle_degrees(mesh: &Mesh) -> f64 {
    let mut least = f64::INFINITY;
    for t in mesh.faces.iter().flat_map(|f| &f.triangles) {
        let p = t.map(|n| mesh.nodes[n as usize]);
        for k in 0..3 {
            let (a, b, c) = (p[k], p[(k + 1) % 3], p[(k + 2) % 3]);
            let (u, v) = ([b[0] - a[0], b[1] - a[1]], [c[0] - a[0], c[1] - a[1]]);
            let cos = (u[0] * v[0] + u[1] * v[1]) / (u[0].hypot(u[1]) * v[0].hypot(v[1]));
            least = least.min(cos.clamp(-1.0, 1.0).acos().to_degrees());
        }
    }
    least
}

/// Meshing at a 30° minimum angle, with an optional area limit.
pub fn at_30_degrees(max_area: Option<f64>) -> MeshOptions {
    MeshOptions {
        min_angle_degrees: 30.0,
        max_area,
        ..MeshOptions::default()
    }
}

/// Runs `tests/tools/SCRIPT` on `args` then `extra`; its last output line is
/// JSON.
pub fn python(script: &str, args: &[&Path], extra: &[&str]) -> serde_json::Value {
    let path = format!("{}/tests/tools/{script}", env!("CARGO_MANIFEST_DIR"));
    let out = Command::new("python3")
        .arg(path)
        .args(args)
        .args(extra)
        .output()
        .expect("run python3");
    assert!(
        out.status.success(),
        "{script} failed (./scripts/test.sh installs gmsh, meshio, scikit-fem): {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    let line = stdout.lines().last().unwrap_or("");
    serde_json::from_str(line).unwrap_or_else(|e| panic!("bad output {stdout:?}: {e}"))
}

/// The group `name` in `check_mesh.py`'s report of what gmsh read.
pub fn gmsh_group<'a>(report: &'a serde_json::Value, name: &str) -> &'a serde_json::Value {
    let groups = report["gmsh"]["groups"].as_array().expect("groups");
    groups
        .iter()
        .find(|g| g["name"] == name)
        .unwrap_or_else(|| panic!("no group {name} in {groups:?}"))
}

/// The triangles of one subdomain.
pub fn triangles_of(m: &Mesh, name: &str) -> Vec<[u32; 3]> {
    let sub = m
        .subdomains
        .iter()
        .find(|s| s.name == name)
        .unwrap_or_else(|| panic!("no subdomain {name}"));
    sub.faces
        .iter()
        .flat_map(|&(f, _)| m.faces[f as usize].triangles.iter().copied())
        .collect()
}

pub fn area(m: &Mesh, tris: &[[u32; 3]]) -> f64 {
    tris.iter()
        .map(|t| {
            let [p, q, r] = t.map(|n| m.nodes[n as usize]);
            0.5 * ((q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]))
        })
        .inspect(|&a| assert!(a > 0.0, "a triangle runs clockwise"))
        .sum()
}

/// The segments (node pairs) of a fragment's edges.
pub fn fragment_segments(m: &Mesh, name: &str) -> Vec<[u32; 2]> {
    let fragment = m
        .fragments
        .iter()
        .find(|f| f.name == name)
        .unwrap_or_else(|| {
            let names: Vec<_> = m.fragments.iter().map(|f| &f.name).collect();
            panic!("no fragment {name} in {names:?}")
        });
    fragment
        .edges
        .iter()
        .flat_map(|&e| m.edges[e as usize].nodes.windows(2).map(|w| [w[0], w[1]]))
        .collect()
}

/// The smallest and largest coordinate `axis` (0 = x, 1 = y) over the nodes
/// of `segments`, each node first given to `check` (which asserts that it
/// lies where the test expects, e.g. on the interface's line).
pub fn coordinate_range(
    m: &Mesh,
    segments: &[[u32; 2]],
    axis: usize,
    check: impl Fn([f64; 3]),
) -> (f64, f64) {
    segments
        .iter()
        .flatten()
        .map(|&n| {
            let p = m.nodes[n as usize];
            check(p);
            p[axis]
        })
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| {
            (l.min(v), h.max(v))
        })
}

/// The undirected sides of a set of triangles.
pub fn sides(tris: &[[u32; 3]]) -> BTreeSet<[u32; 2]> {
    tris.iter()
        .flat_map(|t| (0..3).map(move |k| sorted([t[k], t[(k + 1) % 3]])))
        .collect()
}

pub fn sorted([a, b]: [u32; 2]) -> [u32; 2] {
    [a.min(b), a.max(b)]
}

/// Every interface segment is a triangle side on both sides (no hanging
/// node): returns the interface's node count.
pub fn assert_conforming(m: &Mesh, fragment: &str, a: &str, b: &str) -> usize {
    let segments = fragment_segments(m, fragment);
    assert!(!segments.is_empty());
    let (sa, sb) = (sides(&triangles_of(m, a)), sides(&triangles_of(m, b)));
    for s in &segments {
        let s = sorted(*s);
        assert!(sa.contains(&s), "interface segment {s:?} is no side of {a}");
        assert!(sb.contains(&s), "interface segment {s:?} is no side of {b}");
    }
    let nodes: BTreeSet<u32> = segments.iter().flatten().copied().collect();
    let of =
        |name: &str| -> BTreeSet<u32> { triangles_of(m, name).into_iter().flatten().collect() };
    let (na, nb) = (of(a), of(b));
    let shared = na.intersection(&nb).count();
    // The subdomains meet only on the interface: their common nodes are its nodes.
    assert_eq!(shared, nodes.len(), "common nodes of {a} and {b}");
    assert!(nodes.iter().all(|n| na.contains(n) && nb.contains(n)));
    nodes.len()
}

/// The mesh of a 2D domain that must check clean, at 30° and `max_area`.
pub fn mesh_clean(xml: &str, max_area: f64) -> Mesh {
    let checked = check_source(
        SourceFile::new("t.xml", xml.to_string()),
        &Options::default(),
    );
    assert!(
        checked.diagnostics.items.is_empty(),
        "{:#?}",
        checked.diagnostics.items
    );
    let model = checked.lowered.expect("a model").model;
    mesh_model(&model, &at_30_degrees(Some(max_area))).expect("meshes")
}

/// `geomc compile` of `xml` (written to `dir/name.xml`) to `dir/name.msh`
/// at 30° and `max_area`, through the binary as a user runs it.
pub fn compile_msh(xml: &str, dir: &Path, name: &str, max_area: &str) -> PathBuf {
    let input = dir.join(format!("{name}.xml"));
    std::fs::write(&input, xml).expect("write input");
    let msh = dir.join(format!("{name}.msh"));
    let status = Command::new(env!("CARGO_BIN_EXE_geomc"))
        .args(["compile", "-q"])
        .arg(&input)
        .args(["--min-angle", "30", "--max-area", max_area, "-o"])
        .arg(&msh)
        .status()
        .expect("run geomc");
    assert!(status.success(), "geomc compile {name}");
    msh
}

/// gmsh and meshio (report `r` of `check_mesh.py`) read every fragment
/// group of `groups` with the lines `expected` has there (at least one), and
/// every subdomain of `subdomains` with its triangles.
pub fn assert_groups_read(
    r: &serde_json::Value,
    expected: &Mesh,
    groups: &[&str],
    subdomains: &[&str],
) {
    for &group in groups {
        let lines = fragment_segments(expected, group).len() as u64;
        assert!(lines > 0, "{group}");
        assert_eq!(gmsh_group(r, group)["elements"]["line"], lines, "{group}");
        assert_eq!(r["meshio"]["cell_sets"][group], lines, "{group}");
    }
    for &sub in subdomains {
        assert_eq!(
            gmsh_group(r, sub)["elements"]["triangle"],
            triangles_of(expected, sub).len() as u64
        );
    }
}

/// The names of a mesh's fragments.
pub fn fragment_names(m: &Mesh) -> BTreeSet<&str> {
    m.fragments.iter().map(|f| f.name.as_str()).collect()
}

/// The area of the polygon of `segments` seen from `c` (a boundary
/// star-shaped about it, such as a circle's chords about its centre;
/// segments through `c` add nothing).
pub fn fan_area(m: &Mesh, segments: &[[u32; 2]], c: [f64; 2]) -> f64 {
    segments
        .iter()
        .map(|s| {
            let (p, q) = (m.nodes[s[0] as usize], m.nodes[s[1] as usize]);
            0.5 * ((p[0] - c[0]) * (q[1] - c[1]) - (p[1] - c[1]) * (q[0] - c[0])).abs()
        })
        .sum()
}

/// The diagnostics of checking a file, without meshing it.
pub fn diagnostics(xml: &str) -> Vec<geomc::diag::Diagnostic> {
    check_source(
        SourceFile::new("t.xml", xml.to_string()),
        &Options::default(),
    )
    .diagnostics
    .items
}

/// Every triangle's angles are at least the 30° the 2D tests mesh at.
pub fn assert_min_angle_30(m: &Mesh) {
    let least = min_angle_degrees(m);
    assert!(least >= 30.0 - 1e-9, "min angle {least}");
}
