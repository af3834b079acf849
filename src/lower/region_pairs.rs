//! Two R-function regions sharing an interface (issue 6): each region's
//! contour is traced on its own grid, so along their common boundary the two
//! contours are two polylines on the same zero set with different points.
//! Where a run of the later region's contour pieces lies on the earlier
//! region's contour (every vertex and piece middle within the touch
//! distance) and that region has one matching run back, the later region's
//! run is replaced by the earlier one's pieces, reversed: both faces then use
//! one set of edges (shared nodes, one fragment `A|B`), and splits by the
//! mesher land on the earlier region's f = 0. The later run's ends become the
//! earlier run's ends; where the interface is straight, both contours' cut
//! corners are restored first (the parabola through the next contour points
//! beyond each end, extended, meets the interface line), so the shared end is
//! the true corner, and the later region's neighbouring pieces follow it.
//! Anything else (a tangent contact, runs that do not pair up one to one) is
//! left to the touch check: E543.

use super::region_arcs::{begin, end};
use crate::geom::{Curve, Point3};
use crate::ir::{EdgeId, FaceId, Model, OrientedEdge, SourceMap, VertexId};
use std::collections::{BTreeMap, BTreeSet};

/// How far a contour point may be from the other contour to be on it, as a
/// fraction of the region's extent: the contours' chordal tolerance (0.5e-3
/// of the box diagonal), the same as the touch distance of
/// `region_interfaces`, so anything closer is either shared or a touch.
pub(super) const ON_FRACTION: f64 = 0.5e-3;

/// A run of pieces of loop `lp` of a face: `len` pieces from `start`
/// (cyclically), or the whole loop when `closed`.
#[derive(Clone, Copy, Debug)]
pub(super) struct Run {
    pub(super) lp: usize,
    pub(super) start: usize,
    pub(super) len: usize,
    pub(super) closed: bool,
}

/// Shares the interfaces of every pair of regions (subdomains
/// `first_region..`). Pairs whose runs do not pair up one to one are left
/// as they are, for the touch check to report (E543).
pub(super) fn share_region_interfaces(
    model: &mut Model,
    source_map: &mut SourceMap,
    first_region: usize,
) {
    let n = model.subdomains.len();
    let mut dropped_edges = BTreeSet::new();
    let mut dropped_vertices = BTreeSet::new();
    for ra in first_region..n {
        for rb in ra + 1..n {
            let (Some(fa), Some(fb)) = (
                super::region_interfaces::face_of(model, ra),
                super::region_interfaces::face_of(model, rb),
            ) else {
                continue;
            };
            if let Some((edges, vertices)) = share_pair(model, source_map, fa, fb) {
                dropped_edges.extend(edges);
                dropped_vertices.extend(vertices);
            }
        }
    }
    if dropped_edges.is_empty() {
        return;
    }
    let keep_edge: Vec<bool> = (0..model.edges.len())
        .map(|e| !dropped_edges.contains(&EdgeId(e as u32)))
        .collect();
    let keep_vertex: Vec<bool> = (0..model.vertices.len())
        .map(|v| !dropped_vertices.contains(&VertexId(v as u32)))
        .collect();
    super::prune::drop_entities(model, source_map, &keep_edge, &keep_vertex);
}

/// The edges and vertices of face `fb` that its shared runs replaced, or
/// None when the two faces share nothing or their runs do not pair up.
type Shared = Option<(Vec<EdgeId>, Vec<VertexId>)>;

fn share_pair(model: &mut Model, source_map: &mut SourceMap, fa: FaceId, fb: FaceId) -> Shared {
    let tol_a = ON_FRACTION * extent(model, fa);
    let tol_b = ON_FRACTION * extent(model, fb);
    let runs_b = runs_on(model, fb, fa, tol_a);
    if runs_b.is_empty() {
        return None;
    }
    let runs_a = runs_on(model, fa, fb, tol_b);
    match one_to_one(model, fa, fb, &runs_a, &runs_b) {
        Some(pairs) => Some(share_pairs(model, fa, fb, pairs)),
        // Runs broken differently on the two contours: the earlier one is
        // split where the later one leaves it.
        None => super::region_stretches::share_along(model, source_map, fa, fb, &runs_b),
    }
}

