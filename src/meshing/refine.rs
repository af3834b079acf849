//! Delaunay refinement of a plane face on spade's triangulation, with
//! off-centres (Üngör) instead of circumcentres and diametral lenses for
//! segment encroachment, as Shewchuk's Triangle does.
//!
//! Spade's own `refine` inserts circumcentres and splits a segment whenever a
//! point enters its diametral circle; on a polygon with 10,000 boundary
//! vertices that made 34% more triangles than Triangle at the same minimum
//! angle. An off-centre is the point on the shortest edge's bisector where
//! the new triangle on that edge just meets the angle bound; when it is
//! nearer than the circumcentre it is inserted instead, so the new
//! triangles are no smaller than the bound asks for.
//!
//! # Guarantees
//! - When `complete` is returned, every triangle inside the loops has its
//!   smallest angle at least `min_angle` (measured with a margin of 1e-6°)
//!   and its area at most `max_area`.
//! - A point that would encroach a segment (lie in its diametral lens) or
//!   lies beyond one is not inserted: the segment is split instead (at its
//!   middle, or on a power-of-two shell around an input vertex where two
//!   segments meet at an acute angle) and the triangle is tried again.
//! - The order of work depends only on the triangulation (segments first
//!   in FIFO order, then bad triangles by shortest edge and discovery): the
//!   same input gives the same mesh, whatever the thread count.
//!
//! - A segment on a curved edge is split at the curve's point at the
//!   middle parameter (not the chord's middle) when spade can take it there
//!   (the new segments cross nothing): the boundary stays on the curve and
//!   no second refinement pass has to move chord points onto it.
//!
//! # Limitations
//! - For plane faces without poly_lines, small input angles or a kept
//!   boundary: the other cases stay with spade's `refine` (face.rs).

use super::face::{Cdt, Segments};
use crate::geom::Point3;
use robust::{Coord, incircle, orient2d};
use spade::handles::{FixedFaceHandle, FixedVertexHandle, InnerTag};
use spade::{Point2, Triangulation};
use std::collections::VecDeque;

pub(super) struct Params<'a> {
    pub min_angle_degrees: f64,
    /// Largest triangle area (infinite: none).
    pub max_area: f64,
    pub max_additional_vertices: usize,
    /// Faces outside the loops at the start (by face index); they are never
    /// refined, and the faces that replace them stay outside.
    pub outside: Vec<bool>,
    /// The boundary's curves, when splits on curved edges should go onto
    /// them.
    pub curves: Option<Curves<'a>>,
    /// The surface criteria (chordal deviation, edge length) of a curved
    /// face, checked on each new triangle with its corners lifted.
    pub surface: Option<SurfaceCheck<'a>>,
}

/// A curved face's surface criteria inside the refinement loop: each new
/// vertex is lifted once (into `positions`, indexed like the vertices), and
/// a triangle the surface finds too coarse is refined like one too large,
/// so one loop meets the angle bound and the tolerance together instead of
/// alternating spade's whole-face refinement with whole-face chordal scans.
pub(super) struct SurfaceCheck<'a> {
    /// Every vertex's point on the surface; grown as vertices are added.
    pub positions: &'a mut Vec<Point3>,
    /// A chart point's point on the surface.
    pub lift: &'a dyn Fn(Point2<f64>) -> Option<Point3>,
    /// Whether a triangle (corners on the surface) is too coarse.
    pub coarse: &'a dyn Fn([&Point3; 3]) -> bool,
}

/// The boundary segments' edges and curve parameters, kept up to date as
/// segments on curves are split, and where a curved edge's point lies.
pub(super) struct Curves<'a> {
    pub segments: &'a mut Segments,
    /// A curved edge's point at a curve parameter: in the chart and on the
    /// curve; `None` for straight edges (their chord point is on them).
    pub point: &'a dyn Fn(usize, f64) -> Option<(Point2<f64>, Point3)>,
}

pub(super) struct Refined {
    /// Faces outside the loops, by face index.
    pub outside: Vec<bool>,
    /// False when the vertex budget ran out first.
    pub complete: bool,
    /// The vertices put on segments (ascending): the only new vertices on
    /// the boundary. `None` when not known (spade's `refine`). Splits
    /// put on a curve are not among them but in `curved`.
    pub on_segments: Option<Vec<usize>>,
    /// Vertices put on curved edges, at the curve's point (ascending):
    /// (edge, vertex, curve parameter, point on the curve).
    pub curved: Vec<(usize, usize, f64, Point3)>,
    /// Every triangle was checked against the angle and area bounds when
    /// it was made (false after a flood fill: adding constraints there may
    /// flip edges away from the new point, out of its star).
    pub all_checked: bool,
}

