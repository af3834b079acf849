//! Second-order elements: one node in the middle of every element edge,
//! shared by the triangles and lines that meet there. On a model edge the
//! node lies on the curve at the middle of the segment's parameter range, so
//! 6-node triangles follow curved boundaries and interfaces (both sides
//! share it); inside a face it is the chord's middle.
//!
//! # Limitations
//! - On curved 3D surfaces face-interior mid nodes lie on the chord, not on
//!   the surface.

use super::crack::EdgeOrigins;
use super::edges::EdgeNodes;
use crate::ir::Model;
use crate::mesh::{Mesh, QuadraticNodes};
use std::collections::HashMap;

/// `origins` (from [`super::crack::open`]) says which model edge, from which
/// node on, each mesh edge follows: the parts of an edge cut at a crack
/// mouth keep their mid nodes on the curve.
pub(crate) fn elevate(
    model: &Model,
    edge_nodes: &[EdgeNodes],
    origins: &EdgeOrigins,
    mesh: &mut Mesh,
) {
    let mut mids: HashMap<(u32, u32), u32> = HashMap::new();
    let key = |a: u32, b: u32| (a.min(b), a.max(b));
    let mut quadratic = QuadraticNodes::default();
    for (i, edge) in mesh.edges.iter().enumerate() {
        let mut per_segment = Vec::with_capacity(edge.nodes.len().saturating_sub(1));
        let curve_params = origins.get(i).copied().flatten().and_then(|(m, first)| {
            let curve = model.edges.get(m)?.curve(&model.solids);
            Some((curve, edge_nodes.get(m)?, first))
        });
        for (j, w) in edge.nodes.windows(2).enumerate() {
            let id = *mids.entry(key(w[0], w[1])).or_insert_with(|| {
                let point = match curve_params {
                    Some((ref curve, disc, first)) if first + j + 1 < disc.params.len() => {
                        let k = first + j;
                        let s = 0.5 * (disc.params[k] + disc.params[k + 1]);
                        let p = curve.point(s);
                        [p.x, p.y, p.z]
                    }
                    _ => middle(&mesh.nodes, w[0], w[1]),
                };
                mesh.nodes.push(point);
                (mesh.nodes.len() - 1) as u32
            });
            per_segment.push(id);
        }
        quadratic.edges.push(per_segment);
    }
    let mut mid = |nodes: &mut Vec<[f64; 3]>, a: u32, b: u32| {
        *mids.entry(key(a, b)).or_insert_with(|| {
            let point = middle(nodes, a, b);
            nodes.push(point);
            (nodes.len() - 1) as u32
        })
    };
    for face in &mesh.faces {
        let per_triangle = face
            .triangles
            .iter()
            .map(|&[a, b, c]| {
                [
                    mid(&mut mesh.nodes, a, b),
                    mid(&mut mesh.nodes, b, c),
                    mid(&mut mesh.nodes, c, a),
                ]
            })
            .collect();
        quadratic.faces.push(per_triangle);
    }
    for line in &mesh.polylines {
        let per_segment = line
            .nodes
            .windows(2)
            .map(|w| mid(&mut mesh.nodes, w[0], w[1]))
            .collect();
        quadratic.polylines.push(per_segment);
    }
    mesh.quadratic = Some(quadratic);
}

fn middle(nodes: &[[f64; 3]], a: u32, b: u32) -> [f64; 3] {
    let (p, q) = (nodes[a as usize], nodes[b as usize]);
    [
        0.5 * (p[0] + q[0]),
        0.5 * (p[1] + q[1]),
        0.5 * (p[2] + q[2]),
    ]
}