/// Each later run with the earlier run whose ends are nearest its ends
/// (the earlier run goes the other way), when the runs pair up one to one:
/// as many on each side, closed with closed, and open ones straight on both
/// contours, ending at the same corners once those are restored. Curved
/// open runs and anything else go to `region_stretches`.
fn one_to_one(
    model: &Model,
    fa: FaceId,
    fb: FaceId,
    runs_a: &[Run],
    runs_b: &[Run],
) -> Option<Vec<(Run, Run)>> {
    if runs_a.len() != runs_b.len() {
        return None;
    }
    let mut pairs = Vec::with_capacity(runs_b.len());
    let mut used = vec![false; runs_a.len()];
    for rb in runs_b {
        if rb.closed {
            let k = (0..runs_a.len()).find(|&k| runs_a[k].closed && !used[k])?;
            used[k] = true;
            pairs.push((runs_a[k], *rb));
            continue;
        }
        let (sb, eb) = run_end_points(model, fb, rb);
        let best = (0..runs_a.len())
            .filter(|&k| !used[k] && !runs_a[k].closed)
            .min_by(|&i, &j| {
                let d = |k: usize| {
                    let (sa, ea) = run_end_points(model, fa, &runs_a[k]);
                    (ea - sb).norm() + (sa - eb).norm()
                };
                d(i).total_cmp(&d(j))
            });
        let k = best?;
        used[k] = true;
        pairs.push((runs_a[k], *rb));
    }
    let agree = |(ra, rb): &(Run, Run)| {
        let (Some(a), Some(b)) = (
            planned_corners(model, fa, ra),
            planned_corners(model, fb, rb),
        ) else {
            return false;
        };
        let ((sa, ea), (sb, eb)) = (a.ends(model, fa), b.ends(model, fb));
        let reach = 2.0 * a.end_piece(model, fa).max(b.end_piece(model, fb));
        (ea - sb).norm() <= reach && (sa - eb).norm() <= reach
    };
    pairs
        .iter()
        .all(|p| (p.0.closed && p.1.closed) || agree(p))
        .then_some(pairs)
}

/// Replaces each later run by its earlier partner's pieces, reversed.
fn share_pairs(
    model: &mut Model,
    fa: FaceId,
    fb: FaceId,
    pairs: Vec<(Run, Run)>,
) -> (Vec<EdgeId>, Vec<VertexId>) {
    let mut dropped_edges = Vec::new();
    let mut dropped_vertices = Vec::new();
    let mut canonical: BTreeMap<VertexId, VertexId> = BTreeMap::new();
    let mut swaps: BTreeMap<usize, Vec<(usize, usize, Vec<OrientedEdge>)>> = BTreeMap::new();
    for (ra, rb) in pairs {
        // A straight stretch goes on to both contours' restored corners.
        let (ra, rb) = if ra.closed {
            (ra, rb)
        } else {
            (
                restore_corners(model, fa, &ra),
                restore_corners(model, fb, &rb),
            )
        };
        let own_a = pieces(model, fa, &ra);
        let own_b = pieces(model, fb, &rb);
        if !ra.closed {
            // b's start is a's end and b's end a's start.
            canonical.insert(begin(model, own_b[0]), end(model, own_a[ra.len - 1]));
            canonical.insert(end(model, own_b[rb.len - 1]), begin(model, own_a[0]));
        }
        for (i, oe) in own_b.iter().enumerate() {
            dropped_edges.push(oe.edge);
            if i > 0 || rb.closed {
                dropped_vertices.push(begin(model, *oe));
            }
        }
        let replacement = reversed(&own_a);
        swaps
            .entry(rb.lp)
            .or_default()
            .push((rb.start, rb.len, replacement));
    }
    dropped_vertices.extend(canonical.keys().copied());
    swap_runs(model, fb, swaps, &canonical);
    (dropped_edges, dropped_vertices)
}

/// The later region's runs replaced by the earlier region's pieces
/// (`swaps`: per loop, the runs' start, length and replacement), and its
/// remaining pieces next to a run end moved onto the run's corner vertices.
pub(super) fn swap_runs(
    model: &mut Model,
    fb: FaceId,
    swaps: BTreeMap<usize, Vec<(usize, usize, Vec<OrientedEdge>)>>,
    canonical: &BTreeMap<VertexId, VertexId>,
) {
    let mut loops = model.faces[fb.index()].loops.to_vecs();
    for (l, mut list) in swaps {
        list.sort_by_key(|s| s.0);
        loops[l] = super::region_arcs::spliced(&loops[l], &list);
    }
    model.faces[fb.index()].loops = loops.into();
    let remaining: BTreeSet<EdgeId> = model.faces[fb.index()]
        .loops
        .edges()
        .iter()
        .map(|oe| oe.edge)
        .collect();
    for e in remaining {
        let edge = &mut model.edges[e.index()];
        for v in [&mut edge.begin, &mut edge.end] {
            if let Some(&w) = canonical.get(v) {
                *v = w;
            }
        }
        super::edge_parts::follow_vertices(model, e);
    }
}

