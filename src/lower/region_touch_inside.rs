//! A carved region touching its kernel region's boundary from inside (issue
//! 6): a disk subtracted from a square and tangent to one of its sides, a
//! bead against the inside of a kernel circle. The kernel face keeps the
//! region's contour as a hole that meets its outer loop at the touch point:
//! that point is one vertex of both loops (the kernel edge split there, the
//! nearest contour vertex moved onto it, as `region_touch` does for
//! neighbours), so the meshes of both faces and the kernel edge share it.
//! The kernel face's angles there are as small as the contour's chords make
//! them: the mesher's small-input-angle exception (no triangle can meet the
//! bound next to them) covers them.
//!
//! Only tangencies are taken: every contour vertex within the touch distance
//! of the kernel outline must belong to a short run that `region_touch::land`
//! lands on a straight, circle or ellipse kernel edge. Anything else (a
//! contour running along an edge without lying on it, a touch on another
//! kind of curve) is refused with the point and the edge.

use super::region_arcs::KernelCurve;
use super::region_inside_cusp::arc_cuts;
use super::region_interfaces::{Outline, face_vertex_set};
use super::region_touch::{KernelEdge, Landing, apply, land, near_runs, nearest, vertex_at};
use crate::geom::Point3;
use crate::ir::{EdgeId, FaceId, Model, OrientedEdge, SourceMap, Vertex, VertexId};
use std::collections::{BTreeMap, BTreeSet};

/// Why a touch from inside was not shared; `carve` reports it as E544.
pub(super) enum InsideRefusal {
    /// The contour comes near the edge without a single tangent point.
    NoTangency { at: Point3, edge: EdgeId },
    /// The touched edge is neither straight nor a circle or ellipse arc.
    Curve { at: Point3, edge: EdgeId },
}

/// Shares each point where region face `fr` (inside kernel face `fk`,
/// crossing none of its edges) touches the kernel outline: the kernel edge
/// is split there or its vertex taken, and the contour vertex nearest the
/// touch moved onto it. `region_edges` are the edges of every region (the
/// holes other carves gave `fk` are no kernel edges); `touch` is the
/// region's touch distance.
pub(super) fn share_inside_touches(
    model: &mut Model,
    source_map: &mut SourceMap,
    (fk, fr): (FaceId, FaceId),
    region_edges: &BTreeSet<EdgeId>,
    touch: f64,
) -> Result<(), InsideRefusal> {
    let mut seen = BTreeSet::new();
    let mut kernel = Vec::new();
    let mut other_curves = Vec::new();
    for oe in model.faces[fk.index()].loops.edges() {
        if region_edges.contains(&oe.edge) || !seen.insert(oe.edge) {
            continue;
        }
        match KernelCurve::of(&model.edge_curve(oe.edge)) {
            Some(curve) => kernel.push(KernelEdge {
                edge: oe.edge,
                curve,
                subdomains: Vec::new(),
            }),
            None => other_curves.push(oe.edge),
        }
    }
    let outline = Outline::of(model, fk);
    let near: Vec<VertexId> = face_vertex_set(model, fr)
        .into_iter()
        .filter(|&v| outline.distance(&model.vertex(v).position) <= touch)
        .collect();
    let Some(&first) = near.first() else {
        return Ok(());
    };
    let refuse_at = |model: &Model, v: VertexId| {
        let at = model.vertex(v).position;
        let edge = outline.nearest_edge(&at).unwrap_or(EdgeId(0));
        if other_curves.contains(&edge) {
            InsideRefusal::Curve { at, edge }
        } else {
            InsideRefusal::NoTangency { at, edge }
        }
    };
    let kernel_vertices = face_vertex_set(model, fk);
    let loops: Vec<Vec<OrientedEdge>> = model.faces[fr.index()].loops.to_vecs();
    let mut landings: BTreeMap<VertexId, Landing> = BTreeMap::new();
    // Per landing: its loop and the index of its vertex there.
    let mut placed: Vec<(usize, usize, Point3)> = Vec::new();
    let mut covered: BTreeSet<VertexId> = BTreeSet::new();
    for (l, lp) in loops.iter().enumerate() {
        for k in &kernel {
            for run in near_runs(model, lp, &k.curve, touch, &kernel_vertices) {
                let closest = run
                    .iter()
                    .map(|&i| vertex_at(model, lp, i))
                    .min_by(|&a, &b| {
                        let d = |v: VertexId| nearest(&k.curve, &model.vertex(v).position).1;
                        d(a).total_cmp(&d(b))
                    })
                    .unwrap_or(first);
                let Some((v, landing)) = land(model, lp, &run, k, (fr, touch)) else {
                    return Err(refuse_at(model, closest));
                };
                covered.extend(run.iter().map(|&i| vertex_at(model, lp, i)));
                // A touch at a kernel vertex is seen from both its edges.
                let same = |l: &Landing| matches!((l, &landing), (Landing::Merge(a), Landing::Merge(b)) if a == b);
                if !landings.values().any(same) && !landings.contains_key(&v) {
                    let at = match landing {
                        Landing::Split { at, .. } => at,
                        Landing::Merge(w) => model.vertex(w).position,
                    };
                    let i = (0..lp.len()).find(|&i| vertex_at(model, lp, i) == v);
                    if let Some(i) = i {
                        placed.push((l, i, at));
                    }
                    landings.insert(v, landing);
                }
            }
        }
    }
    // A vertex near the outline but in no landed run: near an edge of
    // another kind, or the whole contour near it.
    if let Some(&v) = near.iter().find(|v| !covered.contains(v)) {
        return Err(refuse_at(model, v));
    }
    if landings.is_empty() {
        return Err(refuse_at(model, first));
    }
    let cuts = arc_cuts_near(model, source_map, &kernel, &loops, &placed);
    let points: Vec<Point3> = placed.iter().map(|p| p.2).collect();
    apply(model, source_map, &kernel, landings, cuts, covered);
    straighten_at(model, fr, &points);
    Ok(())
}

