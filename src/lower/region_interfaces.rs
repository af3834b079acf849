//! Interfaces of 2D R-function regions with kernel regions (issue 6). A
//! region's contour is its own polyline, not a kernel curve, so it can share
//! edges with a kernel region in two ways, both conforming (one model edge
//! used by both faces, so the mesh shares its nodes and the edges form the
//! fragment `KERNEL|REGION`):
//!
//! - **carving**: a kernel subdomain's `<difference>` subtracts the
//!   R-function solid of a region subdomain lying strictly inside it; the
//!   region's contour loops become holes of the kernel face (an inclusion);
//!   a carved region whose contour crosses kernel edges is split at the
//!   crossings instead (`region_crossing`);
//! - **a box side on a straight kernel edge**: contour pieces along a side of
//!   the region's box that lie on a straight kernel edge replace that part of
//!   the edge, which is split around them;
//! - **a contour run on a kernel curve** (`region_arcs`): a run of contour
//!   pieces on a kernel arc or straight edge is replaced by that edge, split
//!   at the run's ends.
//!
//! Anything else that touches is E543 (the interface would have hanging
//! nodes) and an overlap is E407, as for kernel subdomains.

use super::edge_parts::EdgeParts;
use crate::diag::{Code, Diagnostic, Diagnostics};
use crate::geom::{Curve, Point3};
use crate::implicit::xml::Carve;
use crate::ir::{
    EdgeId, FaceId, Loops, Model, OrientedEdge, SourceMap, SubdomainCells, SubdomainId, VertexId,
};
use std::collections::{BTreeMap, BTreeSet};

/// The touch distance, as a fraction of a region's extent: the contour's
/// chordal tolerance (`rfunction_region`'s 0.5e-3 of its box diagonal).
const TOUCH_FRACTION: f64 = 0.5e-3;

/// Joins the R-function regions (subdomains `first_region..`) to the kernel
/// regions before them: carves, shares box sides lying on straight kernel
/// edges, then reports what still touches (E543) or overlaps (E407).
/// `region_of` maps an implicit solid to the subdomain whose whole solid it is.
pub fn join(
    model: &mut Model,
    source_map: &mut SourceMap,
    first_region: usize,
    carves: &[Carve],
    region_of: &[(String, String)],
    diags: &mut Diagnostics,
) {
    super::region_collinear::split_at_joints(model, source_map, first_region);
    // Pairs a refused carve or arc run reported already.
    let mut reported = super::region_arcs::share_arcs(model, source_map, first_region, diags);
    for c in carves {
        if let Some(pair) = carve(model, source_map, first_region, c, region_of, diags) {
            reported.insert(pair);
        }
    }
    for r in first_region..model.subdomains.len() {
        share_box_sides(model, source_map, first_region, r, diags);
    }
    super::region_pairs::share_region_interfaces(model, source_map, first_region);
    let touch_of = |m: &Model, r: usize| face_of(m, r).map_or(0.0, |f| touch_distance(m, f));
    let touched = super::region_touch::share_touch_points(
        model,
        source_map,
        first_region,
        touch_of,
        &reported,
    );
    let touched = super::region_corner_touch::share_corner_touches(
        model,
        source_map,
        first_region,
        touch_of,
        &reported,
        touched,
    );
    check(model, source_map, first_region, &reported, &touched, diags);
}

/// The edges of the faces of subdomains `subdomains` (2D: one face each).
pub(super) fn face_edges(
    model: &Model,
    subdomains: std::ops::Range<usize>,
) -> impl Iterator<Item = EdgeId> + '_ {
    subdomains.filter_map(|k| face_of(model, k)).flat_map(|f| {
        model.faces[f.index()]
            .loops
            .edges()
            .iter()
            .map(|oe| oe.edge)
    })
}

/// The one face of a 2D subdomain.
pub(super) fn face_of(model: &Model, k: usize) -> Option<FaceId> {
    match &model.subdomains[k].cells {
        SubdomainCells::Region { faces } if faces.len() == 1 => Some(faces[0]),
        _ => None,
    }
}

