//! Carved regions crossing a kernel edge (issue 6): a kernel subdomain's
//! `<difference>` subtracts an R-function region whose contour crosses the
//! kernel face's boundary (a disk sticking out of a rectangle's side, a blob
//! across a kernel circle). The region subdomain stays its whole solid, as a
//! kernel subdomain subtracted by `<difference>` does: the kernel face loses
//! the part inside the region, and the region's part outside the kernel face
//! is its own (fragment `REGION|exterior`, or an overlap with whatever lies
//! there, E407).
//!
//! The crossings are the sign changes of the region's function along each
//! kernel edge (sampled, then bisected to the last bit of the edge's
//! parameter): the kernel edge is cut there (`NAME.2`, … as `edge_parts`
//! names parts), and so is the contour piece through the point (its second
//! part `PIECE.2`), unless a contour vertex is near enough to be moved there.
//! The kernel face then takes its edges outside the region and the contour
//! pieces inside its outline reversed, chained into loops as `rejoin` does,
//! so the pieces inside form the fragment `KERNEL|REGION`.

use super::edge_parts::{EdgeParts, follow_vertices};
use super::region_arcs::{KernelCurve, split_kernel_edge};
use super::region_interfaces::{Outline, chain, replace_edge};
use crate::diag::{Code, Diagnostic};
use crate::geom::{Curve, Point3};
use crate::implicit::tape::Ssa;
use crate::ir::{EdgeId, FaceId, Loops, Model, OrientedEdge, SourceMap, Vertex, VertexId};
use crate::span::Span;
use std::collections::{BTreeMap, BTreeSet};

/// Samples of the region's function along each kernel edge: at least
/// `MIN_SAMPLES`, and one per 1/`PER_EXTENT` of the region's extent (a
/// small region on a long edge), at most `MAX_SAMPLES`. Two crossings closer
/// than the spacing are missed: no sign change (the contour then stays
/// near the edge, and the touch check reports it).
const MIN_SAMPLES: usize = 512;
const PER_EXTENT: f64 = 256.0;
const MAX_SAMPLES: usize = 1 << 16;

/// A contour vertex within this fraction of its piece's length from a
/// crossing is moved onto it rather than the piece cut (no short piece).
const MOVE_FRACTION: f64 = 0.25;

/// Why a crossing was not split; `carve` reports it as E544.
pub(super) enum Refusal {
    /// A side of the region's box (not f = 0) crosses the kernel edge.
    BoxSide { at: Point3, edge: EdgeId },
    /// The crossed edge is neither straight nor a circle or ellipse arc.
    Curve { at: Point3, edge: EdgeId },
    /// The crossings found do not cut the boundaries into simple loops.
    Unmatched { at: Point3, edge: EdgeId },
}

impl Refusal {
    /// The located E544 for subdomain `kernel` subtracting `region` at `span`.
    pub(super) fn diagnostic(
        &self,
        model: &Model,
        span: Span,
        kernel: &str,
        region: &str,
    ) -> Diagnostic {
        let (at, edge) = match *self {
            Refusal::BoxSide { at, edge }
            | Refusal::Curve { at, edge }
            | Refusal::Unmatched { at, edge } => (at, model.edge(edge).name.to_string()),
        };
        let (message, help) = match self {
            Refusal::BoxSide { .. } => (
                format!(
                    "subdomain '{kernel}' subtracts region '{region}', a side of whose box crosses the kernel edge '{edge}' at ({:.6}, {:.6}): only the contour f = 0 is split at a crossing",
                    at.x, at.y
                ),
                "widen the region's box (x_min … y_max) so that f = 0 bounds the region where it crosses the kernel boundary, or clip its R-function to the kernel shape",
            ),
            Refusal::Curve { .. } => (
                format!(
                    "subdomain '{kernel}' subtracts region '{region}', whose contour crosses the edge '{edge}' at ({:.6}, {:.6}), which is neither straight nor a circle or ellipse arc: only those are split at a crossing",
                    at.x, at.y
                ),
                "clip the region to the kernel region (intersect its R-function with the kernel shape, so that its contour runs along the edge instead of crossing it), or move the region clear of the edge",
            ),
            Refusal::Unmatched { .. } => (
                format!(
                    "subdomain '{kernel}' subtracts region '{region}', whose contour crosses the kernel edge '{edge}' near ({:.6}, {:.6}) where the crossings found do not cut both boundaries into simple loops (crossings closer than the sampling of the edge, or a crossing at a tangency)",
                    at.x, at.y
                ),
                "move the region so that its contour crosses each kernel edge clearly, or clip its R-function to the kernel shape",
            ),
        };
        Diagnostic::new(Code::RegionCarveOutside, span, message).with_help(help)
    }
}

