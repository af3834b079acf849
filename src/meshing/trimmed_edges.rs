//! The topology IR's trimmed edges and vertices on the mesh (issue 9): each
//! IR edge of a trimmed face (a trim piece or a patch side, `S.trim[k]`,
//! `S.u_min[k]`, …) becomes one mesh edge, cut out of the boundary chain
//! its surface was meshed with, and each IR vertex the node at its place on
//! that chain. An edge the face shares with a model edge or with an earlier
//! trimmed face (a hole's rim) is written once, by its owner, and the face
//! only refers to it, as ordinary faces do: mesh edge k is IR edge k, mesh
//! vertex k IR vertex k.

use super::MeshError;
use crate::geom::{Curve, Point3};
use crate::ir::Model;
use crate::mesh::{Mesh, MeshEdge, MeshVertex};
use crate::trimmed::shared::{distance_to_polyline, nearest_point};

/// Appends the mesh edges and vertices of `model`'s trimmed entities
/// (`model.trimmed_start`), `chains[j]` being trimmed surface j's boundary
/// chains in global node ids (a closed chain repeats its first node), and
/// returns each trimmed face's boundary (mesh edge, direction in its loop).
pub(super) fn write(
    model: &Model,
    mesh: &mut Mesh,
    chains: &[Vec<Vec<u32>>],
) -> Result<Vec<Vec<(u32, bool)>>, MeshError> {
    let Some([v0, e0, f0]) = model.trimmed_start else {
        return Ok(vec![Vec::new(); chains.len()]);
    };
    if mesh.edges.len() != e0 || mesh.vertices.len() != v0 {
        return Err(MeshError::Internal {
            entity: "the trimmed surfaces".into(),
            message: format!(
                "the mesh has {} edges and {} vertices before them, the model {e0} and {v0}",
                mesh.edges.len(),
                mesh.vertices.len()
            ),
        });
    }
    let node_point = |n: u32| {
        let p = mesh.nodes.get(n as usize).copied().unwrap_or([f64::NAN; 3]);
        Point3::new(p[0], p[1], p[2])
    };
    let mut edge_nodes: Vec<Option<Vec<u32>>> = vec![None; model.edges.len() - e0];
    let mut vertex_nodes: Vec<Option<u32>> = vec![None; model.vertices.len() - v0];
    let mut boundaries = Vec::with_capacity(chains.len());
    for (j, own) in chains.iter().enumerate() {
        let Some(face) = model.faces.get(f0 + j) else {
            boundaries.push(Vec::new());
            continue;
        };
        let rings: Vec<Ring> = own
            .iter()
            .map(|c| Ring::new(c, &node_point))
            .filter(|r| r.nodes.len() >= 2)
            .collect();
        for oe in face.loops.iter().flatten() {
            let k = oe.edge.index();
            if k < e0 || edge_nodes[k - e0].is_some() {
                continue;
            }
            let edge = &model.edges[k];
            let path = cut(model, edge, &rings).ok_or_else(|| MeshError::Face {
                face: face.name.to_string(),
                reason: format!(
                    "its boundary piece `{}` was not found on the mesh of its boundary; \
                     refine the tolerance so the trim curve is traced alike for the model \
                     and the mesh",
                    edge.name
                ),
            })?;
            for (v, node) in [(edge.begin, path[0]), (edge.end, path[path.len() - 1])] {
                if let Some(slot) = v.index().checked_sub(v0) {
                    vertex_nodes[slot].get_or_insert(node);
                }
            }
            edge_nodes[k - e0] = Some(path);
        }
        boundaries.push(
            face.loops
                .iter()
                .flatten()
                .map(|oe| (oe.edge.0, oe.forward))
                .collect(),
        );
    }
    for (k, nodes) in edge_nodes.into_iter().enumerate() {
        let edge = &model.edges[e0 + k];
        let Some(nodes) = nodes else {
            return Err(MeshError::Internal {
                entity: format!("edge `{}`", edge.name),
                message: "no trimmed face bounded by it was meshed".into(),
            });
        };
        mesh.edges.push(MeshEdge {
            name: edge.name.to_string(),
            nodes,
        });
    }
    for (k, node) in vertex_nodes.into_iter().enumerate() {
        let vertex = &model.vertices[v0 + k];
        let Some(node) = node else {
            return Err(MeshError::Internal {
                entity: format!("vertex `{}`", vertex.name),
                message: "no trimmed edge ends at it".into(),
            });
        };
        mesh.vertices.push(MeshVertex {
            name: vertex.name.to_string(),
            node,
        });
    }
    Ok(boundaries)
}