fn carve(
    model: &mut Model,
    source_map: &mut SourceMap,
    first_region: usize,
    c: &Carve,
    region_of: &[(String, String)],
    diags: &mut Diagnostics,
) -> Option<(usize, usize)> {
    // A kernel subdomain that failed to lower was reported already.
    let k = (0..first_region).find(|&k| model.subdomains[k].name == c.subdomain)?;
    let Some((_, region)) = region_of.iter().find(|(solid, _)| *solid == c.solid) else {
        diags.push(
            Diagnostic::new(
                Code::RegionCarveNotSubdomain,
                c.span,
                format!(
                    "subdomain '{}' subtracts the R-function solid '{}', which is no subdomain's whole solid",
                    c.subdomain, c.solid
                ),
            )
            .with_help(format!(
                "add <subdomain name=\"…\"><solid ref=\"{}\"/></subdomain> (an inclusion), or subtract a kernel solid",
                c.solid
            )),
        );
        return None;
    };
    // A region that failed to trace was reported already.
    let r =
        (first_region..model.subdomains.len()).find(|&r| model.subdomains[r].name == *region)?;
    let (fk, fr) = (face_of(model, k)?, face_of(model, r)?);
    let outline = Outline::of(model, fk);
    let touch = touch_distance(model, fr);
    // Arcs the region runs along (`region_arcs`) are in both faces already.
    let shared: BTreeSet<EdgeId> = face_edges(model, k..k + 1)
        .filter(|e| face_edges(model, r..r + 1).any(|x| x == *e))
        .collect();
    let on_shared: BTreeSet<VertexId> = shared
        .iter()
        .flat_map(|&e| [model.edge(e).begin, model.edge(e).end])
        .collect();
    let points: Vec<Point3> = loop_vertices(model, fr)
        .into_iter()
        .filter(|v| !on_shared.contains(v))
        .map(|v| model.vertex(v).position)
        .collect();
    if let Some(near) = crossing(&outline, &points, touch) {
        let region_edges: BTreeSet<EdgeId> =
            face_edges(model, first_region..model.subdomains.len()).collect();
        let split = super::region_crossing::split_at_crossings(
            model,
            source_map,
            (fk, fr),
            &region_edges,
            touch,
            near,
        );
        return match split {
            Ok(()) => None,
            Err(refusal) => {
                diags.push(refusal.diagnostic(model, c.span, &c.subdomain, region));
                Some((k, r))
            }
        };
    }
    // Clear of the outline and outside it: the region lies outside.
    let beyond = points
        .iter()
        .find(|p| outline.distance(p) > touch && !outline.contains(p));
    let near = points.iter().find(|p| outline.distance(p) <= touch);
    if let (None, Some(_), true) = (beyond, near, shared.is_empty()) {
        // Inside, touching the outline: shared where it is a tangency.
        let region_edges: BTreeSet<EdgeId> =
            face_edges(model, first_region..model.subdomains.len()).collect();
        let touched = super::region_touch_inside::share_inside_touches(
            model,
            source_map,
            (fk, fr),
            &region_edges,
            touch,
        );
        if let Err(refusal) = touched {
            diags.push(refusal.diagnostic(model, c.span, &c.subdomain, region));
            return Some((k, r));
        }
    } else if let Some(p) = points
        .iter()
        .find(|p| outline.distance(p) <= touch || !outline.contains(p))
    {
        diags.push(
            Diagnostic::new(
                Code::RegionCarveOutside,
                c.span,
                format!(
                    "subdomain '{}' subtracts region '{}', but the region is not strictly inside it: its contour reaches ({:.6}, {:.6})",
                    c.subdomain, region, p.x, p.y
                ),
            )
            .with_help("make the region lie inside the kernel region, clear of its boundary, or make them neighbours without <difference>"),
        );
        return Some((k, r));
    }
    if !shared.is_empty() {
        return match rejoin(model, fk, fr, &shared) {
            Ok(loops) => {
                model.faces[fk.index()].loops = Loops::from(loops);
                None
            }
            Err(p) => {
                diags.push(
                    Diagnostic::new(
                        Code::RegionTouches,
                        c.span,
                        format!(
                            "subdomain '{}' subtracts region '{}', whose contour leaves the curved edge it runs along and meets the boundary again at ({:.6}, {:.6}): the remaining boundary is no set of simple loops",
                            c.subdomain, region, p.x, p.y
                        ),
                    )
                    .with_help("let the region touch the kernel boundary along one stretch of each edge, or move it clear of the boundary"),
                );
                Some((k, r))
            }
        };
    }
    let holes: Vec<Vec<OrientedEdge>> = model.faces[fr.index()]
        .loops
        .iter()
        .map(|l| {
            l.iter()
                .rev()
                .map(|oe| OrientedEdge {
                    edge: oe.edge,
                    forward: !oe.forward,
                })
                .collect()
        })
        .collect();
    model.faces[fk.index()].loops.extend(holes);
    None
}