/// A sign change of the region's function on a kernel edge, at parameter
/// `u` of its `KernelCurve`.
struct Crossing {
    edge: EdgeId,
    u: f64,
    at: Point3,
}

/// Splits kernel face `fk` and region face `fr` at their crossings and
/// gives `fk` the loops of its part outside the region. `region_edges` are
/// the edges of every region (not kernel edges); `touch` is the region's
/// touch distance; `near` the crossing `carve` saw (where a refusal points
/// when no crossing is found).
pub(super) fn split_at_crossings(
    model: &mut Model,
    source_map: &mut SourceMap,
    (fk, fr): (FaceId, FaceId),
    region_edges: &BTreeSet<EdgeId>,
    touch: f64,
    near: (Point3, EdgeId),
) -> Result<(), Refusal> {
    let unmatched = Refusal::Unmatched {
        at: near.0,
        edge: near.1,
    };
    let Some(f) = region_function(model, fr) else {
        return Err(unmatched);
    };
    box_sides_clear(model, fr, fk, touch)?;
    let extent = super::region_arcs::extent(model, fr);
    let crossings = find_crossings(model, (fk, fr), region_edges, &f, (touch, extent))?;
    if crossings.is_empty() {
        return Err(unmatched);
    }
    place_crossings(model, source_map, fk, fr, &crossings);
    let kernel = Outline::of(model, fk);
    let region = Outline::of(model, fr);
    let inside_region = |p: &Point3| {
        if region.distance(p) > touch {
            region.contains(p)
        } else {
            f.eval_point([p.x, p.y, p.z]) > 0.0
        }
    };
    let region_forward: BTreeMap<EdgeId, bool> = model.faces[fr.index()]
        .loops
        .edges()
        .iter()
        .map(|oe| (oe.edge, oe.forward))
        .collect();
    let kernel_loops: Vec<OrientedEdge> = model.faces[fk.index()].loops.edges().to_vec();
    let mut pool = Vec::with_capacity(kernel_loops.len() + region_forward.len());
    let mut dropped = Vec::new();
    for oe in &kernel_loops {
        match region_forward.get(&oe.edge) {
            // A shared arc the region runs the same way is inside it.
            Some(&forward) => {
                if forward != oe.forward {
                    pool.push(*oe);
                }
            }
            None if inside_region(&model.edge_curve(oe.edge).point(0.5)) => dropped.push(oe.edge),
            None => pool.push(*oe),
        }
    }
    let kernel_edges: BTreeSet<EdgeId> = kernel_loops.iter().map(|oe| oe.edge).collect();
    let kept = pool.len();
    for oe in model.faces[fr.index()].loops.edges() {
        if !kernel_edges.contains(&oe.edge)
            && kernel.contains(&piece_middle(&model.edge_curve(oe.edge)))
        {
            pool.push(OrientedEdge {
                edge: oe.edge,
                forward: !oe.forward,
            });
        }
    }
    if pool.len() == kept {
        return Err(unmatched);
    }
    let loops = chain(model, &pool).map_err(|at| Refusal::Unmatched { at, edge: near.1 })?;
    model.faces[fk.index()].loops = Loops::from(loops);
    drop_unused(model, source_map, &dropped);
    Ok(())
}

/// A point in the middle of a region piece, to tell which side of the
/// kernel outline it is on: a contour piece's chord middle (its curve
/// middle costs a root finding, and lies within the chordal tolerance of
/// it, far closer than a piece ending at a crossing comes to the outline
/// elsewhere).
fn piece_middle(curve: &Curve) -> Point3 {
    match *curve {
        Curve::Contour { a, b, .. } => a + (b - a) * 0.5,
        _ => curve.point(0.5),
    }
}

