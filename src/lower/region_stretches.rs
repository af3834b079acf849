//! Region interfaces whose runs do not pair one to one (issue 6): a later
//! region's contour may lie along the earlier one's in several runs where
//! the earlier one has one (a notch of the later region cuts the stretch in
//! two), or a run of it may lie along two regions' contours (a ring around
//! two half disks), or run along a curve where both contours leave it
//! smoothly. Each run of the later contour is replaced by the earlier
//! contour between the two corners where the later contour leaves it: each
//! corner is found on the earlier contour (its pieces' points lie on its
//! f = 0) as the point where the later region's function stops being zero,
//! by sampling and bisection, and the earlier piece there is split (or its
//! vertex taken when the corner falls on one). Both faces then use one set
//! of edges between the corners.

use super::edge_parts::EdgeParts;
use super::region_arcs::{begin, end};
use super::region_pairs::{
    ON_FRACTION, ON_SET_FRACTION, Run, extent, off_zero_set, pieces, reversed, segment_distance,
    swap_runs,
};
use crate::geom::{Curve, Point3};
use crate::implicit::tape::Ssa;
use crate::ir::{EdgeId, FaceId, Model, OrientedEdge, SourceMap, Vertex, VertexId};
use std::collections::{BTreeMap, BTreeSet};

/// Samples per piece of the earlier contour when looking for the corner.
const SAMPLES: usize = 16;
/// How many pieces of the earlier contour beyond a run's end are searched.
const SEARCH_PIECES: usize = 3;
/// Bisection steps between a sample on the later zero set and one off it:
/// 2⁻⁶⁰ of a piece, below any model tolerance.
const BISECTIONS: usize = 60;
/// How far from the later region's zero set a corner may be, as a fraction
/// of its extent, when the earlier contour's points there pass that test:
/// far below the traced vertices' own precision
/// ([`ON_SET_FRACTION`]), so a corner lands on both curves.
const CORNER_FRACTION: f64 = 1e-14;

/// A point of face A's contour: loop `lp`, piece `piece` of it, at `s`
/// along the piece in the loop's direction.
#[derive(Clone, Copy, Debug)]
struct Place {
    lp: usize,
    piece: usize,
    s: f64,
    at: Point3,
}

/// How a point is told to lie on the later region's boundary: on its f = 0
/// (a contour piece) or on a box side's segment.
enum OnLater<'a> {
    Zero(&'a Ssa),
    Side(Point3, Point3),
}

impl OnLater<'_> {
    fn holds(&self, p: Point3, tight: f64) -> bool {
        match self {
            OnLater::Zero(f) => off_zero_set(f, p, tight) <= tight,
            OnLater::Side(a, b) => segment_distance(p, *a, *b) <= tight,
        }
    }
}