/// Where a region's contour (`points`) crosses a kernel outline: some of
/// its points lie clearly inside, some clearly outside. Returns the contour
/// point nearest the outline and the kernel edge there.
fn crossing(outline: &Outline, points: &[Point3], touch: f64) -> Option<(Point3, EdgeId)> {
    let clear = |p: &&Point3| outline.distance(p) > touch;
    let inside = points.iter().filter(clear).any(|p| outline.contains(p));
    let outside = points.iter().filter(clear).any(|p| !outline.contains(p));
    if !(inside && outside) {
        return None;
    }
    let p = *points
        .iter()
        .min_by(|a, b| outline.distance(a).total_cmp(&outline.distance(b)))?;
    let edge = outline
        .segments
        .iter()
        .min_by(|a, b| {
            let d = |s: &([f64; 2], [f64; 2], EdgeId)| segment_distance([p.x, p.y], s.0, s.1);
            d(a).total_cmp(&d(b))
        })?
        .2;
    Some((p, edge))
}

/// The loops of kernel face `fk` less region face `fr`, which lies inside
/// it and shares the `shared` edges of its boundary: the kernel's edges but
/// the shared ones, and the region's others reversed, chained end to start.
/// Err(point) where the chaining is ambiguous (the boundaries touch at a
/// point as well) or does not close.
fn rejoin(
    model: &Model,
    fk: FaceId,
    fr: FaceId,
    shared: &BTreeSet<EdgeId>,
) -> Result<Vec<Vec<OrientedEdge>>, Point3> {
    let faces = &model.faces;
    let region_forward: BTreeMap<EdgeId, bool> = faces[fr.index()]
        .loops
        .edges()
        .iter()
        .map(|oe| (oe.edge, oe.forward))
        .collect();
    // A shared edge the region runs the same way (inside the kernel face
    // there) leaves the kernel face; one run the other way is a neighbour's.
    let mut pool: Vec<OrientedEdge> = faces[fk.index()]
        .loops
        .edges()
        .iter()
        .filter(|oe| region_forward.get(&oe.edge) != Some(&oe.forward))
        .copied()
        .collect();
    pool.extend(
        faces[fr.index()]
            .loops
            .edges()
            .iter()
            .filter(|oe| !shared.contains(&oe.edge))
            .map(|oe| OrientedEdge {
                edge: oe.edge,
                forward: !oe.forward,
            }),
    );
    chain(model, &pool)
}

/// Chains oriented edges end to start into closed loops. Err(point) where
/// two edges leave one vertex (the boundaries touch at a point as well) or a
/// chain does not close.
pub(super) fn chain(
    model: &Model,
    pool: &[OrientedEdge],
) -> Result<Vec<Vec<OrientedEdge>>, Point3> {
    let start_of = |oe: &OrientedEdge| {
        let e = model.edge(oe.edge);
        if oe.forward { e.begin } else { e.end }
    };
    let end_of = |oe: &OrientedEdge| {
        let e = model.edge(oe.edge);
        if oe.forward { e.end } else { e.begin }
    };
    let mut leaving: BTreeMap<VertexId, Vec<usize>> = BTreeMap::new();
    for (i, oe) in pool.iter().enumerate() {
        leaving.entry(start_of(oe)).or_default().push(i);
    }
    if let Some((v, _)) = leaving.iter().find(|(_, out)| out.len() > 1) {
        return Err(model.vertex(*v).position);
    }
    let mut used = vec![false; pool.len()];
    let mut loops = Vec::new();
    for first in 0..pool.len() {
        if used[first] {
            continue;
        }
        let mut lp = Vec::new();
        let mut at = first;
        loop {
            used[at] = true;
            lp.push(pool[at]);
            let v = end_of(&pool[at]);
            if v == start_of(&pool[first]) {
                break;
            }
            match leaving.get(&v).and_then(|out| out.first()) {
                Some(&next) if !used[next] => at = next,
                _ => return Err(model.vertex(v).position),
            }
        }
        loops.push(lp);
    }
    Ok(loops)
}

