//! Region contours on kernel curves (issue 6): where a 2D R-function
//! region's contour runs along a kernel circle or ellipse arc (a material
//! patch against a hole or the outer circle, a coating around a disk) or
//! along a straight kernel edge (a patch against a triangle's slanted side),
//! that run of contour pieces is replaced by the kernel edge itself, split at
//! the run's ends. Both faces then use the same edges, so their meshes share
//! the nodes, and the mesher puts every new node on the true curve, not on
//! the traced contour. The run's own vertices and pieces are dropped. Box
//! sides on a straight kernel edge are left to `region_interfaces`' split.
//!
//! A run's end is the last contour vertex on the kernel curve, moved onto it exactly
//! (marching squares cut a corner of the contour there by at most its
//! chordal tolerance); an end at a kernel vertex, or at another run's end,
//! becomes that vertex.

use super::edge_parts::EdgeParts;
use crate::diag::{Code, Diagnostic, Diagnostics};
use crate::geom::{Curve, Point3, Vec3};
use crate::ir::{EdgeId, FaceId, Model, OrientedEdge, SourceMap, SubdomainId, VertexId};
use std::collections::{BTreeMap, BTreeSet};
use std::f64::consts::TAU;

/// How far a contour vertex may be from a kernel curve to count as on it, as a
/// fraction of the region's extent: the traced points lie on f = 0 to root
/// finding's precision, far inside the contour's chordal tolerance (5e-4).
pub(super) const ON_ARC_FRACTION: f64 = 1e-6;

/// A kernel edge's circle or ellipse: center + major·cos t + minor·sin t for
/// t from t0 over `span`.
#[derive(Clone, Copy)]
pub(super) struct Arc {
    center: Point3,
    major: Vec3,
    minor: Vec3,
    t0: f64,
    span: f64,
}

/// A straight kernel edge: from + direction·u for u from 0 to `length`
/// (`direction` a unit vector, so u is the distance along the edge).
#[derive(Clone, Copy)]
pub(super) struct Line {
    from: Point3,
    direction: Vec3,
    length: f64,
}

/// The kernel curve a region's contour may run along.
#[derive(Clone, Copy)]
pub(super) enum KernelCurve {
    Arc(Arc),
    Line(Line),
}

impl KernelCurve {
    pub(super) fn of(curve: &Curve) -> Option<KernelCurve> {
        match *curve {
            Curve::Ellipse {
                center,
                major,
                minor,
                t0,
                t1,
            } => Some(KernelCurve::Arc(Arc {
                center,
                major,
                minor,
                t0,
                span: t1 - t0,
            })),
            Curve::Segment { a, b } => {
                let length = (b - a).norm();
                (length > 0.0).then(|| {
                    KernelCurve::Line(Line {
                        from: a,
                        direction: (b - a) / length,
                        length,
                    })
                })
            }
            _ => None,
        }
    }

    /// The centre of a circle or ellipse; None for a line.
    pub(super) fn center(&self) -> Option<Point3> {
        match self {
            KernelCurve::Arc(a) => Some(a.center),
            KernelCurve::Line(_) => None,
        }
    }

    pub(super) fn is_line(&self) -> bool {
        matches!(self, KernelCurve::Line(_))
    }

    pub(super) fn span(&self) -> f64 {
        match self {
            KernelCurve::Arc(a) => a.span,
            KernelCurve::Line(l) => l.length,
        }
    }

    pub(super) fn point(&self, u: f64) -> Point3 {
        match self {
            KernelCurve::Arc(a) => a.point(u),
            KernelCurve::Line(l) => l.from + l.direction * u,
        }
    }

    fn tangent(&self, u: f64) -> Vec3 {
        match self {
            KernelCurve::Arc(a) => a.tangent(u),
            KernelCurve::Line(l) => l.direction,
        }
    }

    pub(super) fn parameter(&self, p: &Point3) -> f64 {
        match self {
            KernelCurve::Arc(a) => a.parameter(p),
            KernelCurve::Line(l) => (p - l.from).dot(&l.direction),
        }
    }