/// Shares face `fb`'s runs on face `fa` (`runs_b`), splitting `fa`'s
/// contour at the corners. Returns the edges and vertices of `fb` the runs
/// replaced, or None (nothing changed) when a run has no corner on `fa`
/// within a few pieces, a closed run, or two runs map onto one stretch:
/// the touch check then reports the pair (E543).
pub(super) fn share_along(
    model: &mut Model,
    source_map: &mut SourceMap,
    fa: FaceId,
    fb: FaceId,
    runs_b: &[Run],
) -> Option<(Vec<EdgeId>, Vec<VertexId>)> {
    if runs_b.iter().any(|r| r.closed) {
        return None;
    }
    let tight = ON_SET_FRACTION * extent(model, fb);
    let near = ON_FRACTION * extent(model, fb);
    // Each run's corners on A: where it starts and where it ends.
    let mut corners: Vec<[Place; 2]> = Vec::with_capacity(runs_b.len());
    for rb in runs_b {
        let own = pieces(model, fb, rb);
        let first = begin(model, own[0]);
        let last = end(model, own[rb.len - 1]);
        // Before its start B's contour runs the way A's goes on.
        let start = corner(
            model,
            fa,
            model.vertex(first).position,
            true,
            &own[0],
            tight,
        )?;
        let stop = corner(
            model,
            fa,
            model.vertex(last).position,
            false,
            &own[rb.len - 1],
            tight,
        )?;
        // A's stretch from the end's corner forward to the start's lies
        // along the run: every A vertex inside it near one of its pieces.
        // One loop, and two distinct corners (the same one would make the
        // stretch the whole loop).
        if start.lp != stop.lp || (start.at - stop.at).norm() <= 16.0 * model.tolerance {
            return None;
        }
        let inside = stretch_vertices(model, fa, &stop, &start)?;
        // The run's chain, from the start's corner to the end's.
        let mut chain: Vec<(Point3, Point3)> = vec![(start.at, model.vertex(first).position)];
        chain.extend(own.iter().map(|&oe| {
            (
                model.vertex(begin(model, oe)).position,
                model.vertex(end(model, oe)).position,
            )
        }));
        chain.push((model.vertex(last).position, stop.at));
        if inside
            .iter()
            .any(|&p| chain.iter().all(|&(a, b)| segment_distance(p, a, b) > near))
        {
            return None;
        }
        corners.push([start, stop]);
    }
    // Every corner's piece can be cut: a contour piece or a straight side.
    for place in corners.iter().flatten() {
        let oe = model.faces[fa.index()].loops[place.lp][place.piece];
        if !matches!(
            *model.edge_curve(oe.edge),
            Curve::Contour { .. } | Curve::Segment { .. }
        ) {
            return None;
        }
    }
    let at = split_at_corners(model, source_map, fa, &corners);
    // Each run replaced by A's pieces from its end's corner to its start's,
    // reversed.
    let a_vertices = super::region_interfaces::face_vertex_set(model, fa);
    let mut used = BTreeSet::new();
    let mut canonical: BTreeMap<VertexId, VertexId> = BTreeMap::new();
    let mut dropped_edges = Vec::new();
    let mut dropped_vertices = Vec::new();
    let mut swaps: BTreeMap<usize, Vec<(usize, usize, Vec<OrientedEdge>)>> = BTreeMap::new();
    for ((rb, [start, stop]), places) in runs_b.iter().zip(&at).zip(&corners) {
        let lp = &model.faces[fa.index()].loops[places[0].lp];
        if start == stop {
            return None;
        }
        let walk = walk_forward(model, lp, *stop, *start)?;
        if walk.iter().any(|oe| !used.insert(oe.edge)) {
            return None;
        }
        let own = pieces(model, fb, rb);
        for (v, w) in [
            (begin(model, own[0]), *start),
            (end(model, own[rb.len - 1]), *stop),
        ] {
            if v != w {
                canonical.insert(v, w);
            }
        }
        for (i, oe) in own.iter().enumerate() {
            dropped_edges.push(oe.edge);
            let v = begin(model, *oe);
            if i > 0 && !a_vertices.contains(&v) {
                dropped_vertices.push(v);
            }
        }
        let replacement = reversed(&walk);
        swaps
            .entry(rb.lp)
            .or_default()
            .push((rb.start, rb.len, replacement));
    }
    dropped_vertices.extend(canonical.keys().copied());
    swap_runs(model, fb, swaps, &canonical);
    Some((dropped_edges, dropped_vertices))
}

/// The point of A's loop `lp`, piece `piece`, at `s` in the loop's direction.
fn point_at(model: &Model, fa: FaceId, lp: usize, piece: usize, s: f64) -> Point3 {
    let oe = model.faces[fa.index()].loops[lp][piece];
    let t = if oe.forward { s } else { 1.0 - s };
    model.edge_curve(oe.edge).point(t)
}

