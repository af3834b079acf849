//! Opening cracks: a poly_line with `crack="true"` that the 2D mesh follows
//! is cut open. Every node of its chain but the two tips is duplicated; the
//! triangles on the chain's right get the copies, so a solver sees a slit.
//! The two sides become mesh edges `NAME.left` and `NAME.right` (left: the
//! side to the left walking from the first point to the last), each its own
//! boundary fragment of the subdomain around the crack.
//!
//! Which side a triangle at a chain node lies on is read from angles: its
//! centroid's direction from the node, measured counter-clockwise from the
//! next chain node, is on the left when it comes before the previous chain
//! node's direction. Triangles of one fan never straddle a chain edge (the
//! mesh follows the line), so this needs no adjacency.
//!
//! A tip on the outer boundary (an edge crack) is duplicated too, so the
//! crack mouth opens: at the tip the fan of triangles runs from one
//! boundary neighbour to the other, and the side is read from the angle
//! against the boundary neighbour met first turning counter-clockwise from
//! the chain. The boundary edge through the mouth is cut there: it keeps
//! its part up to the mouth (node order and curve parameters unchanged)
//! and a new mesh edge `EDGE.beyond.NAME` takes the rest, listed in every
//! face and fragment the edge was. A tip on an interface between two
//! faces stays shared (opening it would break the interface).

use crate::ir::Model;
use crate::mesh::{Mesh, MeshEdge, MeshFragment};
use std::f64::consts::TAU;

/// Where each mesh edge's nodes come from: (model edge, index of its first
/// node in that edge's discretisation), or `None` for edges that follow no
/// model curve (crack sides, edges added after meshing).
pub(crate) type EdgeOrigins = Vec<Option<(usize, usize)>>;

/// Opens every crack poly_line whose chain lies in the mesh's triangles;
/// returns the origin of every mesh edge, so that an `EDGE.beyond.NAME` part
/// still knows its curve parameters (second-order mid nodes on the curve).
pub(crate) fn open(model: &Model, mesh: &mut Mesh) -> EdgeOrigins {
    let mut origins: EdgeOrigins = (0..mesh.edges.len())
        .map(|i| (i < model.edges.len()).then_some((i, 0)))
        .collect();
    for (index, line) in model.polylines.iter().enumerate() {
        if !line.crack {
            continue;
        }
        let Some(chain) = mesh.polylines.get(index).map(|p| p.nodes.clone()) else {
            continue;
        };
        if chain.len() < 2 {
            continue;
        }
        let Some(face) = face_with_edge(mesh, chain[0], chain[1]) else {
            // A free line (outside every region): nothing to open.
            continue;
        };
        let mouths: Vec<Option<Mouth>> = [0, chain.len() - 1]
            .map(|k| mouth(mesh, face, &chain, k))
            .into();
        let mut right = open_chain(mesh, face, &chain);
        for (m, k) in mouths.into_iter().zip([0, chain.len() - 1]) {
            if let Some(m) = m {
                right[k] = open_mouth(mesh, face, &m, &line.name, &mut origins);
            }
        }
        let subdomain = mesh
            .subdomains
            .iter()
            .position(|s| s.faces.iter().any(|&(f, _)| f as usize == face))
            .unwrap_or(0) as u32;
        for (side, nodes) in [("left", chain.clone()), ("right", right)] {
            let edge = mesh.edges.len() as u32;
            let name = format!("{}.{side}", line.name);
            mesh.edges.push(MeshEdge {
                name: name.clone(),
                nodes,
            });
            mesh.fragments.push(MeshFragment {
                name,
                subdomain,
                other: None,
                faces: Vec::new(),
                edges: vec![edge],
            });
        }
    }
    origins.resize(mesh.edges.len(), None);
    origins
}

fn face_with_edge(mesh: &Mesh, a: u32, b: u32) -> Option<usize> {
    mesh.faces
        .iter()
        .position(|f| f.triangles.iter().any(|t| t.contains(&a) && t.contains(&b)))
}

/// Duplicates the chain's inner nodes for the triangles on its right;
/// returns the right side's chain (tips shared).
fn open_chain(mesh: &mut Mesh, face: usize, chain: &[u32]) -> Vec<u32> {
    let mut right = chain.to_vec();
    let last = chain.len() - 1;
    // Triangles at each inner chain node, found in one pass.
    let mut around: std::collections::HashMap<u32, Vec<usize>> =
        chain[1..last].iter().map(|&n| (n, Vec::new())).collect();
    for (i, t) in mesh.faces[face].triangles.iter().enumerate() {
        for n in t {
            if let Some(list) = around.get_mut(n) {
                list.push(i);
            }
        }
    }
    for k in 1..last {
        let (prev, node, next) = (chain[k - 1], chain[k], chain[k + 1]);
        let at = mesh.nodes[node as usize];
        let angle_of = |p: [f64; 3]| (p[1] - at[1]).atan2(p[0] - at[0]);
        let base = angle_of(mesh.nodes[next as usize]);
        let from_next = |p: [f64; 3]| (angle_of(p) - base).rem_euclid(TAU);
        let limit = from_next(mesh.nodes[prev as usize]);
        let copy = mesh.nodes.len() as u32;
        mesh.nodes.push(at);
        right[k] = copy;
        let nodes = &mesh.nodes;
        let triangles = &mut mesh.faces[face].triangles;
        for &i in around.get(&node).into_iter().flatten() {
            let t = &mut triangles[i];
            let Some(slot) = t.iter().position(|&n| n == node) else {
                continue;
            };
            let centroid: [f64; 3] =
                std::array::from_fn(|c| t.iter().map(|&n| nodes[n as usize][c]).sum::<f64>() / 3.0);
            if from_next(centroid) > limit {
                t[slot] = copy;
            }
        }
    }
    right
}