    /// Where the contour leaving the curve at `a` towards `b` and `c` really
    /// meets it: marching squares cut that corner off with the chord a → b,
    /// so the line c → b is followed back to the curve. None when that point
    /// is not near `a` (the contour leaves the curve smoothly).
    fn corner(&self, a: Point3, b: Point3, c: Point3) -> Option<Point3> {
        let x = match self {
            KernelCurve::Arc(arc) => arc.corner(b, c)?,
            // Kept on the edge: a corner past its end is at that end.
            KernelCurve::Line(line) => {
                self.point(self.parameter(&line.corner(b, c)?).clamp(0.0, line.length))
            }
        };
        // Within a few chords of a: the same corner.
        ((x - a).norm() <= 2.0 * (b - a).norm()).then_some(x)
    }

    /// The parameter of p if p lies on the curve within `tol`.
    fn on(&self, p: &Point3, tol: f64) -> Option<f64> {
        let (u, reach) = match self {
            KernelCurve::Arc(a) => a.unwrapped(p, tol),
            KernelCurve::Line(_) => (self.parameter(p), tol),
        };
        ((-reach..=self.span() + reach).contains(&u) && (self.point(u) - p).norm() <= tol)
            .then_some(u.clamp(0.0, self.span()))
    }

    /// The kernel edge's piece between parameters u0 and u1, whose end
    /// vertices are at `ends`.
    fn piece(&self, u0: f64, u1: f64, ends: (Point3, Point3)) -> Curve {
        match self {
            KernelCurve::Arc(arc) => Curve::Ellipse {
                center: arc.center,
                major: arc.major,
                minor: arc.minor,
                t0: arc.t0 + u0,
                t1: arc.t0 + u1,
            },
            // The vertices' own positions, so the piece ends exactly there.
            KernelCurve::Line(_) => Curve::Segment {
                a: ends.0,
                b: ends.1,
            },
        }
    }
}

impl Arc {
    fn closed(&self) -> bool {
        self.span >= TAU * (1.0 - 1e-12)
    }

    fn point(&self, u: f64) -> Point3 {
        let t = self.t0 + u;
        self.center + self.major * t.cos() + self.minor * t.sin()
    }

    fn tangent(&self, u: f64) -> Vec3 {
        let t = self.t0 + u;
        self.minor * t.cos() - self.major * t.sin()
    }

    /// p's coordinates in the frame where the curve is the unit circle
    /// (lines stay lines).
    fn local(&self, p: &Point3) -> [f64; 2] {
        let (m, n) = (self.major, self.minor);
        let det = m.x * n.y - m.y * n.x;
        let d = p - self.center;
        [(d.x * n.y - d.y * n.x) / det, (m.x * d.y - m.y * d.x) / det]
    }

    /// The parameter u ∈ [0, 2π) of the curve point along p's direction in
    /// the arc's (major, minor) frame: exact for a point on the curve.
    fn parameter(&self, p: &Point3) -> f64 {
        let [c, s] = self.local(p);
        (s.atan2(c) - self.t0).rem_euclid(TAU)
    }

    /// p's parameter, just before 0 rather than just before 2π on an open
    /// arc, with how far past the ends a parameter may be within `tol`.
    fn unwrapped(&self, p: &Point3, tol: f64) -> (f64, f64) {
        let u = self.parameter(p);
        let reach = tol / self.major.norm().min(self.minor.norm());
        let u = if !self.closed() && u > self.span && u > TAU - reach {
            0.0
        } else {
            u
        };
        (u, reach)
    }