/// Straight contour pieces of region `r` (its box sides) lying on a straight
/// kernel edge become part of that edge: the kernel edge is cut into the
/// pieces between them, and every face using it walks the whole chain.
fn share_box_sides(
    model: &mut Model,
    source_map: &mut SourceMap,
    first_region: usize,
    r: usize,
    diags: &mut Diagnostics,
) {
    let Some(fr) = face_of(model, r) else {
        return;
    };
    let sides: Vec<EdgeId> = model.faces[fr.index()]
        .loops
        .iter()
        .flatten()
        .map(|oe| oe.edge)
        .filter(|&e| matches!(*model.edge_curve(e), Curve::Segment { .. }))
        .collect();
    if sides.is_empty() {
        return;
    }
    // Carved regions' contours are in kernel faces too: not kernel edges.
    let region_edges: BTreeSet<EdgeId> =
        face_edges(model, first_region..model.subdomains.len()).collect();
    let kernel_edges: BTreeSet<EdgeId> = face_edges(model, 0..first_region)
        .filter(|e| !region_edges.contains(e))
        .filter(|&e| matches!(*model.edge_curve(e), Curve::Segment { .. }))
        .collect();
    let tol = 16.0 * model.tolerance;
    for ke in kernel_edges {
        let (a, b) = ends(model, ke);
        let d = b - a;
        let length2 = d.norm_squared();
        if length2 <= tol * tol {
            continue;
        }
        let at = |p: Point3| (p - a).dot(&d) / length2;
        let off = |p: Point3| (p - a - d * at(p)).norm();
        // (from, to, edge, runs a → b) along the kernel edge.
        let mut on: Vec<(f64, f64, EdgeId, bool)> = sides
            .iter()
            .filter_map(|&e| {
                let (p, q) = ends(model, e);
                let inside = |p: Point3| off(p) <= tol && (-1e-9..=1.0 + 1e-9).contains(&at(p));
                (inside(p) && inside(q)).then(|| {
                    let (s, t) = (at(p), at(q));
                    (s.min(t), s.max(t), e, s < t)
                })
            })
            .collect();
        if on.is_empty() {
            continue;
        }
        on.sort_by(|x, y| x.0.total_cmp(&y.0));
        let eps = tol / length2.sqrt();
        let mut chain = Vec::with_capacity(2 * on.len() + 1);
        let mut cur = model.edge(ke).begin;
        let mut last = 0.0;
        let mut failed = None;
        for &(from, to, e, forward) in &on {
            let edge = model.edge(e);
            let (start, end) = if forward {
                (edge.begin, edge.end)
            } else {
                (edge.end, edge.begin)
            };
            if from > last + eps {
                chain.push(Piece::Gap(cur, start));
            } else if start != cur {
                // The piece starts on a kernel vertex or where another ends:
                // two vertices at one point.
                failed = Some(model.vertex(start).position);
                break;
            }
            chain.push(Piece::Shared(OrientedEdge { edge: e, forward }));
            cur = end;
            last = to;
        }
        let end_vertex = model.edge(ke).end;
        if failed.is_none() {
            if last < 1.0 - eps {
                chain.push(Piece::Gap(cur, end_vertex));
            } else {
                failed = Some(model.vertex(cur).position);
            }
        }
        if let Some(p) = failed {
            let span = source_map.subdomain(SubdomainId(r as u32));
            diags.push(
                Diagnostic::new(
                    Code::RegionTouches,
                    span,
                    format!(
                        "region '{}' runs along edge '{}' up to its end or to another piece at ({:.6}, {:.6}); only a box side strictly inside a straight kernel edge becomes an interface",
                        model.subdomains[r].name, model.edge(ke).name, p.x, p.y
                    ),
                )
                .with_help("move the region's box side so that it ends inside the kernel edge"),
            );
            continue;
        }
        let replacement = split_edge(model, source_map, ke, &chain);
        replace_edge(model, ke, &replacement);
    }
}