/// One boundary chain of a trimmed face's mesh: its nodes (a closed chain
/// without the repeated last node) and their points.
struct Ring {
    nodes: Vec<u32>,
    points: Vec<Point3>,
    closed: bool,
}

impl Ring {
    fn new(chain: &[u32], point: &impl Fn(u32) -> Point3) -> Ring {
        let closed = chain.len() > 2 && chain.first() == chain.last();
        let nodes: Vec<u32> = if closed {
            chain[..chain.len() - 1].to_vec()
        } else {
            chain.to_vec()
        };
        let points = nodes.iter().map(|&n| point(n)).collect();
        Ring {
            nodes,
            points,
            closed,
        }
    }

    /// The node indices from index `a` to index `b`, forward or backward (around
    /// the ring when closed; `a == b` on a closed ring is the whole ring).
    fn path(&self, a: usize, b: usize, forward: bool) -> Option<Vec<usize>> {
        let n = self.nodes.len();
        if !self.closed && (forward && b < a || !forward && a < b) {
            return None;
        }
        let steps = match (forward, self.closed) {
            (_, true) if a == b => n,
            (true, _) => (b + n - a) % n,
            (false, _) => (a + n - b) % n,
        };
        Some(
            (0..=steps)
                .map(|s| {
                    if forward {
                        (a + s) % n
                    } else {
                        (a + n - s % n) % n
                    }
                })
                .collect(),
        )
    }
}

/// The mesh nodes of IR edge `edge` (from its begin to its end vertex) cut
/// out of the face's rings: the ring node nearest the begin vertex, the
/// one nearest the end, and the way round that passes by the edge's own
/// points. `None` when the path strays from the edge's points.
fn cut(model: &Model, edge: &crate::ir::Edge, rings: &[Ring]) -> Option<Vec<u32>> {
    // Chains are never a primitive's: their carriers are their own.
    let Some(Curve::Chain { points }) = edge.carrier.owned() else {
        return None;
    };
    let begin = model.vertices.get(edge.begin.index())?.position;
    let end = model.vertices.get(edge.end.index())?.position;
    let (r, a) = rings
        .iter()
        .enumerate()
        .map(|(r, ring)| {
            let i = nearest_point(&ring.points, &begin);
            (r, i, (ring.points[i] - begin).norm())
        })
        .min_by(|x, y| x.2.total_cmp(&y.2))
        .map(|(r, i, _)| (r, i))?;
    let ring = &rings[r];
    let n = ring.nodes.len();
    let closed_edge = edge.begin == edge.end;
    let b = if closed_edge {
        a
    } else {
        nearest_point(&ring.points, &end)
    };
    // A point inside the edge tells the way round.
    let probe = points[if closed_edge {
        (points.len() / 8).max(1)
    } else {
        points.len() / 2
    }];
    let m = nearest_point(&ring.points, &probe);
    let forward = if closed_edge {
        (m + n - a) % n <= n / 2
    } else if ring.closed {
        (m + n - a) % n <= (b + n - a) % n
    } else {
        b >= a
    };
    let path = ring.path(a, b, forward)?;
    let line: Vec<Point3> = path.iter().map(|&i| ring.points[i]).collect();
    let longest = |l: &[Point3]| {
        l.windows(2)
            .map(|w| (w[1] - w[0]).norm())
            .fold(0.0, f64::max)
    };
    // A guard against a wrong ring or way round, not a precision check: the
    // model traces at its own tolerance, the mesh at the mesh's, so the two
    // polylines differ by up to about a chord.
    let distance = 4.0 * model.tolerance + 0.5 * longest(&line).max(longest(points));
    // Up to 64 of the edge's points, evenly spread, checked.
    let stride = points.len().div_ceil(64).max(1);
    let near = points
        .iter()
        .step_by(stride)
        .all(|p| distance_to_polyline(&line, p) <= distance);
    (path.len() >= 2 && near).then(|| path.iter().map(|&i| ring.nodes[i]).collect())
}