    /// Where the parabola through the contour points q[0], q[1], q[2]
    /// (parameters 0 and their chord lengths), extended back past q[0],
    /// first meets the curve: the contour's curvature kept, so the corner is
    /// found to the third order of the piece length (the ray of
    /// [`Arc::corner`] to the second). None when it does not meet it within
    /// four of q[0]'s pieces.
    fn corner_parabola(&self, q: [Point3; 3]) -> Option<Point3> {
        let s1 = (q[1] - q[0]).norm();
        let s2 = s1 + (q[2] - q[1]).norm();
        if s1 <= 0.0 || s2 <= s1 {
            return None;
        }
        // Lagrange's form, each coordinate.
        let at = |s: f64| {
            let w0 = (s - s1) * (s - s2) / (s1 * s2);
            let w1 = s * (s - s2) / (s1 * (s1 - s2));
            let w2 = s * (s - s1) / (s2 * (s2 - s1));
            q[0] * w0 + (q[1] * w1).coords + (q[2] * w2).coords
        };
        // Outside (+) or inside (−) the curve, in its unit-circle frame.
        let side = |s: f64| {
            let [x, y] = self.local(&at(s));
            x * x + y * y - 1.0
        };
        let step = s1 / 8.0;
        let mut near = (0.0, side(0.0));
        for i in 1..=32 {
            let s = -step * f64::from(i);
            let g = side(s);
            if g == 0.0 || (g > 0.0) != (near.1 > 0.0) {
                let (mut inner, mut outer) = (near.0, s);
                for _ in 0..60 {
                    let mid = 0.5 * (inner + outer);
                    if (side(mid) > 0.0) == (near.1 > 0.0) {
                        inner = mid;
                    } else {
                        outer = mid;
                    }
                }
                let x = at(0.5 * (inner + outer));
                return Some(self.point(self.parameter(&x)));
            }
            near = (s, g);
        }
        None
    }

    /// The first point of the ray from b away from c on the curve.
    fn corner(&self, b: Point3, c: Point3) -> Option<Point3> {
        let (lb, lc) = (self.local(&b), self.local(&c));
        let dir = [lb[0] - lc[0], lb[1] - lc[1]];
        // |lb + s·dir|² = 1 for the smallest s ≥ 0.
        let qa = dir[0] * dir[0] + dir[1] * dir[1];
        let qb = 2.0 * (lb[0] * dir[0] + lb[1] * dir[1]);
        let qc = lb[0] * lb[0] + lb[1] * lb[1] - 1.0;
        let disc = qb * qb - 4.0 * qa * qc;
        if qa == 0.0 || disc < 0.0 {
            return None;
        }
        let s = [
            (-qb - disc.sqrt()) / (2.0 * qa),
            (-qb + disc.sqrt()) / (2.0 * qa),
        ]
        .into_iter()
        .filter(|&s| s >= 0.0)
        .fold(f64::INFINITY, f64::min);
        if !s.is_finite() {
            return None;
        }
        Some(self.center + self.major * (lb[0] + s * dir[0]) + self.minor * (lb[1] + s * dir[1]))
    }
}

impl Line {
    /// Where the ray from b away from c crosses the line.
    fn corner(&self, b: Point3, c: Point3) -> Option<Point3> {
        let ray = b - c;
        let cross = |u: Vec3, v: Vec3| u.x * v.y - u.y * v.x;
        let across = cross(ray, self.direction);
        if across == 0.0 {
            return None;
        }
        let s = -cross(b - self.from, self.direction) / across;
        (s >= 0.0).then(|| b + ray * s)
    }
}

/// A run of a region loop's pieces on one kernel arc or line: `len` pieces from
/// piece `start` (cyclically), or the whole loop when `closed`.
struct Run {
    face: FaceId,
    lp: usize,
    start: usize,
    len: usize,
    arc: EdgeId,
    curve: KernelCurve,
    closed: bool,
}

/// A run's place in its loop (first piece, count) and the arc pieces that
/// replace it.
type Swap = (usize, usize, Vec<OrientedEdge>);

