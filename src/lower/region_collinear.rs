//! Region contours running across a joint of collinear kernel edges (issue
//! 6): two straight kernel edges meeting at a vertex on one line (two
//! rectangles stacked, a polygon with a vertex on a straight stretch), and a
//! region's contour running along that line over the vertex. The contour
//! piece that steps over the vertex is cut there first, so `region_arcs`
//! finds one run on each edge, both ending at the joint, and the runs are
//! replaced by the two edges' parts meeting at the kernel vertex (no hanging
//! node). [`continues_past`] tells `region_arcs` that such a run going on
//! past its edge's end is not refused.

use super::edge_parts::EdgeParts;
use super::region_arcs::{ON_ARC_FRACTION, extent};
use crate::geom::{Curve, Point3, Vec3};
use crate::ir::{EdgeId, Model, SourceMap, Vertex, VertexId};
use std::collections::{BTreeMap, BTreeSet};

/// How far from parallel two edges' directions may be to count as one line.
const PARALLEL: f64 = 1e-9;

/// A kernel vertex where two collinear straight kernel edges meet.
struct Joint {
    at: Point3,
    direction: Vec3,
}

/// Cuts each region contour piece lying on the line of a collinear joint and
/// stepping over the joint's vertex into two pieces meeting at a new region
/// vertex there (merged into the kernel vertex by `region_arcs`).
pub(super) fn split_at_joints(model: &mut Model, source_map: &mut SourceMap, first_region: usize) {
    let n = model.subdomains.len();
    let region_edges: BTreeSet<EdgeId> =
        super::region_interfaces::face_edges(model, first_region..n).collect();
    let kernel_edges: BTreeSet<EdgeId> =
        super::region_interfaces::face_edges(model, 0..first_region)
            .filter(|e| !region_edges.contains(e))
            .collect();
    let joints = joints(model, &kernel_edges);
    if joints.is_empty() {
        return;
    }
    let merge = 16.0 * model.tolerance;
    let mut cuts: Vec<(EdgeId, Point3)> = Vec::new();
    for r in first_region..n {
        let Some(fr) = super::region_interfaces::face_of(model, r) else {
            continue;
        };
        let tol = ON_ARC_FRACTION * extent(model, fr);
        for oe in model.faces[fr.index()].loops.edges() {
            let edge = model.edge(oe.edge);
            let curve = edge.curve(&model.solids);
            let Curve::Contour { a, b, .. } = &*curve else {
                continue;
            };
            let middle = curve.point(0.5);
            for j in &joints {
                let off = |p: &Point3| {
                    let d = p - j.at;
                    (d - j.direction * d.dot(&j.direction)).norm()
                };
                let (sa, sb) = ((a - j.at).dot(&j.direction), (b - j.at).dot(&j.direction));
                let over = sa.min(sb) < -merge && sa.max(sb) > merge;
                if over && off(a) <= tol && off(b) <= tol && off(&middle) <= tol {
                    cuts.push((oe.edge, j.at));
                }
            }
        }
    }
    cuts.sort_by_key(|c| c.0);
    cuts.dedup_by_key(|c| c.0);
    for (e, at) in cuts {
        cut(model, source_map, e, at);
    }
}

/// The kernel vertices where two straight kernel edges meet on one line.
fn joints(model: &Model, kernel_edges: &BTreeSet<EdgeId>) -> Vec<Joint> {
    let mut at_vertex: BTreeMap<VertexId, Vec<Vec3>> = BTreeMap::new();
    for &e in kernel_edges {
        let edge = model.edge(e);
        if let Curve::Segment { a, b } = *edge.curve(&model.solids) {
            let length = (b - a).norm();
            if length > 0.0 {
                let d = (b - a) / length;
                at_vertex.entry(edge.begin).or_default().push(d);
                at_vertex.entry(edge.end).or_default().push(-d);
            }
        }
    }
    at_vertex
        .into_iter()
        .filter_map(|(vertex, out)| {
            let direction = *out.iter().find(|d| {
                out.iter()
                    .any(|o| (*o + **d).norm() <= PARALLEL && (*o - **d).norm() > PARALLEL)
            })?;
            Some(Joint {
                at: model.vertex(vertex).position,
                direction,
            })
        })
        .collect()
}

/// Cuts region edge `e` (a contour piece) at `at` into two pieces meeting at
/// a new vertex there.
fn cut(model: &mut Model, source_map: &mut SourceMap, e: EdgeId, at: Point3) {
    let edge = model.edge(e).clone();
    let Curve::Contour { a, b, f } = edge.curve(&model.solids).into_owned() else {
        return;
    };
    let v = VertexId(model.vertices.len() as u32);
    model.vertices.push(Vertex {
        name: format!("{}.joint", edge.name).into(),
        position: at,
    });
    let mut parts = EdgeParts::new(model, e);
    let first = parts.push(
        model,
        source_map,
        Curve::Contour {
            a,
            b: at,
            f: f.clone(),
        },
        edge.begin,
        v,
    );
    let second = parts.push(
        model,
        source_map,
        Curve::Contour { a: at, b, f },
        v,
        edge.end,
    );
    parts.finish(model);
    let chain = [first, second].map(|edge| crate::ir::OrientedEdge {
        edge,
        forward: true,
    });
    super::region_interfaces::replace_edge(model, e, &chain);
}

/// Whether a run on the straight kernel edge `edge`, whose contour goes on
/// past the run's `end` to `beyond`, continues onto a collinear kernel edge
/// from the edge's end vertex at `end` (the joint `split_at_joints` cut).
pub(super) fn continues_past(
    model: &Model,
    edge: EdgeId,
    end: VertexId,
    beyond: VertexId,
    tol: f64,
) -> bool {
    let merge = 16.0 * model.tolerance;
    let (p, q) = (model.vertex(end).position, model.vertex(beyond).position);
    let e = model.edge(edge);
    let Some(joint) = [e.begin, e.end]
        .into_iter()
        .find(|&k| (model.vertex(k).position - p).norm() <= merge)
    else {
        return false;
    };
    model.edges.iter().enumerate().any(|(g, other)| {
        let Curve::Segment { a, b } = *other.curve(&model.solids) else {
            return false;
        };
        let length = (b - a).norm();
        if EdgeId(g as u32) == edge || length <= 0.0 || ![other.begin, other.end].contains(&joint) {
            return false;
        }
        let d = (b - a) / length;
        let along = model.edge_curve(edge).tangent(0.0);
        if (along.x * d.y - along.y * d.x).abs() > PARALLEL {
            return false;
        }
        let u = (q - a).dot(&d);
        let off = (q - a - d * u).norm();
        off <= tol && (-tol..=length + tol).contains(&u)
    })
}
