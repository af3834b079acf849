//! Hand-built meshes for the writer tests, and the external checkers' plumbing.
//! Boxes are welded by coordinates, so two boxes that touch share vertices,
//! edges and the face between them, as the mesh IR requires.

#![allow(dead_code)]

use geomc::mesh::{
    Mesh, MeshEdge, MeshFace, MeshFragment, MeshPolyline, MeshSubdomain, MeshVertex,
};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

/// Corner `i` of a box: bit 0 = x, bit 1 = y, bit 2 = z.
fn corner(min: [f64; 3], max: [f64; 3], i: usize) -> [f64; 3] {
    [0, 1, 2].map(|k| if i >> k & 1 == 1 { max[k] } else { min[k] })
}

/// The six faces of a box as corner loops, counter-clockwise about the outward normal.
const BOX_FACES: [(&str, [usize; 4]); 6] = [
    ("xmin", [0, 4, 6, 2]),
    ("xmax", [1, 3, 7, 5]),
    ("ymin", [0, 1, 5, 4]),
    ("ymax", [2, 6, 7, 3]),
    ("zmin", [0, 2, 3, 1]),
    ("zmax", [4, 5, 7, 6]),
];

#[derive(Default)]
pub struct Builder {
    pub mesh: Mesh,
    node_at: BTreeMap<[u64; 3], u32>,
    edge_of: BTreeMap<(u32, u32), u32>,
    face_of: BTreeMap<Vec<u32>, u32>,
}

impl Builder {
    pub fn new(dimension: u8) -> Builder {
        let mut b = Builder::default();
        b.mesh.dimension = dimension;
        b
    }

    /// The vertex node at `p`, made on first use.
    pub fn vertex(&mut self, p: [f64; 3]) -> u32 {
        let key = p.map(f64::to_bits);
        if let Some(&n) = self.node_at.get(&key) {
            return n;
        }
        let n = self.mesh.nodes.len() as u32;
        self.mesh.nodes.push(p);
        self.mesh.vertices.push(MeshVertex {
            name: format!("v{n}"),
            node: n,
        });
        self.node_at.insert(key, n);
        n
    }

    /// The straight edge between two vertex nodes (one segment), made on first
    /// use; returns it with the direction `a → b` has along it.
    pub fn edge(&mut self, a: u32, b: u32) -> (u32, bool) {
        if let Some(&e) = self.edge_of.get(&(a.min(b), a.max(b))) {
            return (e, self.mesh.edges[e as usize].nodes[0] == a);
        }
        let e = self.mesh.edges.len() as u32;
        self.mesh.edges.push(MeshEdge {
            name: format!("e{e}"),
            nodes: vec![a, b],
        });
        self.edge_of.insert((a.min(b), a.max(b)), e);
        (e, true)
    }

    /// An axis-aligned box subdomain; faces shared with an earlier box are
    /// reused (with `outward = false`).
    pub fn add_box(&mut self, name: &str, min: [f64; 3], max: [f64; 3]) -> u32 {
        let corners: Vec<u32> = (0..8).map(|i| self.vertex(corner(min, max, i))).collect();
        let mut faces = Vec::new();
        for (face_name, loop_) in BOX_FACES {
            let q = loop_.map(|i| corners[i]);
            let mut key = q.to_vec();
            key.sort();
            if let Some(&f) = self.face_of.get(&key) {
                // Shared: it was made counter-clockwise about the other box's outward normal.
                faces.push((f, false));
                continue;
            }
            let boundary = (0..4).map(|k| self.edge(q[k], q[(k + 1) % 4])).collect();
            let f = self.mesh.faces.len() as u32;
            self.mesh.faces.push(MeshFace {
                name: format!("{name}.{face_name}"),
                triangles: vec![[q[0], q[1], q[2]], [q[0], q[2], q[3]]],
                boundary,
            });
            self.face_of.insert(key, f);
            faces.push((f, true));
        }
        self.mesh.subdomains.push(MeshSubdomain {
            name: name.to_string(),
            material: Some("steel".to_string()),
            faces,
        });
        (self.mesh.subdomains.len() - 1) as u32
    }