struct Refiner<'a, 'c> {
    cdt: &'a mut Cdt,
    curves: Option<Curves<'c>>,
    surface: Option<SurfaceCheck<'c>>,
    /// The curve point of the segment split being made: the position of the
    /// vertex it adds (the chart's lift of it may be off the curve by the
    /// chart's rounding).
    next_node: Option<Point3>,
    /// A vertex did not lift onto the surface: the lifted positions stop
    /// before it, and triangles with corners beyond them are not checked
    /// against the surface (the caller reports the vertex).
    lift_failed: bool,
    curved: Vec<(usize, usize, f64, Point3)>,
    outside: Vec<bool>,
    /// Bad triangles, shortest edge first (Triangle's order: fewer points
    /// than first-come), then in the order they were found.
    triangles: BucketQueue,
    /// Reused per insertion: the faces around the new vertex.
    /// with their corners (counter-clockwise) and side.
    around: Vec<(FixedFaceHandle<InnerTag>, [Point2<f64>; 3], bool)>,
    opposite: Vec<(FixedVertexHandle, FixedVertexHandle)>,
    /// Reused per insertion: the faces around a new vertex.
    star: Vec<FixedFaceHandle<InnerTag>>,
    segments: VecDeque<(FixedVertexHandle, FixedVertexHandle)>,
    /// Input vertices (below this index) where two segments meet at an acute
    /// angle: splits next to them go on power-of-two shells.
    acute: Vec<bool>,
    cos_limit: f64,
    /// cos² of the smallest apex angle (180° − 2·min angle) at which a point
    /// encroaches a segment (Triangle's diametral lens), when that angle is
    /// obtuse.
    lens_cos2: f64,
    off_constant: f64,
    max_area: f64,
    /// Per face index: the pass that last put it in the cavity.
    stamp: Vec<u32>,
    /// Per face index: bumped whenever the slot gets a new triangle (every
    /// triangle an insertion makes is around the new vertex), so a queued
    /// triangle that is gone is told without looking at its corners.
    generation: Vec<u32>,
    pass: u32,
    cavity: Vec<FixedFaceHandle<InnerTag>>,
    encroached: Vec<(FixedVertexHandle, FixedVertexHandle)>,
    on_segments: Vec<usize>,
    reflooded: bool,
    /// A bad triangle was left as it is (its point could be neither
    /// inserted nor made room for).
    gave_up: bool,
}

pub(super) fn refine(cdt: &mut Cdt, params: Params<'_>) -> Refined {
    let alpha = params.min_angle_degrees.to_radians();
    let cos_alpha = alpha.cos();
    let inputs = cdt.num_vertices();
    let limit = inputs.saturating_add(params.max_additional_vertices);
    let acute = acute_vertices(cdt);
    let mut outside = params.outside;
    outside.resize(cdt.num_all_faces(), true);
    let generation = vec![0; cdt.num_all_faces()];
    let mut r = Refiner {
        cdt,
        curves: params.curves,
        surface: params.surface,
        next_node: None,
        lift_failed: false,
        curved: Vec::new(),
        outside,
        triangles: BucketQueue::new(),
        around: Vec::new(),
        opposite: Vec::new(),
        star: Vec::new(),
        segments: VecDeque::new(),
        acute,
        cos_limit: (params.min_angle_degrees + 1e-6).to_radians().cos(),
        // Diametral circles (any obtuse apex encroaches), not Triangle's
        // lenses: with lenses the interface of two materials kept
        // triangles up to 124° against it and the flux across it (fem_2d)
        // jumped 6% instead of under 3%.
        lens_cos2: 0.0,
        // Triangle's 0.475 rather than 0.5: the new triangle ends a little
        // above the bound, not on it.
        off_constant: 0.475 * ((1.0 + cos_alpha) / (1.0 - cos_alpha)).sqrt(),
        max_area: params.max_area,
        stamp: Vec::new(),
        generation,
        pass: 0,
        cavity: Vec::new(),
        encroached: Vec::new(),
        on_segments: Vec::new(),
        reflooded: false,
        gave_up: false,
    };
    let segments: Vec<_> = r
        .cdt
        .undirected_edges()
        .filter(|e| e.is_constraint_edge())
        .map(|e| {
            let [a, b] = e.vertices();
            (a.fix(), b.fix())
        })
        .collect();
    r.segments.extend(segments);
    let faces: Vec<_> = r.cdt.fixed_inner_faces().collect();
    for f in faces {
        if !r.outside[f.index()] {
            r.push_triangle(f);
        }
    }
    let mut complete = true;
    loop {
        if r.cdt.num_vertices() >= limit {
            complete = false;
            break;
        }
        if let Some((a, b)) = r.segments.pop_front() {
            if r.is_encroached(a, b) {
                r.split_segment(a, b);
            }
            continue;
        }
        let Some((face, generation)) = r.triangles.pop() else {
            break;
        };
        let index = face.index();
        // Gone since it was queued (its slot now holds another triangle,
        // queued on its own when it was made): told by the slot's
        // generation, without a lookup in the triangulation (face lookups
        // are a sixth of the time at 1.5 M triangles).
        if r.generation.get(index) != Some(&generation) || r.outside[index] {
            continue;
        }
        // Unchanged since it was found bad (same slot generation): its
        // point is computed without checking it again (the surface check
        // is the costly half of that).
        // One walk of the face for both its corners and their positions.
        let vertices = r.cdt.face(face).vertices();
        let corners = vertices.map(|v| v.fix());
        if let Some(point) = r.bad_triangle_point(vertices.map(|v| v.position())) {
            r.split_triangle(face, corners, point);
        }
    }
    Refined {
        complete: complete && !r.gave_up,
        outside: r.outside,
        on_segments: Some(r.on_segments),
        curved: r.curved,
        all_checked: !r.reflooded,
    }
}

fn coord(p: Point2<f64>) -> Coord<f64> {
    Coord { x: p.x, y: p.y }
}