/// The place of A's contour nearest p (on a piece's chord).
fn nearest_place(model: &Model, fa: FaceId, p: Point3) -> Option<(usize, usize, f64)> {
    let mut best: Option<(f64, (usize, usize, f64))> = None;
    for (l, lp) in model.faces[fa.index()].loops.iter().enumerate() {
        for (k, &oe) in lp.iter().enumerate() {
            let (a, b) = (
                model.vertex(begin(model, oe)).position,
                model.vertex(end(model, oe)).position,
            );
            let d = b - a;
            let l2 = d.x * d.x + d.y * d.y;
            let s = if l2 > 0.0 {
                (((p.x - a.x) * d.x + (p.y - a.y) * d.y) / l2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let distance = segment_distance(p, a, b);
            if best.is_none() || best.is_some_and(|(x, _)| distance < x) {
                best = Some((distance, (l, k, s)));
            }
        }
    }
    best.map(|(_, place)| place)
}

/// Where B's contour, at its run end p (the run's end piece `piece`), leaves
/// A's: the first point of A's contour from p in the direction B's contour
/// goes on beyond the run (`forward` along A's loop) where B's function is
/// no longer zero, bisected between samples; from a start already off B's
/// zero set, the first point back on it. None when no such point is within
/// [`SEARCH_PIECES`] pieces.
fn corner(
    model: &Model,
    fa: FaceId,
    p: Point3,
    forward: bool,
    piece: &OrientedEdge,
    tight: f64,
) -> Option<Place> {
    let curve = model.edge_curve(piece.edge);
    let on_later = match &*curve {
        Curve::Contour { f, .. } => OnLater::Zero(f),
        Curve::Segment { a, b } => OnLater::Side(*a, *b),
        _ => return None,
    };
    let (l, k0, s0) = nearest_place(model, fa, p)?;
    let n = model.faces[fa.index()].loops[l].len();
    let point = |k: usize, s: f64| point_at(model, fa, l, k, s);
    let on = |k: usize, s: f64| on_later.holds(point(k, s), tight);
    let start_on = on(k0, s0);
    let dir = if start_on { forward } else { !forward };
    let mut previous = (k0, s0);
    for step in 0..SEARCH_PIECES.min(n) {
        let k = if dir {
            (k0 + step) % n
        } else {
            (k0 + n - step) % n
        };
        for i in 0..=SAMPLES {
            let u = i as f64 / SAMPLES as f64;
            let s = if dir { u } else { 1.0 - u };
            if step == 0 && (if dir { s <= s0 } else { s >= s0 }) {
                continue;
            }
            if on(k, s) == start_on {
                previous = (k, s);
                continue;
            }
            // The sample before, on this piece (its first point is the
            // previous piece's last).
            let mut same = if previous.0 == k {
                previous.1
            } else if dir {
                0.0
            } else {
                1.0
            };
            let mut other = s;
            let (same0, other0) = (same, other);
            for _ in 0..BISECTIONS {
                let mid = 0.5 * (same + other);
                if on(k, mid) == start_on {
                    same = mid;
                } else {
                    other = mid;
                }
            }
            // Closer with a strict test where the sample before passes it
            // (the earlier contour's points lie on its f = 0 to root
            // finding's precision, so on a shared stretch on B's too).
            let strict_tight = CORNER_FRACTION * tight / ON_SET_FRACTION;
            let strict = |k: usize, s: f64| on_later.holds(point(k, s), strict_tight);
            let bracket_on = if start_on { same0 } else { other0 };
            if strict(k, bracket_on) {
                let (mut inside, mut outside) = (bracket_on, if start_on { other0 } else { same0 });
                for _ in 0..BISECTIONS {
                    let mid = 0.5 * (inside + outside);
                    if strict(k, mid) {
                        inside = mid;
                    } else {
                        outside = mid;
                    }
                }
                return Some(Place {
                    lp: l,
                    piece: k,
                    s: inside,
                    at: point(k, inside),
                });
            }
            let s = if start_on { same } else { other };
            return Some(Place {
                lp: l,
                piece: k,
                s,
                at: point(k, s),
            });
        }
    }
    None
}

/// The positions of A's vertices strictly between places `from` and `to`
/// going forward along their loop; None when `to` is not after `from`
/// within the loop.
fn stretch_vertices(model: &Model, fa: FaceId, from: &Place, to: &Place) -> Option<Vec<Point3>> {
    let lp = &model.faces[fa.index()].loops[from.lp];
    let n = lp.len();
    if from.piece == to.piece && from.s < to.s {
        return Some(Vec::new());
    }
    let mut out = Vec::new();
    let mut k = from.piece;
    for _ in 0..n {
        let v = end(model, lp[k]);
        k = (k + 1) % n;
        out.push(model.vertex(v).position);
        if k == to.piece {
            return Some(out);
        }
    }
    None
}

/// Splits A's pieces at every corner (a corner within the merge distance of
/// a piece's end, or of another corner, takes that vertex) and returns each
/// run's [start, stop] vertices.
fn split_at_corners(
    model: &mut Model,
    source_map: &mut SourceMap,
    fa: FaceId,
    corners: &[[Place; 2]],
) -> Vec<[VertexId; 2]> {
    let merge = 16.0 * model.tolerance;
    // The cuts of each piece, by (loop, piece): (s, corner index).
    let mut cuts: BTreeMap<(usize, usize), Vec<(f64, usize)>> = BTreeMap::new();
    let flat: Vec<Place> = corners.iter().flatten().copied().collect();
    let mut vertex_of: Vec<Option<VertexId>> = vec![None; flat.len()];
    for (i, place) in flat.iter().enumerate() {
        let oe = model.faces[fa.index()].loops[place.lp][place.piece];
        let ends = [begin(model, oe), end(model, oe)];
        if let Some(&w) = ends
            .iter()
            .find(|&&w| (model.vertex(w).position - place.at).norm() <= merge)
        {
            vertex_of[i] = Some(w);
        } else {
            cuts.entry((place.lp, place.piece))
                .or_default()
                .push((place.s, i));
        }
    }
    // The pieces before any is cut (cutting one shifts the loop's indices).
    let cuts: Vec<(OrientedEdge, Vec<(f64, usize)>)> = cuts
        .into_iter()
        .map(|((l, k), list)| (model.faces[fa.index()].loops[l][k], list))
        .collect();
    for (oe, mut list) in cuts {
        list.sort_by(|a, b| a.0.total_cmp(&b.0));
        // New vertices along the loop's direction, close ones merged.
        let mut stops: Vec<VertexId> = Vec::new();
        let mut last: Option<Point3> = None;
        for &(_, i) in &list {
            let p = flat[i].at;
            match last {
                Some(q) if (p - q).norm() <= merge => {}
                _ => {
                    let id = VertexId(model.vertices.len() as u32);
                    if let Some(&origin) = source_map.edges.get(&oe.edge) {
                        source_map.vertices.insert(id, origin);
                    }
                    model.vertices.push(Vertex {
                        name: format!("{}.corner{}", model.edge(oe.edge).name, stops.len() + 1)
                            .into(),
                        position: p,
                    });
                    stops.push(id);
                    last = Some(p);
                }
            }
            vertex_of[i] = stops.last().copied();
        }
        split_piece(model, source_map, oe, &stops);
    }
    let ids: Vec<VertexId> = vertex_of.into_iter().flatten().collect();
    ids.chunks(2).map(|c| [c[0], c[1]]).collect()
}

/// Cuts A's piece `oe` at `stops` (in the loop's direction) into parts on
/// the same curve; every face using it walks the parts.
fn split_piece(
    model: &mut Model,
    source_map: &mut SourceMap,
    oe: OrientedEdge,
    stops: &[VertexId],
) {
    let e = oe.edge;
    let (first, last) = (model.edge(e).begin, model.edge(e).end);
    let mut chain = vec![first];
    if oe.forward {
        chain.extend(stops.iter().copied());
    } else {
        chain.extend(stops.iter().rev().copied());
    }
    chain.push(last);
    let curve = model.edge_curve(e).into_owned();
    let mut parts = EdgeParts::new(model, e);
    let mut out = Vec::with_capacity(chain.len() - 1);
    for w in chain.windows(2) {
        let (a, b) = (model.vertex(w[0]).position, model.vertex(w[1]).position);
        let part = match &curve {
            Curve::Contour { f, .. } => Curve::Contour { a, b, f: f.clone() },
            _ => Curve::Segment { a, b },
        };
        out.push(OrientedEdge {
            edge: parts.push(model, source_map, part, w[0], w[1]),
            forward: true,
        });
    }
    parts.finish(model);
    super::region_interfaces::replace_edge(model, e, &out);
}

/// A's pieces of loop `lp` from vertex `from` forward to vertex `to`.
fn walk_forward(
    model: &Model,
    lp: &[OrientedEdge],
    from: VertexId,
    to: VertexId,
) -> Option<Vec<OrientedEdge>> {
    let n = lp.len();
    let start = lp.iter().position(|&oe| begin(model, oe) == from)?;
    let mut out = Vec::new();
    for i in 0..n {
        let oe = lp[(start + i) % n];
        out.push(oe);
        if end(model, oe) == to {
            return Some(out);
        }
    }
    None
}