/// Pieces walked the other way: the earlier region's run as the later one
/// goes along it.
pub(super) fn reversed(pieces: &[OrientedEdge]) -> Vec<OrientedEdge> {
    pieces
        .iter()
        .rev()
        .map(|oe| OrientedEdge {
            edge: oe.edge,
            forward: !oe.forward,
        })
        .collect()
}

fn loop_of(model: &Model, f: FaceId, lp: usize) -> &[OrientedEdge] {
    &model.faces[f.index()].loops[lp]
}

pub(super) fn pieces(model: &Model, f: FaceId, run: &Run) -> Vec<OrientedEdge> {
    let lp = loop_of(model, f, run.lp);
    let n = lp.len();
    (0..run.len).map(|i| lp[(run.start + i) % n]).collect()
}

fn run_end_points(model: &Model, f: FaceId, run: &Run) -> (Point3, Point3) {
    let own = pieces(model, f, run);
    (
        model.vertex(begin(model, own[0])).position,
        model.vertex(end(model, own[run.len - 1])).position,
    )
}

/// A straight run extended along its line, with the positions its two end
/// vertices move to (see [`restore_corners`]).
struct Planned {
    run: Run,
    moves: Vec<(VertexId, Point3)>,
}

impl Planned {
    /// The run's end points once moved.
    fn ends(&self, model: &Model, f: FaceId) -> (Point3, Point3) {
        let own = pieces(model, f, &self.run);
        let at = |v: VertexId| {
            self.moves
                .iter()
                .find(|m| m.0 == v)
                .map_or(model.vertex(v).position, |m| m.1)
        };
        (
            at(begin(model, own[0])),
            at(end(model, own[self.run.len - 1])),
        )
    }

    /// The longer of the run's two end pieces.
    fn end_piece(&self, model: &Model, f: FaceId) -> f64 {
        let own = pieces(model, f, &self.run);
        let length = |oe: OrientedEdge| {
            (model.vertex(end(model, oe)).position - model.vertex(begin(model, oe)).position).norm()
        };
        length(own[0]).max(length(own[self.run.len - 1]))
    }
}

/// Where a straight run's ends really are: marching squares cut the corner
/// where the contour leaves the interface, so the line through the next two
/// contour points beyond each end is followed back to the run's line, and
/// the end vertex moved there when that point is within two of the end's
/// pieces (else the contour leaves smoothly and the end stays).
fn restore_corners(model: &mut Model, f: FaceId, run: &Run) -> Run {
    let Some(plan) = planned_corners(model, f, run) else {
        return *run;
    };
    for (v, x) in plan.moves {
        model.vertices[v.index()].position = x;
    }
    // The run's own pieces and the neighbours follow their vertices.
    for oe in loop_of(model, f, run.lp).to_vec() {
        super::edge_parts::follow_vertices(model, oe.edge);
    }
    plan.run
}

/// [`restore_corners`] without moving anything; None when the run is not
/// straight.
fn planned_corners(model: &Model, f: FaceId, run: &Run) -> Option<Planned> {
    let lp = loop_of(model, f, run.lp);
    let n = lp.len();
    let mut moves: Vec<(VertexId, Point3)> = Vec::new();
    let (a, b) = run_end_points(model, f, run);
    // Straight: every vertex of the run on the chord of its ends.
    let tol = ON_SET_FRACTION * extent(model, f);
    let position = |v: VertexId| model.vertex(v).position;
    if pieces(model, f, run)
        .iter()
        .any(|oe| off_line(position(end(model, *oe)), a, b) > tol)
    {
        return None;
    }
    // The contour may go on along the line past the other's cut corner.
    let mut run = *run;
    while run.len + 2 < n
        && off_line(position(end(model, lp[(run.start + run.len) % n])), a, b) <= tol
    {
        run.len += 1;
    }
    while run.len + 2 < n
        && off_line(position(begin(model, lp[(run.start + n - 1) % n])), a, b) <= tol
    {
        run.start = (run.start + n - 1) % n;
        run.len += 1;
    }
    let own = pieces(model, f, &run);
    let (first, last) = (begin(model, own[0]), end(model, own[run.len - 1]));
    let after = run.start + run.len;
    let ends = [
        (
            first,
            begin(model, lp[(run.start + n - 1) % n]),
            begin(model, lp[(run.start + n - 2) % n]),
            begin(model, lp[(run.start + n - 3) % n]),
        ),
        (
            last,
            end(model, lp[after % n]),
            end(model, lp[(after + 1) % n]),
            end(model, lp[(after + 2) % n]),
        ),
    ];
    for (v, beyond, further, third) in ends {
        // An end moved already (a run of all but two pieces) counts moved.
        let p = |w: VertexId| moves.iter().find(|m| m.0 == w).map_or(position(w), |m| m.1);
        let (pv, pb, pc) = (p(v), p(beyond), p(further));
        let extended = parabola_meets_line([pb, pc, p(third)], a, b)
            .or_else(|| ray_meets_line(pb, pb - pc, a, b));
        if let Some(x) = extended
            && (x - pv).norm() <= 2.0 * (pb - pv).norm()
        {
            moves.push((v, x));
        }
    }
    Some(Planned { run, moves })
}