/// Input vertices where two constraint edges meet at less than 90°
/// (checked without a per-vertex allocation: this runs over every vertex
/// at each refinement call).
fn acute_vertices(cdt: &Cdt) -> Vec<bool> {
    cdt.vertices()
        .map(|v| {
            let p = v.position();
            let mut dirs = [[0.0f64; 2]; 8];
            for (n, e) in v.out_edges().filter(|e| e.is_constraint_edge()).enumerate() {
                let q = e.to().position();
                let d = [q.x - p.x, q.y - p.y];
                if dirs[..n.min(8)]
                    .iter()
                    .any(|a| a[0] * d[0] + a[1] * d[1] > 0.0)
                {
                    return true;
                }
                if n < 8 {
                    dirs[n] = d;
                }
            }
            false
        })
        .collect()
}

impl Refiner<'_, '_> {
    /// Gives the per-face tables a slot for every face spade made (new
    /// faces start outside, at generation 0).
    fn grow_face_tables(&mut self) {
        let n = self.cdt.num_all_faces();
        if self.outside.len() < n {
            self.outside.resize(n, true);
        }
        if self.generation.len() < n {
            self.generation.resize(n, 0);
        }
    }

    /// Queues the triangle when it is bad.
    fn push_triangle(&mut self, f: FixedFaceHandle<InnerTag>) {
        self.push_triangle_at(f, self.cdt.face(f).positions());
    }

    /// Queues the triangle with corners `p` when it is bad (the corners
    /// already at hand: no face lookup unless a surface check needs the
    /// vertices).
    fn push_triangle_at(&mut self, f: FixedFaceHandle<InnerTag>, p: [Point2<f64>; 3]) {
        self.lift_new_vertices();
        let (lengths, k) = shortest_edge(p);
        let bad = self.badness(p, lengths, k)
            || (self.surface.is_some() && {
                let corners = self.cdt.face(f).vertices().map(|v| v.fix().index());
                self.too_coarse(corners)
            });
        if bad {
            self.triangles
                .push(lengths[k], (f, self.generation[f.index()]));
        }
    }

    /// Whether the triangle is below the angle bound or above the area
    /// limit (`lengths`, `k`: its squared edge lengths and the shortest).
    fn badness(&self, p: [Point2<f64>; 3], lengths: [f64; 3], k: usize) -> bool {
        let (o, q, r) = (p[k], p[(k + 1) % 3], p[(k + 2) % 3]);
        let (u, v) = ([o.x - r.x, o.y - r.y], [q.x - r.x, q.y - r.y]);
        let cross = (q.x - o.x) * (r.y - o.y) - (q.y - o.y) * (r.x - o.x);
        let skinny = (u[0] * v[0] + u[1] * v[1])
            > self.cos_limit * (lengths[(k + 1) % 3] * lengths[(k + 2) % 3]).sqrt();
        skinny || 0.5 * cross > self.max_area
    }

    /// Whether the surface finds the triangle with these corners too coarse
    /// (never without a surface check, or before its corners are lifted).
    fn too_coarse(&self, [a, b, c]: [usize; 3]) -> bool {
        let Some(surface) = &self.surface else {
            return false;
        };
        let positions = &surface.positions;
        match (positions.get(a), positions.get(b), positions.get(c)) {
            (Some(pa), Some(pb), Some(pc)) => (surface.coarse)([pa, pb, pc]),
            _ => false,
        }
    }

    /// Lifts the vertices added since the last call onto the surface (the
    /// split being made puts its vertex at its curve point instead).
    fn lift_new_vertices(&mut self) {
        let Some(surface) = self.surface.as_mut() else {
            return;
        };
        let n = self.cdt.num_vertices();
        while !self.lift_failed && surface.positions.len() < n {
            let v = surface.positions.len();
            let point = match self.next_node {
                Some(node) if v + 1 == n => Some(node),
                _ => (surface.lift)(self.cdt.vertex(FixedVertexHandle::from_index(v)).position()),
            };
            match point {
                Some(p) => surface.positions.push(p),
                None => self.lift_failed = true,
            }
        }
    }

    /// After the last vertex was taken out again: its lifted position goes
    /// too (the next vertex takes its index).
    fn forget_removed(&mut self) {
        let n = self.cdt.num_vertices();
        if let Some(surface) = self.surface.as_mut() {
            surface.positions.truncate(n);
        }
    }

    /// Whether the apex of an inside triangle next to segment a–b lies in
    /// its diametral lens.
    fn is_encroached(&self, a: FixedVertexHandle, b: FixedVertexHandle) -> bool {
        let Some(edge) = self.cdt.get_edge_from_neighbors(a, b) else {
            return false;
        };
        if !edge.is_constraint_edge() {
            return false;
        }
        let [pa, pb] = [edge.from().position(), edge.to().position()];
        [edge, edge.rev()].iter().any(|side| {
            let inside = side
                .face()
                .as_inner()
                .is_some_and(|f| !self.outside[f.fix().index()]);
            inside
                && side
                    .opposite_position()
                    .is_some_and(|o| self.encroaches(pa, pb, o))
        })
    }

    /// Whether `p` lies in the diametral lens of segment a–b (the apex angle
    /// at `p` at least 180° − 2·min angle).
    fn encroaches(&self, a: Point2<f64>, b: Point2<f64>, p: Point2<f64>) -> bool {
        let (u, v) = ([a.x - p.x, a.y - p.y], [b.x - p.x, b.y - p.y]);
        let dot = u[0] * v[0] + u[1] * v[1];
        dot < 0.0
            && dot * dot
                >= self.lens_cos2 * (u[0] * u[0] + u[1] * u[1]) * (v[0] * v[0] + v[1] * v[1])
    }