/// Every face using edge `ke` walks `replacement` (in `ke`'s direction)
/// instead.
pub(super) fn replace_edge(model: &mut Model, ke: EdgeId, replacement: &[OrientedEdge]) {
    for face in &mut model.faces {
        if !face.loops.edges().iter().any(|oe| oe.edge == ke) {
            continue;
        }
        let mut loops = face.loops.to_vecs();
        for lp in &mut loops {
            if !lp.iter().any(|oe| oe.edge == ke) {
                continue;
            }
            let mut out = Vec::with_capacity(lp.len() + replacement.len());
            for oe in lp.iter() {
                if oe.edge != ke {
                    out.push(*oe);
                } else if oe.forward {
                    out.extend(replacement.iter().copied());
                } else {
                    out.extend(replacement.iter().rev().map(|p| OrientedEdge {
                        edge: p.edge,
                        forward: !p.forward,
                    }));
                }
            }
            *lp = out;
        }
        face.loops = Loops::from(loops);
    }
}

/// A part of a kernel edge after the split: a straight gap between two
/// vertices, or a region's contour piece.
enum Piece {
    Gap(VertexId, VertexId),
    Shared(OrientedEdge),
}

/// Makes the gaps of `chain` edges (the first keeps the kernel edge's id,
/// name and boundaries; the others are `NAME.2`, `NAME.3`, … in the same
/// boundaries) and returns the chain in the edge's direction.
fn split_edge(
    model: &mut Model,
    source_map: &mut SourceMap,
    ke: EdgeId,
    chain: &[Piece],
) -> Vec<OrientedEdge> {
    let mut parts = EdgeParts::new(model, ke);
    let mut out = Vec::with_capacity(chain.len());
    for piece in chain {
        match *piece {
            Piece::Shared(oe) => out.push(oe),
            Piece::Gap(from, to) => {
                let curve = Curve::Segment {
                    a: model.vertex(from).position,
                    b: model.vertex(to).position,
                };
                out.push(OrientedEdge {
                    edge: parts.push(model, source_map, curve, from, to),
                    forward: true,
                });
            }
        }
    }
    parts.finish(model);
    out
}

fn ends(model: &Model, e: EdgeId) -> (Point3, Point3) {
    let edge = model.edge(e);
    (
        model.vertex(edge.begin).position,
        model.vertex(edge.end).position,
    )
}

/// The vertices of a face's loops, each once, in loop order.
fn loop_vertices(model: &Model, f: FaceId) -> Vec<VertexId> {
    let mut seen = BTreeSet::new();
    model.faces[f.index()]
        .loops
        .iter()
        .flatten()
        .flat_map(|oe| {
            let e = model.edge(oe.edge);
            [e.begin, e.end]
        })
        .filter(|v| seen.insert(*v))
        .collect()
}

/// The vertices of a face's loops as a set (lookups, not order).
pub(super) fn face_vertex_set(model: &Model, f: FaceId) -> BTreeSet<VertexId> {
    loop_vertices(model, f).into_iter().collect()
}

/// [`TOUCH_FRACTION`] of the diagonal of a region's contour.
pub(super) fn touch_distance(model: &Model, f: FaceId) -> f64 {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for v in loop_vertices(model, f) {
        let p = model.vertex(v).position;
        lo = [lo[0].min(p.x), lo[1].min(p.y)];
        hi = [hi[0].max(p.x), hi[1].max(p.y)];
    }
    TOUCH_FRACTION * (hi[0] - lo[0]).hypot(hi[1] - lo[1])
}

/// A face's boundary as straight pieces (curved edges sampled finely), each
/// with its edge.
pub(super) struct Outline {
    segments: Vec<([f64; 2], [f64; 2], EdgeId)>,
    lo: [f64; 2],
    hi: [f64; 2],
}

impl Outline {
    pub(super) fn of(model: &Model, f: FaceId) -> Outline {
        let mut segments = Vec::new();
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for oe in model.faces[f.index()].loops.iter().flatten() {
            let curve = model.edge_curve(oe.edge);
            let n = match *curve {
                Curve::Segment { .. } | Curve::Contour { .. } => 1,
                _ => 256,
            };
            let points = curve.samples(n);
            for w in points.windows(2) {
                let (a, b) = ([w[0].x, w[0].y], [w[1].x, w[1].y]);
                for p in [a, b] {
                    lo = [lo[0].min(p[0]), lo[1].min(p[1])];
                    hi = [hi[0].max(p[0]), hi[1].max(p[1])];
                }
                segments.push((a, b, oe.edge));
            }
        }
        Outline { segments, lo, hi }
    }