/// New vertices on the kernel arcs next to each touch point (`placed`: loop,
/// vertex index, point), where the arc's chords would cross the contour
/// (`region_inside_cusp`), by kernel edge.
fn arc_cuts_near(
    model: &mut Model,
    source_map: &mut SourceMap,
    kernel: &[KernelEdge],
    loops: &[Vec<OrientedEdge>],
    placed: &[(usize, usize, Point3)],
) -> BTreeMap<EdgeId, Vec<(f64, VertexId)>> {
    let merge = 16.0 * model.tolerance;
    let mut out: BTreeMap<EdgeId, Vec<(f64, VertexId)>> = BTreeMap::new();
    for &(l, i, at) in placed {
        for k in kernel {
            // The touch lies on the edge (split there) or at its end.
            if nearest(&k.curve, &at).1 > merge {
                continue;
            }
            let name = model.edge(k.edge).name.to_string();
            let origin = source_map.edges.get(&k.edge).copied();
            for u in arc_cuts(model, k.edge, &loops[l], i, at) {
                let list = out.entry(k.edge).or_default();
                let v = VertexId(model.vertices.len() as u32);
                model.vertices.push(Vertex {
                    name: format!("{name}.near{}", list.len() + 1).into(),
                    position: k.curve.point(u),
                });
                if let Some(origin) = origin {
                    source_map.vertices.insert(v, origin);
                }
                list.push((u, v));
            }
        }
    }
    out
}

/// Makes the contour pieces ending at a touch point their chords: split
/// on the true curve they would close the kernel face's cusp there ever
/// further (the curve is tangent to the kernel edge), so refinement could
/// not stop; the chord is within the contour's chordal tolerance of it.
fn straighten_at(model: &mut Model, fr: FaceId, points: &[Point3]) {
    let edges: Vec<EdgeId> = model.faces[fr.index()]
        .loops
        .edges()
        .iter()
        .map(|oe| oe.edge)
        .collect();
    for e in edges {
        let edge = model.edge(e);
        let ends = [edge.begin, edge.end].map(|v| model.vertex(v).position);
        if !ends.iter().any(|p| points.contains(p)) {
            continue;
        }
        let curve = model.edge_curve_mut(e);
        if let crate::geom::Curve::Contour { a, b, .. } = *curve {
            *curve = crate::geom::Curve::Segment { a, b };
        }
    }
}

impl InsideRefusal {
    /// The located E544 for subdomain `kernel` subtracting `region` at `span`.
    pub(super) fn diagnostic(
        &self,
        model: &Model,
        span: crate::span::Span,
        kernel: &str,
        region: &str,
    ) -> crate::diag::Diagnostic {
        let (message, help) = match *self {
            InsideRefusal::NoTangency { at, edge } => (
                format!(
                    "subdomain '{kernel}' subtracts region '{region}', whose contour comes within its chordal tolerance of the kernel edge '{}' from inside near ({:.6}, {:.6}) without touching it at a single point: only a tangency (a short run of contour vertices near the edge, at most one on it) is shared",
                    model.edge(edge).name,
                    at.x,
                    at.y
                ),
                "move the region clear of the kernel boundary, let it touch the edge at one point or cross it, or let its R-function contain the edge's circle or half-plane so that its contour runs along the edge",
            ),
            InsideRefusal::Curve { at, edge } => (
                format!(
                    "subdomain '{kernel}' subtracts region '{region}', whose contour touches the kernel edge '{}' from inside near ({:.6}, {:.6}), which is neither straight nor a circle or ellipse arc: only those share a touch point",
                    model.edge(edge).name,
                    at.x,
                    at.y
                ),
                "move the region clear of the edge, or let it cross the edge elsewhere than at a tangency",
            ),
        };
        crate::diag::Diagnostic::new(crate::diag::Code::RegionCarveOutside, span, message)
            .with_help(help)
    }
}