    /// The point to insert for a bad triangle (its off-centre or
    /// circumcentre), or `None` when it is degenerate.
    fn bad_triangle_point(&self, p: [Point2<f64>; 3]) -> Option<Point2<f64>> {
        // The shortest edge k runs from p[k] to p[k + 1]; its opposite
        // corner holds the smallest angle.
        let (_, k) = shortest_edge(p);
        let (o, q, r) = (p[k], p[(k + 1) % 3], p[(k + 2) % 3]);
        // Circumcentre relative to o.
        let (bx, by, cx, cy) = (q.x - o.x, q.y - o.y, r.x - o.x, r.y - o.y);
        let det = 2.0 * (bx * cy - by * cx);
        if det.abs() <= f64::MIN_POSITIVE || !det.is_finite() {
            return None;
        }
        let (b2, c2) = (bx * bx + by * by, cx * cx + cy * cy);
        let (ux, uy) = ((cy * b2 - by * c2) / det, (bx * c2 - cx * b2) / det);
        // Off-centre: on the bisector of o–q, on r's side (left of o → q).
        let (mx, my) = (0.5 * bx, 0.5 * by);
        let (offx, offy) = (mx - self.off_constant * by, my + self.off_constant * bx);
        let (dx, dy) =
            if (offx - mx).powi(2) + (offy - my).powi(2) < (ux - mx).powi(2) + (uy - my).powi(2) {
                (offx, offy)
            } else {
                (ux, uy)
            };
        Some(Point2::new(o.x + dx, o.y + dy))
    }

    /// Inserts `x` for the bad triangle `face` (corners `corners`,
    /// counter-clockwise), unless it encroaches a segment or lies beyond
    /// one: then those segments are split and the triangle is tried again
    /// later.
    ///
    /// Triangle's way: `x` is inserted, and taken out again when its star
    /// has an encroached segment opposite it, does not hold `face` (a
    /// segment lies between them), or lies outside. Finding the cavity
    /// first (`split_triangle_by_cavity`) and then letting spade insert
    /// found it twice: a third of the refinement's time on a
    /// 10,000-vertex polygon.
    fn split_triangle(
        &mut self,
        face: FixedFaceHandle<InnerTag>,
        corners: [FixedVertexHandle; 3],
        x: Point2<f64>,
    ) {
        let faces_before = self.cdt.num_all_faces();
        let before = self.cdt.num_vertices();
        let v = match self.cdt.insert_with_hint(x, corners[0]) {
            Ok(v) if v.index() >= before => v,
            _ => {
                self.gave_up = true;
                return;
            }
        };
        self.grow_face_tables();
        let mut star = std::mem::take(&mut self.star);
        star.clear();
        self.encroached.clear();
        // The star holds `face`'s slot when `face` was destroyed (x is
        // visible from it); slots it reuses were all in x's region.
        let (mut holds_face, mut outside, mut on_hull, mut on_segment) =
            (false, false, false, false);
        // The star's triangles with their corners (x, then the edge
        // opposite it), for queueing them when x stays: the walk around x
        // is not made a second time (`after_insertion`).
        let mut around = std::mem::take(&mut self.around);
        around.clear();
        for e in self.cdt.vertex(v).out_edges() {
            on_segment |= e.is_constraint_edge();
            let Some(f) = e.face().as_inner() else {
                on_hull = true;
                continue;
            };
            let slot = f.fix().index();
            holds_face |= slot == face.index();
            outside |= slot < faces_before && self.outside[slot];
            star.push(f.fix());
            let next = e.next();
            let (a, b) = (next.from(), next.to());
            let (pa, pb) = (a.position(), b.position());
            around.push((f.fix(), [x, pa, pb], false));
            if next.is_constraint_edge() && self.encroaches(pa, pb, x) {
                self.encroached.push((a.fix(), b.fix()));
            }
        }
        if holds_face && !outside && !on_hull && !on_segment && self.encroached.is_empty() {
            self.star = star;
            // Inside: the star's triangles are queued when bad, and the
            // segments opposite x were just checked against it (what
            // `after_insertion` does for `Side::Inside { checked: true }`).
            for &(f, corners, _) in &around {
                self.outside[f.index()] = false;
                self.generation[f.index()] = self.generation[f.index()].wrapping_add(1);
                self.push_triangle_at(f, corners);
            }
            self.around = around;
            return;
        }
        self.around = around;
        // Take x out again: removing the last vertex moves no vertex, and
        // the face slots it frees or moves are all in its star (the two
        // slots the insertion added are the last ones).
        let segment_ends = on_segment.then(|| {
            let vertex = self.cdt.vertex(v);
            let mut ends = vertex
                .out_edges()
                .filter(|e| e.is_constraint_edge())
                .map(|e| e.to().fix());
            (ends.next(), ends.next())
        });
        self.cdt.remove(v);
        self.forget_removed();
        let n = self.cdt.num_all_faces();
        for f in &star {
            self.generation[f.index()] = self.generation[f.index()].wrapping_add(1);
        }
        if on_hull || on_segment || (holds_face && outside) {
            // x fell outside the hull or on a segment (whose constraint the
            // removal took), or its star mixed sides: rare, so the sides
            // are found afresh and the cavity walk decides.
            if let Some((Some(a), Some(b))) = segment_ends {
                self.cdt.add_constraint(a, b);
            }
            self.star = star;
            self.reflood();
            // The flood queued every inside triangle again: the bad one is
            // taken off (by its slot's generation) and the walk decides.
            if let Some(f) = self.find_face(corners) {
                self.generation[f.index()] = self.generation[f.index()].wrapping_add(1);
                self.split_triangle_by_cavity(f, x);
            }
            return;
        }
        for f in &star {
            if f.index() < n {
                self.outside[f.index()] = outside;
            }
        }
        if !holds_face {
            // A segment lies between the triangle and x: the cavity walk
            // finds it (`face` was not in the star, so it is untouched; the
            // star's triangles are back as they were, queued again).
            if !outside {
                self.push_star(&star, n);
            }
            self.star = star;
            self.split_triangle_by_cavity(face, x);
            return;
        }
        let segments = std::mem::take(&mut self.encroached);
        let mut split = false;
        for &(a, b) in &segments {
            split |= self.split_segment(a, b);
        }
        self.encroached = segments;
        self.push_star(&star, n);
        self.star = star;
        if !split {
            // Nothing could be split: the triangle stays as it is.
            self.gave_up = true;
            if let Some(f) = self.find_face(corners) {
                self.generation[f.index()] = self.generation[f.index()].wrapping_add(1);
            }
        }
    }