/// The corner where a contour leaving the line `from + direction·u` at
/// vertex v (then b, c and the vertex after c in loop `lp`) really meets it:
/// the parabola through b, c and the next, extended back to the line, when
/// that point is within two of v's pieces of v.
pub(super) fn corner_on_line(
    model: &Model,
    lp: &[OrientedEdge],
    [v, b, c]: [VertexId; 3],
    from: Point3,
    direction: crate::geom::Vec3,
) -> Option<Point3> {
    let d = vertex_after(model, lp, b, c)?;
    let p = |w: VertexId| model.vertex(w).position;
    let x = parabola_meets_line([p(b), p(c), p(d)], from, from + direction)?;
    ((x - p(v)).norm() <= 2.0 * (p(b) - p(v)).norm()).then_some(x)
}

/// The vertex of loop `lp` after c, coming from b.
pub(super) fn vertex_after(
    model: &Model,
    lp: &[OrientedEdge],
    b: VertexId,
    c: VertexId,
) -> Option<VertexId> {
    lp.iter().find_map(|oe| {
        let e = model.edge(oe.edge);
        match (e.begin, e.end) {
            (x, y) if x == c && y != b => Some(y),
            (y, x) if x == c && y != b => Some(y),
            _ => None,
        }
    })
}

/// Where the parabola through the contour points q[0], q[1], q[2]
/// (parameters 0 and their chord lengths), extended back past q[0], first
/// meets the line through a and b: the contour's curvature kept, so the
/// corner is found to the third order of the piece length, not the second.
fn parabola_meets_line(q: [Point3; 3], a: Point3, b: Point3) -> Option<Point3> {
    let (s1, s2) = (
        (q[1] - q[0]).norm(),
        (q[1] - q[0]).norm() + (q[2] - q[1]).norm(),
    );
    if s1 <= 0.0 || s2 <= s1 {
        return None;
    }
    let d = b - a;
    // g(s) = cross(P(s) - a, d), quadratic in s, from its three values.
    let g = |p: Point3| (p.x - a.x) * d.y - (p.y - a.y) * d.x;
    let (g0, g1, g2) = (g(q[0]), g(q[1]), g(q[2]));
    // Newton's form: g0 + s·d01 + s(s - s1)·d012.
    let d01 = (g1 - g0) / s1;
    let d12 = (g2 - g1) / (s2 - s1);
    let d012 = (d12 - d01) / s2;
    let (qa, qb, qc) = (d012, d01 - d012 * s1, g0);
    let roots: Vec<f64> = if qa.abs() <= 1e-12 * qb.abs() {
        (qb != 0.0).then(|| -qc / qb).into_iter().collect()
    } else {
        let disc = qb * qb - 4.0 * qa * qc;
        if disc < 0.0 {
            return None;
        }
        vec![
            (-qb - disc.sqrt()) / (2.0 * qa),
            (-qb + disc.sqrt()) / (2.0 * qa),
        ]
    };
    // Back past q[0] (s ≤ 0), the nearest.
    let s = roots
        .into_iter()
        .filter(|&s| s <= 0.0)
        .fold(f64::NEG_INFINITY, f64::max);
    if !s.is_finite() {
        return None;
    }
    // The point at s by Lagrange's form, each coordinate.
    let w0 = (s - s1) * (s - s2) / (s1 * s2);
    let w1 = s * (s - s2) / (s1 * (s1 - s2));
    let w2 = s * (s - s1) / (s2 * (s2 - s1));
    let x = q[0] * w0 + (q[1] * w1).coords + (q[2] * w2).coords;
    // Onto the line exactly.
    let t = (x - a).dot(&d) / d.norm_squared();
    Some(a + d * t)
}

/// Where the ray from `from` along `dir` crosses the line through a and b.
fn ray_meets_line(from: Point3, dir: crate::geom::Vec3, a: Point3, b: Point3) -> Option<Point3> {
    let d = b - a;
    let cross = |u: crate::geom::Vec3, v: crate::geom::Vec3| u.x * v.y - u.y * v.x;
    let across = cross(dir, d);
    if across == 0.0 {
        return None;
    }
    let s = -cross(from - a, d) / across;
    (s >= 0.0).then(|| from + dir * s)
}