    /// Whether the boxes of two outlines come within `gap` of each other.
    fn near(&self, other: &Outline, gap: f64) -> bool {
        (0..2).all(|i| self.lo[i] <= other.hi[i] + gap && other.lo[i] <= self.hi[i] + gap)
    }

    pub(super) fn distance(&self, p: &Point3) -> f64 {
        self.segments
            .iter()
            .map(|(a, b, _)| segment_distance([p.x, p.y], *a, *b))
            .fold(f64::INFINITY, f64::min)
    }

    /// The edge of the outline's piece nearest p.
    pub(super) fn nearest_edge(&self, p: &Point3) -> Option<EdgeId> {
        self.segments
            .iter()
            .min_by(|a, b| {
                let d = |s: &([f64; 2], [f64; 2], EdgeId)| segment_distance([p.x, p.y], s.0, s.1);
                d(a).total_cmp(&d(b))
            })
            .map(|s| s.2)
    }

    /// Even–odd: inside the outer loop and outside the holes.
    pub(super) fn contains(&self, p: &Point3) -> bool {
        let mut inside = false;
        for (a, b, _) in &self.segments {
            if (a[1] > p.y) != (b[1] > p.y) {
                let x = a[0] + (p.y - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
                if p.x < x {
                    inside = !inside;
                }
            }
        }
        inside
    }

    /// Sample points of the outline, except on the `skip` edges.
    fn points_off<'a>(&'a self, skip: &'a BTreeSet<EdgeId>) -> impl Iterator<Item = Point3> + 'a {
        self.segments
            .iter()
            .filter(|(_, _, e)| !skip.contains(e))
            .flat_map(|(a, b, _)| {
                let m = [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0];
                [*a, m]
            })
            .map(|p| Point3::new(p[0], p[1], 0.0))
    }
}

fn segment_distance(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let d = [b[0] - a[0], b[1] - a[1]];
    let l2 = d[0] * d[0] + d[1] * d[1];
    let t = if l2 > 0.0 {
        (((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1]) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p[0] - a[0] - t * d[0]).hypot(p[1] - a[1] - t * d[1])
}

/// Reports each region that touches a kernel region or another region
/// outside their shared edges (E543), or overlaps a kernel region (E407;
/// regions among themselves are checked by the implicit overlap check).
fn check(
    model: &Model,
    source_map: &SourceMap,
    first_region: usize,
    reported: &BTreeSet<(usize, usize)>,
    touched: &BTreeSet<VertexId>,
    diags: &mut Diagnostics,
) {
    let n = model.subdomains.len();
    let faces: Vec<Option<FaceId>> = (0..n).map(|k| face_of(model, k)).collect();
    let outlines: BTreeMap<usize, Outline> = (0..n)
        .filter_map(|k| faces[k].map(|f| (k, Outline::of(model, f))))
        .collect();
    for (r, &face) in faces.iter().enumerate().skip(first_region) {
        let (Some(fr), Some(or)) = (face, outlines.get(&r)) else {
            continue;
        };
        let touch = touch_distance(model, fr);
        let region_edges: BTreeSet<EdgeId> = or.segments.iter().map(|s| s.2).collect();
        for k in 0..n {
            if k == r {
                continue;
            }
            let Some(ok) = outlines.get(&k).filter(|o| o.near(or, touch)) else {
                continue;
            };
            // Regions meet regions once, from the first.
            if (k >= first_region && k < r) || reported.contains(&(k, r)) {
                continue;
            }
            let shared: BTreeSet<EdgeId> = ok
                .segments
                .iter()
                .map(|s| s.2)
                .filter(|e| region_edges.contains(e))
                .collect();
            // Touch points (`region_touch`) are shared vertices too.
            let exempt: BTreeSet<VertexId> = shared
                .iter()
                .flat_map(|&e| [model.edge(e).begin, model.edge(e).end])
                .chain(touched.iter().copied())
                .collect();
            // A shared edge both faces run the same way has both on one side:
            // they overlap there (a region along a kernel rim, uncarved).
            let forward_in = |f: Option<FaceId>, e: EdgeId| {
                f.and_then(|f| {
                    model.faces[f.index()]
                        .loops
                        .edges()
                        .iter()
                        .find(|oe| oe.edge == e)
                        .map(|oe| oe.forward)
                })
            };
            let same_side = shared
                .iter()
                .find(|&&e| forward_in(face_of(model, k), e) == forward_in(Some(fr), e))
                .map(|&e| (Code::SubdomainsOverlap, model.edge_curve(e).point(0.5)));
            let finding = same_side.or_else(|| {
                loop_vertices(model, fr)
                    .into_iter()
                    .filter(|v| !exempt.contains(v))
                    .map(|v| model.vertex(v).position)
                    .find_map(|p| {
                        if ok.distance(&p) <= touch {
                            Some((Code::RegionTouches, p))
                        } else if k < first_region && ok.contains(&p) {
                            Some((Code::SubdomainsOverlap, p))
                        } else {
                            None
                        }
                    })
                    .or_else(|| {
                        let far = |p: &Point3| or.distance(p) > touch;
                        // The other's pieces leaving a shared end start on it.
                        let at_shared_end = |p: &Point3| {
                            exempt
                                .iter()
                                .any(|&v| (model.vertex(v).position - p).norm() <= touch)
                        };
                        ok.points_off(&shared)
                            .filter(|p| !at_shared_end(p))
                            .find_map(|p| {
                                if !far(&p) {
                                    (k >= first_region).then_some((Code::RegionTouches, p))
                                } else if k < first_region && or.contains(&p) {
                                    Some((Code::SubdomainsOverlap, p))
                                } else {
                                    None
                                }
                            })
                    })
            });
            if let Some((code, p)) = finding {
                report(
                    model,
                    source_map,
                    code,
                    (k, r),
                    (p, ok),
                    first_region,
                    diags,
                );
            }
        }
    }
}

fn report(
    model: &Model,
    source_map: &SourceMap,
    code: Code,
    (k, r): (usize, usize),
    (p, outline): (Point3, &Outline),
    first_region: usize,
    diags: &mut Diagnostics,
) {
    let (kernel, region) = (&model.subdomains[k].name, &model.subdomains[r].name);
    let span = source_map.subdomain(SubdomainId(r as u32));
    let at = format!("({:.6}, {:.6})", p.x, p.y);
    let d = if code == Code::SubdomainsOverlap {
        Diagnostic::new(
            code,
            span,
            format!("region '{region}' and subdomain '{kernel}' overlap at {at}"),
        )
        .with_help(format!(
            "carve one out of the other: <subdomain name=\"{kernel}\"><difference> … <solid ref=\"…\"/></difference></subdomain> subtracting the region's solid"
        ))
    } else if k >= first_region {
        Diagnostic::new(
            code,
            span,
            format!(
                "region '{region}' touches region '{kernel}' at {at} outside a shared stretch: two R-function regions share edges only where both contours run along one zero set"
            ),
        )
        .with_help("move them apart, or let them meet along a stretch of one curve (e.g. one R-function holds x - c, the other c - x)")
    } else {
        // The kernel edge nearest the contact says which rule was missed.
        let nearest = outline
            .segments
            .iter()
            .min_by(|a, b| {
                let d = |s: &([f64; 2], [f64; 2], EdgeId)| segment_distance([p.x, p.y], s.0, s.1);
                d(a).total_cmp(&d(b))
            })
            .map(|s| s.2);
        match nearest.map(|e| (model.edge(e), matches!(*model.edge_curve(e), Curve::Ellipse { .. }))) {
            Some((edge, true)) => Diagnostic::new(
                code,
                span,
                format!(
                    "region '{region}' touches the curved edge '{}' of subdomain '{kernel}' at {at} without running along it: a contour shares a curved edge only where its points lie on that curve",
                    edge.name
                ),
            )
            .with_help("let the region's R-function contain the same circle or ellipse as the kernel edge, so its contour lies on it, or move the region clear of the edge"),
            Some((edge, false)) => Diagnostic::new(
                code,
                span,
                format!(
                    "region '{region}' touches the edge '{}' of subdomain '{kernel}' at {at}, where their boundaries cannot share nodes: a region shares a straight edge only along a side of its box or where its contour runs along that edge",
                    edge.name
                ),
            )
            .with_help("move them apart, carve the region out of a kernel subdomain with <difference>, or let the region's R-function contain the kernel edge's half-plane (or a side of its box lie on the edge)"),
            None => return,
        }
    };
    diags.push(d);
}