    /// Queues the faces now in the slots of a removed vertex's star (below
    /// `n`, the face count after the removal; later splits may have put
    /// other faces there, queued twice then, which is harmless).
    fn push_star(&mut self, star: &[FixedFaceHandle<InnerTag>], n: usize) {
        for &f in star {
            if f.index() < n && f.index() < self.cdt.num_all_faces() {
                self.push_triangle(f);
            }
        }
    }

    /// The inner face with these corners (counter-clockwise), if it exists.
    fn find_face(&self, [a, b, c]: [FixedVertexHandle; 3]) -> Option<FixedFaceHandle<InnerTag>> {
        let edge = self.cdt.get_edge_from_neighbors(a, b)?;
        let face = edge.face().as_inner()?;
        (edge.next().to().fix() == c).then(|| face.fix())
    }

    /// [`Self::split_triangle`] through the cavity walk: the faces whose
    /// circumcircle holds `x`, from `face`, not across segments; used when
    /// a segment lies between the triangle and `x`.
    fn split_triangle_by_cavity(&mut self, face: FixedFaceHandle<InnerTag>, x: Point2<f64>) {
        self.pass = self.pass.wrapping_add(1);
        if self.stamp.len() < self.cdt.num_all_faces() {
            self.stamp.resize(self.cdt.num_all_faces(), 0);
        }
        self.cavity.clear();
        self.encroached.clear();
        self.cavity.push(face);
        self.stamp[face.index()] = self.pass;
        let mut contains = false;
        let mut blocked = None;
        let mut i = 0;
        while i < self.cavity.len() {
            let f = self.cdt.face(self.cavity[i]);
            i += 1;
            // Edge k runs from corner k to corner k + 1: one lookup per
            // corner (vertex lookups are most of the refinement's time).
            let edges = f.adjacent_edges();
            let corners = edges.map(|e| e.from().position());
            let mut inside = true;
            for (k, e) in edges.into_iter().enumerate() {
                let (a, b) = (corners[k], corners[(k + 1) % 3]);
                let side = orient2d(coord(a), coord(b), coord(x));
                let constraint = e.is_constraint_edge();
                if side < 0.0 || (side == 0.0 && constraint) {
                    inside = false;
                }
                if constraint {
                    let seg = (e.from().fix(), e.to().fix());
                    if self.encroaches(a, b, x) {
                        if !self.encroached.contains(&seg) {
                            self.encroached.push(seg);
                        }
                    } else if side < 0.0 && blocked.is_none() {
                        blocked = Some(seg);
                    }
                    continue;
                }
                let rev = e.rev();
                let Some(twin) = rev.face().as_inner() else {
                    continue;
                };
                let t = twin.fix().index();
                if self.stamp[t] == self.pass {
                    continue;
                }
                // The twin runs b, a, then its third corner (counter-clockwise).
                let g = rev.next().to().position();
                if incircle(coord(b), coord(a), coord(g), coord(x)) > 0.0 {
                    self.stamp[t] = self.pass;
                    self.cavity.push(twin.fix());
                }
            }
            contains |= inside;
        }
        if !self.encroached.is_empty() || !contains {
            let mut split = false;
            let segments = if self.encroached.is_empty() {
                blocked.into_iter().collect()
            } else {
                std::mem::take(&mut self.encroached)
            };
            for &(a, b) in &segments {
                split |= self.split_segment(a, b);
            }
            self.encroached = segments;
            if split {
                self.push_triangle(face);
            } else {
                self.gave_up = true;
            }
            return;
        }
        let before = self.cdt.num_vertices();
        let hint = self.cdt.face(face).vertices()[0].fix();
        let v = match self.cdt.insert_with_hint(x, hint) {
            Ok(v) if v.index() >= before => v,
            _ => {
                self.gave_up = true;
                return;
            }
        };
        self.after_insertion(v, Side::Inside { checked: false });
    }