/// A crack tip on the outer boundary: its node, the triangles (in the
/// crack's face) that move to the copy, and its boundary neighbour on the
/// right side.
struct Mouth {
    node: u32,
    right_triangles: Vec<usize>,
    right_neighbour: u32,
}

/// The mouth at chain position `k` (0 or last), when that tip lies on the
/// outer boundary (its fan's two boundary edges are used by one triangle
/// in the whole mesh).
fn mouth(mesh: &Mesh, face: usize, chain: &[u32], k: usize) -> Option<Mouth> {
    let node = chain[k];
    let first = k == 0;
    let along = if first { chain[1] } else { chain[k - 1] };
    let mut uses: std::collections::HashMap<u32, usize> = std::collections::HashMap::new();
    let mut fan = Vec::new();
    for (f, mf) in mesh.faces.iter().enumerate() {
        for (i, t) in mf.triangles.iter().enumerate() {
            if !t.contains(&node) {
                continue;
            }
            if f == face {
                fan.push(i);
            }
            for &n in t.iter().filter(|&&n| n != node) {
                *uses.entry(n).or_default() += 1;
            }
        }
    }
    let neighbours: Vec<u32> = uses
        .iter()
        .filter(|&(_, &c)| c == 1)
        .map(|(&n, _)| n)
        .collect();
    if neighbours.len() != 2 || neighbours.contains(&along) {
        return None;
    }
    let at = mesh.nodes[node as usize];
    let angle_of = |p: [f64; 3]| (p[1] - at[1]).atan2(p[0] - at[0]);
    let base = angle_of(mesh.nodes[along as usize]);
    let from_along = |p: [f64; 3]| (angle_of(p) - base).rem_euclid(TAU);
    let (near, far) = {
        let [a, b] = [neighbours[0], neighbours[1]];
        if from_along(mesh.nodes[a as usize]) <= from_along(mesh.nodes[b as usize]) {
            (a, b)
        } else {
            (b, a)
        }
    };
    let limit = from_along(mesh.nodes[near as usize]);
    // From the first tip the fan before `near` is the left side; into the
    // last tip it is the right side.
    let triangles = &mesh.faces[face].triangles;
    let right_triangles = fan
        .into_iter()
        .filter(|&i| {
            let t = triangles[i];
            let centroid: [f64; 3] = std::array::from_fn(|c| {
                t.iter().map(|&n| mesh.nodes[n as usize][c]).sum::<f64>() / 3.0
            });
            (from_along(centroid) < limit) != first
        })
        .collect();
    Some(Mouth {
        node,
        right_triangles,
        right_neighbour: if first { far } else { near },
    })
}

/// Duplicates a mouth node for the right side's triangles and cuts the
/// boundary edge through it; returns the copy.
fn open_mouth(
    mesh: &mut Mesh,
    face: usize,
    m: &Mouth,
    crack: &str,
    origins: &mut EdgeOrigins,
) -> u32 {
    let copy = mesh.nodes.len() as u32;
    mesh.nodes.push(mesh.nodes[m.node as usize]);
    for &i in &m.right_triangles {
        for n in mesh.faces[face].triangles[i].iter_mut() {
            if *n == m.node {
                *n = copy;
            }
        }
    }
    // The boundary edge with the segment mouth–right neighbour.
    let found = mesh.edges.iter().enumerate().find_map(|(e, edge)| {
        edge.nodes
            .windows(2)
            .position(|w| {
                (w[0] == m.node && w[1] == m.right_neighbour)
                    || (w[1] == m.node && w[0] == m.right_neighbour)
            })
            .map(|j| (e, j))
    });
    let Some((e, j)) = found else {
        return copy;
    };
    let nodes = mesh.edges[e].nodes.clone();
    let at = if nodes[j] == m.node { j } else { j + 1 };
    let right_before = at > 0 && nodes[at - 1] == m.right_neighbour;
    if at == 0 || at + 1 == nodes.len() {
        // The mouth is an end of this edge: the edge just moves to the copy.
        mesh.edges[e].nodes[at] = copy;
        return copy;
    }
    let (mut head, mut tail) = (nodes[..=at].to_vec(), nodes[at..].to_vec());
    if right_before {
        head[at] = copy;
    } else {
        tail[0] = copy;
    }
    let new = mesh.edges.len() as u32;
    let name = format!("{}.beyond.{crack}", mesh.edges[e].name);
    mesh.edges[e].nodes = head;
    mesh.edges.push(MeshEdge { name, nodes: tail });
    // The new part starts `at` nodes into the cut edge's discretisation.
    let origin = origins
        .get(e)
        .copied()
        .flatten()
        .map(|(model_edge, first)| (model_edge, first + at));
    origins.resize(new as usize, None);
    origins.push(origin);
    for f in &mut mesh.faces {
        if let Some(pos) = f.boundary.iter().position(|&(b, _)| b as usize == e) {
            // The new part comes after the kept one along the edge.
            let forward = f.boundary[pos].1;
            f.boundary
                .insert(if forward { pos + 1 } else { pos }, (new, forward));
        }
    }
    for fragment in &mut mesh.fragments {
        if fragment.edges.contains(&(e as u32)) {
            fragment.edges.push(new);
        }
    }
    copy
}