fn off_line(p: Point3, a: Point3, b: Point3) -> f64 {
    let d = b - a;
    let len = d.x.hypot(d.y);
    if len == 0.0 {
        return (p - a).norm();
    }
    ((p.x - a.x) * d.y - (p.y - a.y) * d.x).abs() / len
}

/// How far from the other region's zero set (or box side) a point on it may
/// be, as a fraction of the extent: both contours' points are roots of f, so
/// a shared stretch is on both zero sets to root finding's precision, while
/// two curves that only touch (tangent disks) part quadratically and fail it
/// within a fraction of a piece.
pub(super) const ON_SET_FRACTION: f64 = 1e-6;

/// The maximal runs of face `f`'s loop pieces lying on face `other`'s
/// contour: both ends and the middle within `tol` of one of its pieces, and
/// on that piece's zero set (or on it, for a box side) within
/// [`ON_SET_FRACTION`] of `other`'s extent.
fn runs_on(model: &Model, f: FaceId, other: FaceId, tol: f64) -> Vec<Run> {
    let tight = ON_SET_FRACTION * extent(model, other);
    let segments: Vec<(Point3, Point3, std::borrow::Cow<Curve>)> = model.faces[other.index()]
        .loops
        .edges()
        .iter()
        .map(|oe| {
            let e = model.edge(oe.edge);
            (
                model.vertex(e.begin).position,
                model.vertex(e.end).position,
                e.curve(&model.solids),
            )
        })
        .collect();
    let near = |p: Point3| {
        segments.iter().any(|(a, b, curve)| {
            let d = segment_distance(p, *a, *b);
            d <= tol
                && match &**curve {
                    Curve::Contour { f, .. } => off_zero_set(f, p, tight) <= tight,
                    _ => d <= tight,
                }
        })
    };
    let mut runs = Vec::new();
    for (l, lp) in model.faces[f.index()].loops.iter().enumerate() {
        let n = lp.len();
        let on_vertex: Vec<bool> = lp
            .iter()
            .map(|&oe| near(model.vertex(begin(model, oe)).position))
            .collect();
        let on: Vec<bool> = (0..n)
            .map(|k| {
                on_vertex[k]
                    && on_vertex[(k + 1) % n]
                    && near(model.edge_curve(lp[k].edge).point(0.5))
            })
            .collect();
        if on.iter().all(|&x| x) {
            runs.push(Run {
                lp: l,
                start: 0,
                len: n,
                closed: true,
            });
            continue;
        }
        for k in 0..n {
            if on[k] && !on[(k + n - 1) % n] {
                let len = (0..n).take_while(|i| on[(k + i) % n]).count();
                runs.push(Run {
                    lp: l,
                    start: k,
                    len,
                    closed: false,
                });
            }
        }
    }
    runs
}

/// |f(p)| / |∇f(p)|: the distance of p from f = 0 to first order (central
/// differences with step `h`).
pub(super) fn off_zero_set(f: &crate::implicit::tape::Ssa, p: Point3, h: f64) -> f64 {
    let at = |x: f64, y: f64| f.eval_point([x, y, p.z]);
    let value = at(p.x, p.y);
    let gx = (at(p.x + h, p.y) - at(p.x - h, p.y)) / (2.0 * h);
    let gy = (at(p.x, p.y + h) - at(p.x, p.y - h)) / (2.0 * h);
    let slope = gx.hypot(gy);
    if !value.is_finite() || !slope.is_finite() || slope == 0.0 {
        return f64::INFINITY;
    }
    value.abs() / slope
}

pub(super) fn segment_distance(p: Point3, a: Point3, b: Point3) -> f64 {
    let d = b - a;
    let l2 = d.x * d.x + d.y * d.y;
    let t = if l2 > 0.0 {
        (((p.x - a.x) * d.x + (p.y - a.y) * d.y) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p.x - a.x - t * d.x).hypot(p.y - a.y - t * d.y)
}

/// The diagonal of a face's vertices' box.
pub(super) fn extent(model: &Model, f: FaceId) -> f64 {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for oe in model.faces[f.index()].loops.edges() {
        let p = model.vertex(model.edge(oe.edge).begin).position;
        lo = [lo[0].min(p.x), lo[1].min(p.y)];
        hi = [hi[0].max(p.x), hi[1].max(p.y)];
    }
    (hi[0] - lo[0]).hypot(hi[1] - lo[1])
}