    /// Splits segment a–b at its middle, or on a power-of-two shell around
    /// an end where segments meet at an acute angle; false when it cannot
    /// be split (gone, or too short to hold a point).
    fn split_segment(&mut self, a: FixedVertexHandle, b: FixedVertexHandle) -> bool {
        let Some(edge) = self.cdt.get_edge_from_neighbors(a, b) else {
            return false;
        };
        if !edge.is_constraint_edge() {
            return false;
        }
        let status = |side: spade::handles::DirectedEdgeHandle<'_, _, _, _, _>| {
            side.face()
                .as_inner()
                .is_none_or(|f| self.outside[f.fix().index()])
        };
        let (left, right) = (status(edge), status(edge.rev()));
        let [pa, pb] = [edge.from().position(), edge.to().position()];
        let length = (pb.x - pa.x).hypot(pb.y - pa.y);
        let acute = |v: FixedVertexHandle| self.acute.get(v.index()).copied().unwrap_or(false);
        let mut t = 0.5;
        if acute(a) || acute(b) {
            let mut shell = 1.0;
            while length > 3.0 * shell {
                shell *= 2.0;
            }
            while length < 1.5 * shell {
                shell *= 0.5;
            }
            t = shell / length;
            if !acute(a) {
                t = 1.0 - t;
            }
        }
        let on_curve = self.curve_point(a, b, t);
        self.next_node = on_curve.map(|c| c.3);
        let split = on_curve.and_then(|(_, _, uv, _)| self.split_on_curve(a, b, uv, left, right));
        self.next_node = None;
        if let (Some((edge, s, _, node)), Some(v)) = (on_curve, split) {
            let key = |x: FixedVertexHandle, y: FixedVertexHandle| {
                (x.index().min(y.index()), x.index().max(y.index()))
            };
            if let Some(curves) = self.curves.as_mut() {
                let (a_s, b_s) = match curves.segments.remove(&key(a, b)) {
                    Some((_, lo, hi)) if a.index() < b.index() => (lo, hi),
                    Some((_, lo, hi)) => (hi, lo),
                    None => (s, s),
                };
                let entry = |x: FixedVertexHandle, sx: f64, y: FixedVertexHandle, sy: f64| {
                    if x.index() < y.index() {
                        (edge, sx, sy)
                    } else {
                        (edge, sy, sx)
                    }
                };
                curves.segments.insert(key(a, v), entry(a, a_s, v, s));
                curves.segments.insert(key(v, b), entry(v, s, b, b_s));
            }
            self.curved.push((edge, v.index(), s, node));
            self.segments.push_back((a, v));
            self.segments.push_back((v, b));
            return true;
        }
        let Some(edge) = self.cdt.get_edge_from_neighbors(a, b) else {
            return false;
        };
        let m = Point2::new(pa.x + t * (pb.x - pa.x), pa.y + t * (pb.y - pa.y));
        let undirected = edge.fix().as_undirected();
        self.cdt.remove_constraint_edge(undirected);
        let before = self.cdt.num_vertices();
        let v = match self.cdt.insert_with_hint(m, a) {
            Ok(v) if v.index() >= before => v,
            _ => {
                self.cdt.add_constraint(a, b);
                return false;
            }
        };
        self.on_segments.push(v.index());
        let clean = self.cdt.get_edge_from_neighbors(a, v).is_some()
            && self.cdt.get_edge_from_neighbors(v, b).is_some();
        if !(self.cdt.can_add_constraint(a, v) && self.cdt.can_add_constraint(v, b)) {
            // Keep the boundary whole through the new point as far as spade
            // allows; the flood fill below sorts the faces out.
            self.cdt.add_constraint(a, v);
            self.cdt.add_constraint(v, b);
            self.reflood();
            self.after_insertion(v, Side::Flooded);
            return true;
        }
        self.cdt.add_constraint(a, v);
        self.cdt.add_constraint(v, b);
        if !clean {
            // Adding the constraints flipped edges away from the new point.
            self.reflood();
            self.after_insertion(v, Side::Flooded);
        } else {
            self.after_insertion(v, Side::Split { a, b, left, right });
        }
        self.segments.push_back((a, v));
        self.segments.push_back((v, b));
        true
    }

    /// The point of segment a–b's curve at fraction `t` of its parameter
    /// range: (edge, parameter, chart point, point on the curve), when the
    /// segment lies on a curved edge.
    fn curve_point(
        &self,
        a: FixedVertexHandle,
        b: FixedVertexHandle,
        t: f64,
    ) -> Option<(usize, f64, Point2<f64>, Point3)> {
        let curves = self.curves.as_ref()?;
        let key = (a.index().min(b.index()), a.index().max(b.index()));
        let &(edge, lo, hi) = curves.segments.get(&key)?;
        let (sa, sb) = if a.index() < b.index() {
            (lo, hi)
        } else {
            (hi, lo)
        };
        let s = sa + t * (sb - sa);
        let (uv, node) = (curves.point)(edge, s)?;
        Some((edge, s, uv, node))
    }

    /// Splits segment a–b at `x` off its chord (a point on its curve):
    /// the new vertex, or `None` (the triangulation as it was, up to
    /// face numbering) when the segments a–x–b would cross another one or
    /// x falls on a vertex or segment.
    fn split_on_curve(
        &mut self,
        a: FixedVertexHandle,
        b: FixedVertexHandle,
        x: Point2<f64>,
        left: bool,
        right: bool,
    ) -> Option<FixedVertexHandle> {
        let undirected = self
            .cdt
            .get_edge_from_neighbors(a, b)?
            .fix()
            .as_undirected();
        self.cdt.remove_constraint_edge(undirected);
        let before = self.cdt.num_vertices();
        let v = match self.cdt.insert_with_hint(x, a) {
            Ok(v) if v.index() >= before => v,
            _ => {
                self.cdt.add_constraint(a, b);
                return None;
            }
        };
        let (pa, pb) = (self.cdt.vertex(a).position(), self.cdt.vertex(b).position());
        let crossed = self
            .cdt
            .vertex(v)
            .out_edges()
            .any(|e| e.is_constraint_edge())
            || !(self.cdt.can_add_constraint(a, v) && self.cdt.can_add_constraint(v, b));
        if crossed {
            // Back as it was: x out (with the segment it fell on, put back
            // whole), a–b constrained again, the sides found afresh.
            let ends: Vec<FixedVertexHandle> = self
                .cdt
                .vertex(v)
                .out_edges()
                .filter(|e| e.is_constraint_edge())
                .map(|e| e.to().fix())
                .collect();
            self.cdt.remove(v);
            self.forget_removed();
            if let [c, d] = ends[..] {
                self.cdt.add_constraint(c, d);
            }
            self.cdt.add_constraint(a, b);
            self.reflood();
            return None;
        }
        let clean = self.cdt.get_edge_from_neighbors(a, v).is_some()
            && self.cdt.get_edge_from_neighbors(v, b).is_some();
        self.cdt.add_constraint(a, v);
        self.cdt.add_constraint(v, b);
        self.sides_after_curve_split(a, b, v, pa, pb, clean, left, right);
        Some(v)
    }

    /// Gives the faces around a vertex v just put on a curve between a and
    /// b their sides: by the path a → v → b when every face that changes
    /// side touches v (the constraints went in without flips, and no vertex
    /// lies between the chord and the path), else by a new flood fill.
    #[allow(clippy::too_many_arguments)]
    fn sides_after_curve_split(
        &mut self,
        a: FixedVertexHandle,
        b: FixedVertexHandle,
        v: FixedVertexHandle,
        pa: Point2<f64>,
        pb: Point2<f64>,
        clean: bool,
        left: bool,
        right: bool,
    ) {
        let pv = self.cdt.vertex(v).position();
        let bulge = orient2d(coord(pa), coord(pb), coord(pv));
        // Going counter-clockwise from v→a to v→b sweeps the right of the
        // path; the chord lies there when v bulges to the left.
        let (from, to) = if bulge > 0.0 { (a, b) } else { (b, a) };
        let mut inside_sector = false;
        let mut stray = false;
        // Two turns: the sector may wrap past the first edge.
        let edges: Vec<(FixedVertexHandle, Point2<f64>)> = self
            .cdt
            .vertex(v)
            .out_edges()
            .map(|e| (e.to().fix(), e.to().position()))
            .collect();
        for &(w, pw) in edges.iter().chain(edges.iter()) {
            if w == from {
                inside_sector = true;
                continue;
            }
            if w == to {
                if inside_sector {
                    break;
                }
                continue;
            }
            if inside_sector {
                // w must lie beyond the chord, on the side away from v.
                let side = orient2d(coord(pa), coord(pb), coord(pw));
                stray |= bulge != 0.0 && side * bulge >= 0.0;
            }
        }
        if clean && !stray {
            self.after_insertion(v, Side::Split { a, b, left, right });
        } else {
            self.reflood();
            self.after_insertion(v, Side::Flooded);
        }
    }

    /// Recomputes which faces are outside from scratch.
    fn reflood(&mut self) {
        self.reflooded = true;
        self.outside = super::face::outside_faces(self.cdt, &[]);
        // Adding constraints may have flipped edges away from the new
        // point: every queued triangle is looked at again.
        for g in &mut self.generation {
            *g = g.wrapping_add(1);
        }
        self.generation.resize(self.cdt.num_all_faces(), 0);
        let faces: Vec<_> = self.cdt.fixed_inner_faces().collect();
        for f in faces {
            if !self.outside[f.index()] {
                self.push_triangle(f);
            }
        }
    }

    /// After inserting `v`: the faces around it take their side, are queued
    /// for the quality check, and the segments opposite `v` for
    /// encroachment.
    fn after_insertion(&mut self, v: FixedVertexHandle, side: Side) {
        self.grow_face_tables();
        let mut faces = std::mem::take(&mut self.around);
        let mut opposite = std::mem::take(&mut self.opposite);
        faces.clear();
        opposite.clear();
        // For a split segment a–b: going counter-clockwise around v, the
        // faces from v→b on are left of the path a → v → b, from v→a on
        // right of it (the chord may be off the path: a point on a curve).
        let mut left_of_path = match side {
            Side::Split { a, b, .. } => {
                self.cdt
                    .vertex(v)
                    .out_edges()
                    .map(|e| e.to().fix())
                    .find(|&w| w == a || w == b)
                    == Some(a)
            }
            _ => false,
        };
        let pv = self.cdt.vertex(v).position();
        for e in self.cdt.vertex(v).out_edges() {
            if let Side::Split { a, b, .. } = side {
                let to = e.to().fix();
                if to == b {
                    left_of_path = true;
                } else if to == a {
                    left_of_path = false;
                }
            }
            if let Some(f) = e.face().as_inner() {
                let status = match side {
                    Side::Inside { .. } => false,
                    Side::Flooded => self.outside[f.fix().index()],
                    Side::Split { left, right, .. } => {
                        if left_of_path {
                            left
                        } else {
                            right
                        }
                    }
                };
                // The face left of v → w runs v, w, then next's end
                // (counter-clockwise): its corners without a face lookup.
                let next = e.next();
                let corners = [pv, e.to().position(), next.to().position()];
                faces.push((f.fix(), corners, status));
                if next.is_constraint_edge() {
                    opposite.push((next.from().fix(), next.to().fix()));
                }
            }
        }
        for &(f, corners, status) in &faces {
            self.outside[f.index()] = status;
            self.generation[f.index()] = self.generation[f.index()].wrapping_add(1);
            if !status {
                self.push_triangle_at(f, corners);
            }
        }
        if !matches!(side, Side::Inside { checked: true }) {
            self.segments.extend(opposite.iter().copied());
        }
        self.around = faces;
        self.opposite = opposite;
    }
}