/// The region's function, from any of its contour pieces.
fn region_function(model: &Model, fr: FaceId) -> Option<Ssa> {
    model.faces[fr.index()]
        .loops
        .edges()
        .iter()
        .find_map(|oe| match &*model.edge_curve(oe.edge) {
            Curve::Contour { f, .. } => Some((**f).clone()),
            _ => None,
        })
}

/// Refuses a side of the region's box (a run of straight pieces) with
/// points clearly on both sides of the kernel outline: f does not change
/// sign there.
fn box_sides_clear(model: &Model, fr: FaceId, fk: FaceId, touch: f64) -> Result<(), Refusal> {
    let kernel = Outline::of(model, fk);
    for lp in model.faces[fr.index()].loops.iter() {
        let n = lp.len();
        let straight =
            |i: usize| matches!(*model.edge_curve(lp[i % n].edge), Curve::Segment { .. });
        let start = (0..n).find(|&i| !straight(i)).unwrap_or(0);
        let mut run: Vec<Point3> = Vec::new();
        for i in start..=start + n {
            if i < start + n && straight(i) {
                let oe = lp[i % n];
                let e = model.edge(oe.edge);
                let (a, b) = if oe.forward {
                    (e.begin, e.end)
                } else {
                    (e.end, e.begin)
                };
                if run.is_empty() {
                    run.push(model.vertex(a).position);
                }
                run.push(model.vertex(b).position);
                continue;
            }
            let clear: Vec<(Point3, bool)> = run
                .iter()
                .filter(|p| kernel.distance(p) > touch)
                .map(|p| (*p, kernel.contains(p)))
                .collect();
            if let Some(w) = clear.windows(2).find(|w| w[0].1 != w[1].1) {
                let at = crossing_on_outline(&kernel, &run, (w[0].0, w[1].0));
                let edge = kernel.nearest_edge(&at).unwrap_or(lp[i % n].edge);
                return Err(Refusal::BoxSide { at, edge });
            }
            run.clear();
        }
    }
    Ok(())
}