/// Replaces each run of region contour pieces lying on a kernel arc or
/// straight edge by that edge's pieces. Returns the (kernel subdomain, region) pairs it reported.
pub(super) fn share_arcs(
    model: &mut Model,
    source_map: &mut SourceMap,
    first_region: usize,
    diags: &mut Diagnostics,
) -> BTreeSet<(usize, usize)> {
    let mut reported = BTreeSet::new();
    let region_faces: Vec<(usize, FaceId)> = (first_region..model.subdomains.len())
        .filter_map(|r| super::region_interfaces::face_of(model, r).map(|f| (r, f)))
        .collect();
    let region_edges: BTreeSet<EdgeId> =
        super::region_interfaces::face_edges(model, first_region..model.subdomains.len()).collect();
    let arcs: Vec<(EdgeId, KernelCurve)> =
        super::region_interfaces::face_edges(model, 0..first_region)
            .filter(|e| !region_edges.contains(e))
            .collect::<BTreeSet<EdgeId>>()
            .into_iter()
            .filter_map(|e| KernelCurve::of(&model.edge_curve(e)).map(|a| (e, a)))
            .collect();
    if arcs.is_empty() {
        return reported;
    }
    let mut runs = Vec::new();
    for &(_, f) in &region_faces {
        let tol = ON_ARC_FRACTION * extent(model, f);
        for (l, lp) in model.faces[f.index()].loops.iter().enumerate() {
            for &(arc_edge, arc) in &arcs {
                runs.extend(find_runs(model, f, l, lp, arc_edge, &arc, tol));
            }
        }
    }
    // A contour going on along a straight edge's line past its end would
    // meet the edge's end vertex inside one of its pieces (a hanging node).
    let (past, runs): (Vec<Run>, Vec<Run>) = runs
        .into_iter()
        .partition(|r| goes_on_past_its_line(model, r));
    for run in &past {
        report_run(model, source_map, run, first_region, &mut reported, diags);
    }
    if runs.is_empty() {
        return reported;
    }
    // Where each run ends on its arc: (arc, u, region vertex).
    let merge = 16.0 * model.tolerance;
    let mut canonical: BTreeMap<VertexId, VertexId> = BTreeMap::new();
    let mut splits: BTreeMap<EdgeId, Vec<(f64, VertexId)>> = BTreeMap::new();
    for run in runs.iter().filter(|r| !r.closed) {
        let arc = run.curve;
        let ends = run_ends(model, run);
        let edge = model.edge(run.arc);
        let (kernel_begin, kernel_end) = (edge.begin, edge.end);
        for (v, b, c) in ends {
            let p = |w: VertexId| model.vertex(w).position;
            // On a line, the contour's curvature beyond the corner is kept
            // (a corner on a grid node leaves only one piece's chord to follow).
            let on_line = match arc {
                KernelCurve::Line(l) => {
                    let lp = &model.faces[run.face.index()].loops[run.lp];
                    super::region_pairs::corner_on_line(model, lp, [v, b, c], l.from, l.direction)
                        .map(|x| arc.point(arc.parameter(&x).clamp(0.0, l.length)))
                }
                // On an arc likewise: the contour leaving it is curved too.
                KernelCurve::Arc(curve) => {
                    let lp = &model.faces[run.face.index()].loops[run.lp];
                    super::region_pairs::vertex_after(model, lp, b, c)
                        .and_then(|d| curve.corner_parabola([p(b), p(c), p(d)]))
                        .filter(|x| (x - p(v)).norm() <= 2.0 * (p(b) - p(v)).norm())
                }
            };
            let ray = arc.corner(p(v), p(b), p(c));
            // A contour leaving straight gives the ray's corner to rounding:
            // that one is kept (the same point, and the same mesh as before).
            let on_line = match (on_line, ray) {
                (Some(x), Some(y))
                    if !arc.is_line() && (x - y).norm() <= 1e-12 * (p(b) - p(v)).norm() =>
                {
                    Some(y)
                }
                (x, _) => x,
            };
            let at = on_line
                .or(ray)
                .unwrap_or_else(|| arc.point(arc.parameter(&p(v))));
            let u = arc.parameter(&at);
            let list = splits.entry(run.arc).or_default();
            let near = |w: VertexId, m: &Model| (m.vertex(w).position - at).norm() <= merge;
            let target = if near(kernel_begin, model) {
                Some(kernel_begin)
            } else if near(kernel_end, model) {
                Some(kernel_end)
            } else {
                list.iter().map(|&(_, w)| w).find(|&w| near(w, model))
            };
            match target {
                Some(w) => {
                    canonical.insert(v, w);
                }
                None => {
                    model.vertices[v.index()].position = at;
                    list.push((u, v));
                }
            }
        }
    }
    // Each arc cut into pieces at the runs' ends.
    let mut pieces: BTreeMap<EdgeId, Vec<OrientedEdge>> = BTreeMap::new();
    for &(arc_edge, arc) in &arcs {
        if !runs.iter().any(|r| r.arc == arc_edge) {
            continue;
        }
        let mut cuts = splits.remove(&arc_edge).unwrap_or_default();
        cuts.sort_by(|a, b| a.0.total_cmp(&b.0));
        let chain = split_kernel_edge(model, source_map, arc_edge, &arc, &cuts);
        super::region_interfaces::replace_edge(model, arc_edge, &chain);
        pieces.insert(arc_edge, chain);
    }
    // The runs replaced by the arcs' pieces, their own pieces dropped.
    let mut dropped_edges = BTreeSet::new();
    let mut dropped_vertices: BTreeSet<VertexId> = canonical.keys().copied().collect();
    let mut by_loop: BTreeMap<(FaceId, usize), Vec<Swap>> = BTreeMap::new();
    for run in &runs {
        let lp = &model.faces[run.face.index()].loops[run.lp];
        let n = lp.len();
        let own: Vec<OrientedEdge> = (0..run.len).map(|i| lp[(run.start + i) % n]).collect();
        let arc = run.curve;
        let chain = &pieces[&run.arc];
        let first = begin(model, own[0]);
        let second = end(model, own[0]);
        let u = arc.parameter(&model.vertex(first).position);
        let step = model.vertex(second).position - model.vertex(first).position;
        let forward = arc.tangent(u).dot(&step) > 0.0;
        let resolve = |v: VertexId| canonical.get(&v).copied().unwrap_or(v);
        let replacement = if run.closed {
            oriented(chain, forward)
        } else {
            let last = end(model, own[run.len - 1]);
            match walk(model, chain, resolve(first), resolve(last), forward) {
                Some(w) => w,
                None => {
                    report_run(model, source_map, run, first_region, &mut reported, diags);
                    continue;
                }
            }
        };
        for (i, oe) in own.iter().enumerate() {
            dropped_edges.insert(oe.edge);
            if i > 0 || run.closed {
                dropped_vertices.insert(begin(model, *oe));
            }
        }
        by_loop
            .entry((run.face, run.lp))
            .or_default()
            .push((run.start, run.len, replacement));
    }
    for ((f, l), mut swaps) in by_loop {
        swaps.sort_by_key(|s| s.0);
        let lp: Vec<OrientedEdge> = model.faces[f.index()].loops[l].to_vec();
        let out = spliced(&lp, &swaps);
        let mut loops = model.faces[f.index()].loops.to_vecs();
        loops[l] = out;
        model.faces[f.index()].loops = loops.into();
    }
    // The region's pieces next to a merged or moved run end follow it.
    for e in region_edges.iter().filter(|e| !dropped_edges.contains(e)) {
        let edge = &mut model.edges[e.index()];
        for v in [&mut edge.begin, &mut edge.end] {
            if let Some(&w) = canonical.get(v) {
                *v = w;
            }
        }
        super::edge_parts::follow_vertices(model, *e);
    }
    let keep_edge: Vec<bool> = (0..model.edges.len())
        .map(|e| !dropped_edges.contains(&EdgeId(e as u32)))
        .collect();
    let keep_vertex: Vec<bool> = (0..model.vertices.len())
        .map(|v| !dropped_vertices.contains(&VertexId(v as u32)))
        .collect();
    super::prune::drop_entities(model, source_map, &keep_edge, &keep_vertex);
    reported
}