/// Which side of the boundary the faces around a new vertex are on.
#[derive(Clone, Copy)]
enum Side {
    /// A point inserted inside the loops; `checked` when the segments
    /// opposite it are known not to be encroached by it (nothing else
    /// around them changed, so they need no second look).
    Inside { checked: bool },
    /// A split segment a–b (its ends, joined to the new vertex by
    /// segments): whether its left and right sides are outside.
    Split {
        a: FixedVertexHandle,
        b: FixedVertexHandle,
        left: bool,
        right: bool,
    },
    /// Already known from a new flood fill.
    Flooded,
}

/// A queued bad triangle: its face and the slot's generation when queued.
type Queued = (FixedFaceHandle<InnerTag>, u32);

/// Triangle's bad-triangle queue: 4,096 FIFO buckets by the shortest edge's
/// squared length in factors of √2, shortest first. Push and pop take
/// constant time (a binary heap's pop was 40% of the refinement time at 1.5
/// million triangles).
struct BucketQueue {
    buckets: Vec<VecDeque<Queued>>,
    /// No bucket below this one holds anything.
    lowest: usize,
    len: usize,
}

const BUCKETS: usize = 4096;

impl BucketQueue {
    fn new() -> Self {
        BucketQueue {
            buckets: (0..BUCKETS).map(|_| VecDeque::new()).collect(),
            lowest: BUCKETS,
            len: 0,
        }
    }