    /// Fragments from face use: one per subdomain pair, named `A|B` /
    /// `A|exterior`, or by `rename(face name)` when it gives a name.
    pub fn derive_fragments(&mut self, rename: impl Fn(&str) -> Option<String>) {
        let mut users: BTreeMap<u32, Vec<u32>> = BTreeMap::new();
        for (s, sub) in self.mesh.subdomains.iter().enumerate() {
            for &(f, _) in &sub.faces {
                users.entry(f).or_default().push(s as u32);
            }
        }
        let mut groups: BTreeMap<(u32, Option<u32>, String), Vec<u32>> = BTreeMap::new();
        for (f, subs) in users {
            let (k, other) = (subs[0], subs.get(1).copied());
            let name = rename(&self.mesh.faces[f as usize].name).unwrap_or_else(|| {
                let a = &self.mesh.subdomains[k as usize].name;
                let b = other.map_or("exterior".to_string(), |o| {
                    self.mesh.subdomains[o as usize].name.clone()
                });
                format!("{a}|{b}")
            });
            groups.entry((k, other, name)).or_default().push(f);
        }
        for ((subdomain, other, name), faces) in groups {
            self.mesh.fragments.push(MeshFragment {
                name,
                subdomain,
                other,
                faces,
                edges: Vec::new(),
            });
        }
    }
}

/// The unit cube as one subdomain: 8 vertices, 12 edges, 6 faces of 2
/// triangles; fragments `inlet` (xmin), `outlet` (xmax), `walls` (the rest).
pub fn unit_cube() -> Mesh {
    let mut b = Builder::new(3);
    b.add_box("cube", [0.0; 3], [1.0; 3]);
    b.derive_fragments(|face| match face {
        "cube.xmin" => Some("inlet".into()),
        "cube.xmax" => Some("outlet".into()),
        _ => Some("walls".into()),
    });
    b.mesh
}

/// Two unit cubes `left` and `right` sharing the face x = 1: fragments
/// `left|exterior` (5 faces), `left|right` (1), `right|exterior` (5).
pub fn two_cubes() -> Mesh {
    let mut b = Builder::new(3);
    b.add_box("left", [0.0; 3], [1.0; 3]);
    b.add_box("right", [1.0, 0.0, 0.0], [2.0, 1.0, 1.0]);
    b.derive_fragments(|_| None);
    b.mesh
}

/// The square [0,2]×[0,1] split at x = 1 into regions `left` and `right`; the
/// middle edge has a midpoint node. Fragments: `left|exterior` (3 edges, 3
/// segments), `left|right` (1 edge, 2 segments), `right|exterior` (3, 3).
pub fn split_square() -> Mesh {
    let p = |x: f64, y: f64| [x, y, 0.0];
    let mut mesh = Mesh {
        dimension: 2,
        nodes: vec![
            p(0.0, 0.0),
            p(1.0, 0.0),
            p(2.0, 0.0),
            p(0.0, 1.0),
            p(1.0, 1.0),
            p(2.0, 1.0),
            p(1.0, 0.5),
        ],
        ..Mesh::default()
    };
    mesh.vertices = (0..6)
        .map(|n| MeshVertex {
            name: format!("v{n}"),
            node: n,
        })
        .collect();
    let edge = |name: &str, nodes: &[u32]| MeshEdge {
        name: name.to_string(),
        nodes: nodes.to_vec(),
    };
    mesh.edges = vec![
        edge("bottom_left", &[0, 1]),
        edge("bottom_right", &[1, 2]),
        edge("right", &[2, 5]),
        edge("top_right", &[5, 4]),
        edge("top_left", &[4, 3]),
        edge("left", &[3, 0]),
        edge("middle", &[1, 6, 4]),
    ];
    mesh.faces = vec![
        MeshFace {
            name: "left_square".into(),
            triangles: vec![[0, 1, 6], [0, 6, 4], [0, 4, 3]],
            boundary: vec![(0, true), (6, true), (4, true), (5, true)],
        },
        MeshFace {
            name: "right_square".into(),
            triangles: vec![[2, 5, 4], [2, 4, 6], [2, 6, 1]],
            boundary: vec![(1, true), (2, true), (3, true), (6, false)],
        },
    ];
    mesh.subdomains = vec![
        MeshSubdomain {
            name: "left".into(),
            material: None,
            faces: vec![(0, true)],
        },
        MeshSubdomain {
            name: "right".into(),
            material: Some("copper".into()),
            faces: vec![(1, true)],
        },
    ];
    let fragment = |name: &str, subdomain, other, edges: &[u32]| MeshFragment {
        name: name.to_string(),
        subdomain,
        other,
        faces: Vec::new(),
        edges: edges.to_vec(),
    };
    mesh.fragments = vec![
        fragment("left|exterior", 0, None, &[0, 4, 5]),
        fragment("left|right", 0, Some(1), &[6]),
        fragment("right|exterior", 1, None, &[1, 2, 3]),
    ];
    mesh
}