/// The vertex a loop's oriented edge starts at.
pub(super) fn begin(model: &Model, oe: OrientedEdge) -> VertexId {
    let e = model.edge(oe.edge);
    if oe.forward { e.begin } else { e.end }
}

/// The vertex a loop's oriented edge ends at.
pub(super) fn end(model: &Model, oe: OrientedEdge) -> VertexId {
    let e = model.edge(oe.edge);
    if oe.forward { e.end } else { e.begin }
}

/// Each end of an open run with the two contour vertices beyond it.
fn run_ends(model: &Model, run: &Run) -> [(VertexId, VertexId, VertexId); 2] {
    let lp = &model.faces[run.face.index()].loops[run.lp];
    let n = lp.len();
    let after = run.start + run.len;
    [
        (
            begin(model, lp[run.start]),
            begin(model, lp[(run.start + n - 1) % n]),
            begin(model, lp[(run.start + n - 2) % n]),
        ),
        (
            end(model, lp[(after + n - 1) % n]),
            end(model, lp[after % n]),
            end(model, lp[(after + 1) % n]),
        ),
    ]
}

/// Whether the contour beyond an end of a run on a straight kernel edge
/// stays on the edge's line, outside the edge.
fn goes_on_past_its_line(model: &Model, run: &Run) -> bool {
    if !run.curve.is_line() || run.closed {
        return false;
    }
    let tol = ON_ARC_FRACTION * extent(model, run.face);
    run_ends(model, run).iter().any(|&(end, beyond, _)| {
        let p = model.vertex(beyond).position;
        let u = run.curve.parameter(&p);
        let off = (run.curve.point(u) - p).norm();
        off <= tol
            && !(-tol..=run.curve.span() + tol).contains(&u)
            && !super::region_collinear::continues_past(model, run.arc, end, beyond, tol)
    })
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

/// The maximal runs of a loop's pieces whose ends and middle lie on `arc`.
fn find_runs(
    model: &Model,
    face: FaceId,
    l: usize,
    lp: &[OrientedEdge],
    arc_edge: EdgeId,
    arc: &KernelCurve,
    tol: f64,
) -> Vec<Run> {
    let n = lp.len();
    let on_vertex: Vec<bool> = lp
        .iter()
        .map(|&oe| {
            arc.on(&model.vertex(begin(model, oe)).position, tol)
                .is_some()
        })
        .collect();
    let on: Vec<bool> = (0..n)
        .map(|k| {
            // Box sides on a straight edge are share_box_sides' to split.
            let box_side = matches!(*model.edge_curve(lp[k].edge), Curve::Segment { .. });
            on_vertex[k]
                && on_vertex[(k + 1) % n]
                && !(arc.is_line() && box_side)
                && arc
                    .on(&model.edge_curve(lp[k].edge).point(0.5), tol)
                    .is_some()
        })
        .collect();
    if on.iter().all(|&x| x) {
        return vec![Run {
            face,
            lp: l,
            start: 0,
            len: n,
            arc: arc_edge,
            curve: *arc,
            closed: true,
        }];
    }
    let mut runs = Vec::new();
    for k in 0..n {
        if on[k] && !on[(k + n - 1) % n] {
            let len = (0..n).take_while(|i| on[(k + i) % n]).count();
            runs.push(Run {
                face,
                lp: l,
                start: k,
                len,
                arc: arc_edge,
                curve: *arc,
                closed: false,
            });
        }
    }
    runs
}

/// Cuts the kernel edge `ke` (an arc or a line) at `cuts` (sorted by parameter): the first
/// piece keeps its id, name and boundaries, the others are `NAME.2`, … in
/// the same boundaries. Returns the pieces in the arc's direction.
pub(super) fn split_kernel_edge(
    model: &mut Model,
    source_map: &mut SourceMap,
    ke: EdgeId,
    arc: &KernelCurve,
    cuts: &[(f64, VertexId)],
) -> Vec<OrientedEdge> {
    let (b, e) = (model.edge(ke).begin, model.edge(ke).end);
    let mut stops = vec![(0.0, b)];
    stops.extend(cuts.iter().copied());
    stops.push((arc.span(), e));
    let mut parts = EdgeParts::new(model, ke);
    let mut out = Vec::with_capacity(stops.len() - 1);
    for w in stops.windows(2) {
        let ends = (model.vertex(w[0].1).position, model.vertex(w[1].1).position);
        let curve = arc.piece(w[0].0, w[1].0, ends);
        out.push(OrientedEdge {
            edge: parts.push(model, source_map, curve, w[0].1, w[1].1),
            forward: true,
        });
    }
    parts.finish(model);
    out
}

/// The chain in the given direction.
fn oriented(chain: &[OrientedEdge], forward: bool) -> Vec<OrientedEdge> {
    if forward {
        chain.to_vec()
    } else {
        chain.iter().rev().map(|oe| reversed(*oe)).collect()
    }
}

fn reversed(oe: OrientedEdge) -> OrientedEdge {
    OrientedEdge {
        edge: oe.edge,
        forward: !oe.forward,
    }
}

/// The pieces of `chain` (cyclic when closed) from vertex `from` to `to` in
/// the given direction, or None if the walk leaves the arc first.
fn walk(
    model: &Model,
    chain: &[OrientedEdge],
    from: VertexId,
    to: VertexId,
    forward: bool,
) -> Option<Vec<OrientedEdge>> {
    let steps = oriented(chain, forward);
    let n = steps.len();
    let closed = begin(model, steps[0]) == end(model, steps[n - 1]);
    let start = steps.iter().position(|&oe| begin(model, oe) == from)?;
    let mut out = Vec::new();
    for i in 0..n {
        if !closed && start + i >= n {
            return None;
        }
        let oe = steps[(start + i) % n];
        out.push(oe);
        if end(model, oe) == to {
            return Some(out);
        }
    }
    None
}

fn report_run(
    model: &Model,
    source_map: &SourceMap,
    run: &Run,
    first_region: usize,
    reported: &mut BTreeSet<(usize, usize)>,
    diags: &mut Diagnostics,
) {
    let Some(r) = (first_region..model.subdomains.len())
        .find(|&r| super::region_interfaces::face_of(model, r) == Some(run.face))
    else {
        return;
    };
    for k in 0..first_region {
        if let Some(f) = super::region_interfaces::face_of(model, k)
            && model.faces[f.index()]
                .loops
                .edges()
                .iter()
                .any(|oe| oe.edge == run.arc)
        {
            reported.insert((k, r));
        }
    }
    let kind = if run.curve.is_line() {
        "straight"
    } else {
        "curved"
    };
    let p: Point3 = model
        .vertex(begin(
            model,
            model.faces[run.face.index()].loops[run.lp][run.start],
        ))
        .position;
    diags.push(
        Diagnostic::new(
            Code::RegionTouches,
            source_map.subdomain(SubdomainId(r as u32)),
            format!(
                "region '{}' runs along the {kind} edge '{}' from ({:.6}, {:.6}) past its end; a contour on a {kind} kernel edge must stay within that one edge{}",
                model.subdomains[r].name,
                model.edge(run.arc).name,
                p.x,
                p.y,
                if run.curve.is_line() { " or the collinear kernel edges continuing it" } else { "" }
            ),
        )
        .with_help(if run.curve.is_line() {
            "end the region's contour inside the straight edge, or give the kernel shape a collinear straight edge where the run goes on".to_string()
        } else {
            "end the region's contour inside the curved edge, or split the kernel shape so that one edge holds the whole run".to_string()
        }),
    );
}

/// Loop `lp` with each (start, len) stretch replaced by its pieces.
pub(super) fn spliced(
    lp: &[OrientedEdge],
    swaps: &[(usize, usize, Vec<OrientedEdge>)],
) -> Vec<OrientedEdge> {
    let n = lp.len();
    let mut covered = vec![None; n];
    for (k, (start, len, _)) in swaps.iter().enumerate() {
        for i in 0..*len {
            covered[(start + i) % n] = Some(k);
        }
    }
    // Start the walk where a stretch starts, so none wraps past the end.
    let origin = swaps[0].0;
    let mut out = Vec::with_capacity(n);
    let mut i = 0;
    while i < n {
        let at = (origin + i) % n;
        match covered[at] {
            Some(k) if swaps[k].0 == at => {
                out.extend(swaps[k].2.iter().copied());
                i += swaps[k].1;
            }
            Some(_) => i += 1,
            None => {
                out.push(lp[at]);
                i += 1;
            }
        }
    }
    out
}