    fn push(&mut self, shortest_squared: f64, item: Queued) {
        // 2·log2 of the squared length, from about −2,100 to 2,050 for
        // finite positive doubles, shifted into 0..4,096.
        let bucket = bucket_of(shortest_squared);
        self.buckets[bucket].push_back(item);
        self.lowest = self.lowest.min(bucket);
        self.len += 1;
    }

    fn pop(&mut self) -> Option<Queued> {
        if self.len == 0 {
            return None;
        }
        while self.lowest < BUCKETS {
            if let Some(item) = self.buckets[self.lowest].pop_front() {
                self.len -= 1;
                return Some(item);
            }
            self.lowest += 1;
        }
        None
    }
}

/// The bucket of a squared length x: ⌊2·log2 x⌋ + 2,048, clamped to the
/// buckets. Read off the bits of a normal x (x = 2^e·m, m in [1, 2):
/// ⌊2·log2 x⌋ = 2e, plus 1 when m ≥ √2) instead of calling `log2` and
/// `floor`, which were 2–3% of the refinement; subnormals and the rest
/// take the slow way.
fn bucket_of(x: f64) -> usize {
    if x.is_nan() || x <= 0.0 {
        return 0;
    }
    let bits = x.to_bits();
    let biased = ((bits >> 52) & 0x7ff) as i64;
    let k = if biased == 0 || biased == 0x7ff {
        (2.0 * x.log2()).floor()
    } else {
        let mantissa = f64::from_bits((bits & ((1u64 << 52) - 1)) | (1023u64 << 52));
        (2 * (biased - 1023) + i64::from(mantissa >= std::f64::consts::SQRT_2)) as f64
    };
    (k + 2048.0).clamp(0.0, (BUCKETS - 1) as f64) as usize
}

/// The squared edge lengths of a triangle (edge i from corner i to i + 1)
/// and the index of the shortest.
fn shortest_edge(p: [Point2<f64>; 3]) -> ([f64; 3], usize) {
    let d = |i: usize| {
        let (a, b) = (p[i], p[(i + 1) % 3]);
        (b.x - a.x) * (b.x - a.x) + (b.y - a.y) * (b.y - a.y)
    };
    let lengths = [d(0), d(1), d(2)];
    let k = (0..3)
        .min_by(|&i, &j| lengths[i].total_cmp(&lengths[j]))
        .unwrap_or(0);
    (lengths, k)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The bucket from the bits is the bucket from `log2`: powers of two,
    /// the √2 step between them, and lengths from 1e-300 to 1e300.
    #[test]
    fn bucket_from_bits_matches_log2() {
        let slow = |x: f64| ((2.0 * x.log2()).floor() + 2048.0).clamp(0.0, 4095.0) as usize;
        let mut x = 1e-300;
        while x < 1e300 {
            assert_eq!(bucket_of(x), slow(x), "{x:e}");
            x *= 1.0137;
        }
        assert_eq!(bucket_of(1.0), 2048);
        assert_eq!(bucket_of(2.0), 2050);
        assert_eq!(bucket_of(0.5), 2046);
        assert_eq!(bucket_of(std::f64::consts::SQRT_2), 2049);
        let below_sqrt2 = f64::from_bits(std::f64::consts::SQRT_2.to_bits() - 1);
        assert_eq!(bucket_of(below_sqrt2), 2048);
        assert_eq!(bucket_of(0.0), 0);
        assert_eq!(bucket_of(f64::NAN), 0);
        assert_eq!(bucket_of(5e-324), 0);
        assert_eq!(bucket_of(f64::INFINITY), 4095);
    }
}