/// The unit cube plus a poly_line `probe` of 3 new nodes (2 segments) and a
/// point set `sensors` of 2 new nodes, all inside the cube.
pub fn cube_with_probe() -> Mesh {
    let mut mesh = unit_cube();
    let first = mesh.nodes.len() as u32;
    mesh.nodes.extend([
        [0.2, 0.5, 0.5],
        [0.5, 0.5, 0.5],
        [0.8, 0.5, 0.5],
        [0.25, 0.25, 0.25],
        [0.75, 0.75, 0.75],
    ]);
    mesh.polylines.push(MeshPolyline {
        name: "probe".into(),
        nodes: vec![first, first + 1, first + 2],
    });
    mesh.point_sets.push(MeshPolyline {
        name: "sensors".into(),
        nodes: vec![first + 3, first + 4],
    });
    mesh
}

pub fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

pub fn tools() -> PathBuf {
    root().join("tests").join("tools")
}

const INSTALL_HINT: &str = "run ./scripts/test.sh, which installs the external checkers \
     (pip: gmsh meshio; npm: gltf-validator in tests/tools/node_modules)";

/// Runs a checker script and parses the JSON it prints. Fails the test with
/// the install hint when the interpreter or a module is missing.
pub fn run_json(program: &str, script: &str, args: &[&Path]) -> serde_json::Value {
    let output = Command::new(program)
        .arg(tools().join(script))
        .args(args)
        .output()
        .unwrap_or_else(|e| panic!("cannot run `{program}` for {script}: {e}; {INSTALL_HINT}"));
    let stdout = String::from_utf8_lossy(&output.stdout);
    let stderr = String::from_utf8_lossy(&output.stderr);
    if output.status.code() == Some(3) {
        panic!("{script}: a checker is not installed: {stderr}\n{INSTALL_HINT}");
    }
    assert!(
        output.status.success(),
        "{script} failed ({}):\nstdout: {stdout}\nstderr: {stderr}",
        output.status
    );
    serde_json::from_str(&stdout)
        .unwrap_or_else(|e| panic!("{script} printed no JSON ({e}):\n{stdout}\nstderr: {stderr}"))
}

/// Writes `mesh` to `dir/name` through the registry and returns the path.
pub fn write(
    dir: &Path,
    name: &str,
    mesh: &Mesh,
    options: &geomc::formats::WriteOptions,
) -> (PathBuf, Vec<String>) {
    let path = dir.join(name);
    let warnings = geomc::formats::write_mesh_file(&path, mesh, options)
        .unwrap_or_else(|e| panic!("writing {name}: {e}"));
    (path, warnings.iter().map(ToString::to_string).collect())
}
