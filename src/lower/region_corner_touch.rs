//! A region's contour passing through a kernel vertex (issue 6): a bead
//! against a polygon's corner touches it at that one point, where both
//! kernel edges leave the region. `region_touch` takes such a touch only
//! when a contour vertex happens to lie within the touch distance of the
//! kernel edges; otherwise the contour's chord passes the corner at up to
//! the chordal tolerance and the meshes would leave a gap there. Here the
//! touch is found from the geometry: the region's function is zero at the
//! kernel vertex (to root finding's precision), a contour chord passes
//! within the touch distance of it, and the function is negative a step
//! along each kernel edge from it. The nearer end of that chord becomes the
//! kernel vertex, so both meshes have the corner node.

use super::region_arcs::{ON_ARC_FRACTION, begin, end, extent};
use super::region_pairs::{off_zero_set, segment_distance};
use crate::geom::{Curve, Point3};
use crate::ir::{EdgeId, FaceId, Model, SourceMap, VertexId};
use std::collections::{BTreeMap, BTreeSet};

/// Merges a contour vertex into each kernel vertex a region's contour
/// passes through without a vertex of its own near it. `touched` (region
/// vertices the touch check must not count) comes back renumbered, with
/// the kernel vertices taken added.
pub(super) fn share_corner_touches(
    model: &mut Model,
    source_map: &mut SourceMap,
    first_region: usize,
    touch_of: impl Fn(&Model, usize) -> f64,
    reported: &BTreeSet<(usize, usize)>,
    touched: BTreeSet<VertexId>,
) -> BTreeSet<VertexId> {
    let n = model.subdomains.len();
    let region_edges: BTreeSet<EdgeId> =
        super::region_interfaces::face_edges(model, first_region..n).collect();
    // Each kernel vertex with the kernel edges at it and their subdomains.
    let mut at_vertex: BTreeMap<VertexId, (Vec<EdgeId>, BTreeSet<usize>)> = BTreeMap::new();
    for k in 0..first_region {
        for e in super::region_interfaces::face_edges(model, k..k + 1) {
            if region_edges.contains(&e) {
                continue;
            }
            let edge = model.edge(e);
            for w in [edge.begin, edge.end] {
                let entry = at_vertex.entry(w).or_default();
                if !entry.0.contains(&e) {
                    entry.0.push(e);
                }
                entry.1.insert(k);
            }
        }
    }
    let mut merges: BTreeMap<VertexId, VertexId> = BTreeMap::new();
    let mut taken = BTreeSet::new();
    for r in first_region..n {
        let Some(fr) = super::region_interfaces::face_of(model, r) else {
            continue;
        };
        let own = super::region_interfaces::face_vertex_set(model, fr);
        let touch = touch_of(model, r);
        for (&w, (edges, users)) in &at_vertex {
            if own.contains(&w) || users.iter().any(|&k| reported.contains(&(k, r))) {
                continue;
            }
            if let Some(v) = corner_touch(model, fr, w, edges, touch)
                && !merges.contains_key(&v)
            {
                merges.insert(v, w);
                taken.insert(w);
            }
        }
    }
    if merges.is_empty() {
        return touched;
    }
    // The region's pieces at a merged vertex end at the kernel vertex.
    for e in region_edges {
        let edge = &mut model.edges[e.index()];
        let mut moved = false;
        for v in [&mut edge.begin, &mut edge.end] {
            if let Some(&w) = merges.get(v) {
                *v = w;
                moved = true;
            }
        }
        if moved {
            super::edge_parts::follow_vertices(model, e);
        }
    }
    let keep_edge = vec![true; model.edges.len()];
    let keep_vertex: Vec<bool> = (0..model.vertices.len())
        .map(|v| !merges.contains_key(&VertexId(v as u32)))
        .collect();
    super::prune::drop_entities(model, source_map, &keep_edge, &keep_vertex);
    // Ids after the drop: each loses the number of dropped ones before it.
    touched
        .into_iter()
        .map(|v| merges.get(&v).copied().unwrap_or(v))
        .chain(taken)
        .map(|v| {
            let before = merges.keys().take_while(|&&u| u < v).count() as u32;
            VertexId(v.0 - before)
        })
        .collect()
}

/// The contour vertex of face `fr` to merge into kernel vertex `w`, when
/// the region's contour passes through `w` touching the kernel edges there
/// from outside and no contour vertex lies within `touch` of it.
fn corner_touch(
    model: &Model,
    fr: FaceId,
    w: VertexId,
    edges: &[EdgeId],
    touch: f64,
) -> Option<VertexId> {
    let p = model.vertex(w).position;
    // The nearest chord of the contour.
    let (oe, distance) = model.faces[fr.index()]
        .loops
        .edges()
        .iter()
        .map(|&oe| {
            let (a, b) = (
                model.vertex(begin(model, oe)).position,
                model.vertex(end(model, oe)).position,
            );
            (oe, segment_distance(p, a, b))
        })
        .min_by(|x, y| x.1.total_cmp(&y.1))?;
    if distance > touch {
        return None;
    }
    let curve = model.edge_curve(oe.edge);
    let Curve::Contour { f, .. } = &*curve else {
        return None;
    };
    // On the zero set as the traced vertices are.
    let tight = ON_ARC_FRACTION * extent(model, fr);
    if off_zero_set(f, p, tight) > tight {
        return None;
    }
    let (a, b) = (begin(model, oe), end(model, oe));
    let gap = |v: VertexId| (model.vertex(v).position - p).norm();
    // A vertex near it is `region_touch`'s case.
    if gap(a) <= touch || gap(b) <= touch {
        return None;
    }
    // Both kernel edges leave the region: f < 0 a step along each.
    let step = 0.5 * gap(a).min(gap(b));
    let value = |q: Point3| f.eval_point([q.x, q.y, q.z]);
    let outside = edges.iter().all(|&e| {
        let edge = model.edge(e);
        let kernel = model.edge_curve(e);
        let length = kernel.length().max(f64::MIN_POSITIVE);
        let t = (step / length).min(0.25);
        let q = if edge.begin == w {
            kernel.point(t)
        } else {
            kernel.point(1.0 - t)
        };
        value(q) < 0.0
    });
    outside.then(|| if gap(a) <= gap(b) { a } else { b })
}