/// The point of the polyline `run` between its points `from` and `to`
/// nearest the outline (where the box side crosses it).
fn crossing_on_outline(kernel: &Outline, run: &[Point3], (from, to): (Point3, Point3)) -> Point3 {
    let first = run.iter().position(|p| *p == from).unwrap_or(0);
    let last = run.iter().position(|p| *p == to).unwrap_or(run.len() - 1);
    let mut best = (f64::INFINITY, from);
    for w in run[first..=last.max(first)].windows(2) {
        // Bisection along the piece when it changes side, else its ends.
        let (mut lo, mut hi) = (w[0], w[1]);
        if kernel.contains(&lo) != kernel.contains(&hi) {
            for _ in 0..60 {
                let mid = lo + (hi - lo) * 0.5;
                if kernel.contains(&mid) == kernel.contains(&w[0]) {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
        }
        for p in [lo, hi] {
            let d = kernel.distance(&p);
            if d < best.0 {
                best = (d, p);
            }
        }
    }
    best.1
}

/// The sign changes of f along the kernel edges of `fk` (other regions'
/// contours excluded), each within the contour's chordal tolerance of the
/// region's outline (beyond its box f may change sign too), in face order.
fn find_crossings(
    model: &Model,
    (fk, fr): (FaceId, FaceId),
    region_edges: &BTreeSet<EdgeId>,
    f: &Ssa,
    (touch, extent): (f64, f64),
) -> Result<Vec<Crossing>, Refusal> {
    let mut seen = BTreeSet::new();
    let mut out = Vec::new();
    for oe in model.faces[fk.index()].loops.edges() {
        if region_edges.contains(&oe.edge) || !seen.insert(oe.edge) {
            continue;
        }
        let curve = model.edge_curve(oe.edge).into_owned();
        let g = |s: f64| {
            let p = curve.point(s);
            f.eval_point([p.x, p.y, p.z])
        };
        let per_length = (curve.length() * PER_EXTENT / extent).ceil();
        let samples = if per_length.is_finite() {
            (per_length as usize).clamp(MIN_SAMPLES, MAX_SAMPLES)
        } else {
            MIN_SAMPLES
        };
        let mut roots = Vec::new();
        let mut previous = (0.0, g(0.0));
        for i in 1..=samples {
            let s = i as f64 / samples as f64;
            let here = (s, g(s));
            if previous.1.is_finite() && here.1.is_finite() && (previous.1 > 0.0) != (here.1 > 0.0)
            {
                roots.push(bisect(&g, previous, here));
            }
            previous = here;
        }
        if roots.is_empty() {
            continue;
        }
        let kernel_curve = KernelCurve::of(&curve);
        for s in roots {
            let at = curve.point(s);
            if !near_contour(model, fr, at, touch) {
                continue;
            }
            let Some(kc) = kernel_curve else {
                return Err(Refusal::Curve { at, edge: oe.edge });
            };
            out.push(Crossing {
                edge: oe.edge,
                u: s * kc.span(),
                at,
            });
        }
    }
    Ok(out)
}

/// Whether `at` lies within `touch` of one of the region's contour pieces
/// (a `Contour` chord): a sign change of f beyond its box does not.
fn near_contour(model: &Model, fr: FaceId, at: Point3, touch: f64) -> bool {
    model.faces[fr.index()]
        .loops
        .edges()
        .iter()
        .any(|oe| match &*model.edge_curve(oe.edge) {
            Curve::Contour { a, b, .. } => chord_distance(at, *a, *b) <= touch,
            _ => false,
        })
}

fn chord_distance(p: Point3, a: Point3, b: Point3) -> f64 {
    let d = b - a;
    let l2 = d.norm_squared();
    let t = if l2 > 0.0 {
        ((p - a).dot(&d) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - a - d * t).norm()
}

/// The sign change of g between the samples `lo` and `hi`, bisected until
/// the parameter's midpoint is one of its ends (the last bit).
fn bisect(g: &dyn Fn(f64) -> f64, mut lo: (f64, f64), mut hi: (f64, f64)) -> f64 {
    for _ in 0..200 {
        let s = 0.5 * (lo.0 + hi.0);
        if s <= lo.0 || s >= hi.0 {
            break;
        }
        let here = (s, g(s));
        if (here.1 > 0.0) == (lo.1 > 0.0) {
            lo = here;
        } else {
            hi = here;
        }
    }
    // The end nearer zero: f on the contour to the last bit.
    if lo.1.abs() <= hi.1.abs() { lo.0 } else { hi.0 }
}

/// Gives each crossing a vertex (the kernel vertex it falls on, a contour
/// vertex moved onto it, or a new one), then cuts the kernel edges and the
/// contour pieces there.
fn place_crossings(
    model: &mut Model,
    source_map: &mut SourceMap,
    fk: FaceId,
    fr: FaceId,
    crossings: &[Crossing],
) {
    let merge = 16.0 * model.tolerance;
    // Vertices of the kernel face (shared arcs' ends included) stay put.
    let fixed = super::region_interfaces::face_vertex_set(model, fk);
    let mut moved = BTreeSet::new();
    let mut kernel_cuts: BTreeMap<EdgeId, Vec<(f64, VertexId)>> = BTreeMap::new();
    let mut contour_cuts: Vec<VertexId> = Vec::new();
    let region_name = model.faces[fr.index()].name.to_string();
    let region_name = region_name.trim_end_matches(".region").to_string();
    for c in crossings {
        let edge = model.edge(c.edge);
        let on_end = [edge.begin, edge.end]
            .into_iter()
            .find(|&w| (model.vertex(w).position - c.at).norm() <= merge);
        if let Some(k) = on_end {
            // Seen from both edges at a kernel vertex: one cut.
            if !contour_cuts.contains(&k) {
                contour_cuts.push(k);
            }
            continue;
        }
        let Some((_, a, b)) = nearest_piece(model, fr, c.at) else {
            continue;
        };
        let (pa, pb) = (model.vertex(a).position, model.vertex(b).position);
        let reach = MOVE_FRACTION * (pb - pa).norm();
        let movable = [a, b]
            .into_iter()
            .filter(|w| !fixed.contains(w) && !moved.contains(w))
            .map(|w| (w, (model.vertex(w).position - c.at).norm()))
            .filter(|&(_, d)| d <= reach)
            .min_by(|x, y| x.1.total_cmp(&y.1));
        let v = match movable {
            Some((w, _)) => {
                model.vertices[w.index()].position = c.at;
                moved.insert(w);
                w
            }
            None => {
                let v = VertexId(model.vertices.len() as u32);
                model.vertices.push(Vertex {
                    name: format!("{region_name}.crossing{}", contour_cuts.len() + 1).into(),
                    position: c.at,
                });
                if let Some(&origin) = source_map.edges.get(&c.edge) {
                    source_map.vertices.insert(v, origin);
                }
                contour_cuts.push(v);
                v
            }
        };
        kernel_cuts.entry(c.edge).or_default().push((c.u, v));
    }
    // The pieces at a moved vertex end there.
    for oe in model.faces[fr.index()].loops.edges().to_vec() {
        let e = model.edge(oe.edge);
        if moved.contains(&e.begin) || moved.contains(&e.end) {
            follow_vertices(model, oe.edge);
        }
    }
    for (edge, mut cuts) in kernel_cuts {
        let Some(kc) = KernelCurve::of(&model.edge_curve(edge)) else {
            continue;
        };
        cuts.sort_by(|x, y| x.0.total_cmp(&y.0));
        let parts = split_kernel_edge(model, source_map, edge, &kc, &cuts);
        replace_edge(model, edge, &parts);
    }
    for v in contour_cuts {
        let at = model.vertex(v).position;
        if let Some((piece, a, b)) = nearest_piece(model, fr, at)
            && v != a
            && v != b
        {
            split_piece(model, source_map, piece, v);
        }
    }
}

/// The region's contour piece whose chord is nearest `p`, with its ends.
fn nearest_piece(model: &Model, fr: FaceId, p: Point3) -> Option<(EdgeId, VertexId, VertexId)> {
    model.faces[fr.index()]
        .loops
        .edges()
        .iter()
        .filter_map(|oe| match &*model.edge_curve(oe.edge) {
            Curve::Contour { a, b, .. } => Some((oe.edge, chord_distance(p, *a, *b))),
            _ => None,
        })
        .min_by(|x, y| x.1.total_cmp(&y.1))
        .map(|(e, _)| (e, model.edge(e).begin, model.edge(e).end))
}

/// Cuts contour piece `piece` at vertex `v`: the first part keeps its id
/// and name, the second is `PIECE.2`; every face using it walks both.
fn split_piece(model: &mut Model, source_map: &mut SourceMap, piece: EdgeId, v: VertexId) {
    let Curve::Contour { f, .. } = &*model.edge_curve(piece) else {
        return;
    };
    let f = f.clone();
    let (a, b) = (model.edge(piece).begin, model.edge(piece).end);
    let (pa, pv, pb) = (
        model.vertex(a).position,
        model.vertex(v).position,
        model.vertex(b).position,
    );
    let mut parts = EdgeParts::new(model, piece);
    let first = Curve::Contour {
        a: pa,
        b: pv,
        f: f.clone(),
    };
    let second = Curve::Contour { a: pv, b: pb, f };
    let p1 = parts.push(model, source_map, first, a, v);
    let p2 = parts.push(model, source_map, second, v, b);
    parts.finish(model);
    let forward = |edge| OrientedEdge {
        edge,
        forward: true,
    };
    replace_edge(model, piece, &[forward(p1), forward(p2)]);
}

/// Drops the kernel parts inside the region that no face uses any more, and
/// their vertices no other edge uses.
fn drop_unused(model: &mut Model, source_map: &mut SourceMap, dropped: &[EdgeId]) {
    let used: BTreeSet<EdgeId> = model
        .faces
        .iter()
        .flat_map(|f| f.loops.edges().iter().map(|oe| oe.edge))
        .collect();
    let mut keep_edge = vec![true; model.edges.len()];
    for &e in dropped {
        if !used.contains(&e) {
            keep_edge[e.index()] = false;
        }
    }
    let needed = super::prune::ends_of_kept(model, &keep_edge);
    let mut keep_vertex = vec![true; model.vertices.len()];
    for &e in dropped {
        let edge = model.edge(e);
        for v in [edge.begin, edge.end] {
            keep_vertex[v.index()] = needed[v.index()];
        }
    }
    super::prune::drop_entities(model, source_map, &keep_edge, &keep_vertex);
}
