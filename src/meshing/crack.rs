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

use crate::ir::Model;
use crate::mesh::{Mesh, MeshEdge, MeshFragment};
use std::f64::consts::TAU;

/// Opens every crack poly_line whose chain lies in the mesh's triangles.
pub(crate) fn open(model: &Model, mesh: &mut Mesh) {
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
        let right = open_chain(mesh, face, &chain);
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
