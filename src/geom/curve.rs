//! Curves that carry edges. Each curve is parametrised over s ∈ [0, 1] from
//! the edge's begin vertex to its end vertex.

use super::newton::project_onto_pair;
use super::point_calculus::PcCurve;
use super::trace::{polyline_at, trace};
use super::{Point3, Surface, Vec3};
use crate::implicit::tape::Ssa;
use std::f64::consts::TAU;

#[derive(Debug, Clone, PartialEq)]
pub enum Curve {
    /// The straight segment a → b.
    Segment { a: Point3, b: Point3 },
    /// center + major·cos t + minor·sin t for t from t0 to t1 (t1 > t0; a closed
    /// curve has t1 = t0 + 2π). Circles have |major| = |minor| and major ⊥ minor.
    Ellipse {
        center: Point3,
        major: Vec3,
        minor: Vec3,
        t0: f64,
        t1: f64,
    },
    /// The intersection curve of two surfaces, traced from a to b.
    Intersection {
        surfaces: Box<[Surface; 2]>,
        a: Point3,
        b: Point3,
    },
    /// A curve of paper 003's point calculus (segment, conic, Desargues or
    /// parabolic arc), over its own u = s.
    PointCalculus(Box<PcCurve>),
    /// A boundary chain of a trimmed parametric surface (issue 9: a trim
    /// curve or a patch side), sampled at the model tolerance; its mesh nodes
    /// come from the surface's own meshing, not from this polyline.
    Chain { points: Vec<Point3> },
    /// A piece a → b of a 2D R-function region's contour f(x, y) = 0 (a
    /// marching-squares segment): its points lie on the contour where it
    /// crosses the chord's normal, so a split by refinement lands on the
    /// true curve, not on the chord.
    Contour { a: Point3, b: Point3, f: Box<Ssa> },
}

impl Curve {
    /// The point at normalised parameter s ∈ [0, 1]. For `Intersection`, the
    /// point found by marching along the curve (linear interpolation of a and b
    /// projected onto both surfaces as a fallback).
    pub fn point(&self, s: f64) -> Point3 {
        match self {
            Curve::Segment { a, b } => a + (b - a) * s,
            Curve::Ellipse {
                center,
                major,
                minor,
                t0,
                t1,
            } => ellipse_point(center, major, minor, t0 + (t1 - t0) * s),
            Curve::Intersection { surfaces, a, b } => {
                if s <= 0.0 || s.is_nan() {
                    *a
                } else if s >= 1.0 {
                    *b
                } else {
                    let line = trace(surfaces, a, b);
                    self.on_curve(polyline_at(&line, s).0)
                }
            }
            Curve::PointCalculus(c) => c.point(s),
            Curve::Chain { points } => polyline_at(points, s).0,
            Curve::Contour { a, b, f } => contour_point(a, b, f, s),
        }
    }

    /// `n + 1` points at s = 0, 1/n, …, 1 (n ≥ 1).
    pub fn samples(&self, n: usize) -> Vec<Point3> {
        let n = n.max(1);
        match self {
            Curve::Intersection { surfaces, a, b } => {
                // Trace once and resample, rather than tracing per point.
                let line = trace(surfaces, a, b);
                (0..=n)
                    .map(|i| match i {
                        0 => *a,
                        i if i == n => *b,
                        i => self.on_curve(polyline_at(&line, i as f64 / n as f64).0),
                    })
                    .collect()
            }
            _ => (0..=n).map(|i| self.point(i as f64 / n as f64)).collect(),
        }
    }

    /// The unit tangent at s, in the direction of increasing s.
    pub fn tangent(&self, s: f64) -> Vec3 {
        match self {
            Curve::Segment { a, b } | Curve::Contour { a, b, .. } => unit(b - a),
            Curve::Ellipse {
                major,
                minor,
                t0,
                t1,
                ..
            } => {
                let t = t0 + (t1 - t0) * s;
                unit((minor * t.cos() - major * t.sin()) * (t1 - t0).signum())
            }
            Curve::Intersection { surfaces, a, b } => {
                let line = trace(surfaces, a, b);
                let (p, direction) = polyline_at(&line, s.clamp(0.0, 1.0));
                let p = self.on_curve(p);
                let exact = surfaces[0].gradient(&p).cross(&surfaces[1].gradient(&p));
                let oriented = if exact.dot(&direction) < 0.0 {
                    -exact
                } else {
                    exact
                };
                let t = unit(oriented);
                if t.norm() > 0.0 { t } else { unit(direction) }
            }
            Curve::PointCalculus(c) => c.tangent(s),
            Curve::Chain { points } => unit(polyline_at(points, s.clamp(0.0, 1.0)).1),
        }
    }

    pub fn is_closed(&self) -> bool {
        match self {
            Curve::Segment { .. } | Curve::Contour { .. } => false,
            Curve::Ellipse { t0, t1, .. } => (t1 - t0).abs() >= TAU * (1.0 - 1e-12),
            Curve::Intersection { a, b, .. } => same_point(a, b),
            Curve::PointCalculus(c) => same_point(&c.begin(), &c.end()),
            Curve::Chain { points } => {
                points.len() > 2 && same_point(&points[0], &points[points.len() - 1])
            }
        }
    }

    /// Distance from `p` to the curve (to its carrier line, circle or ellipse,
    /// unbounded in parameter), used to check that a vertex lies on a line.
    pub fn distance_to_carrier(&self, p: &Point3) -> f64 {
        match self {
            Curve::Ellipse {
                center,
                major,
                minor,
                ..
            } if is_circle(major, minor) => {
                let normal = unit(major.cross(minor));
                let d = p - center;
                let off = d.dot(&normal);
                let radial = (d - normal * off).norm();
                off.hypot(radial - major.norm())
            }
            Curve::Intersection { surfaces, .. } => {
                match project_onto_pair([&surfaces[0], &surfaces[1]], p) {
                    Some(q) => (p - q).norm(),
                    None => surfaces[0].distance(p).max(surfaces[1].distance(p)),
                }
            }
            _ => match self.carrier_project(p) {
                Some((q, _)) => (p - q).norm(),
                None => f64::INFINITY,
            },
        }
    }

    /// The length, exact for segments and circles, by quadrature otherwise.
    pub fn length(&self) -> f64 {
        match self {
            // A contour piece is within half the chordal tolerance of its chord.
            Curve::Segment { a, b } | Curve::Contour { a, b, .. } => (b - a).norm(),
            Curve::Ellipse {
                major,
                minor,
                t0,
                t1,
                ..
            } => {
                if is_circle(major, minor) {
                    return major.norm() * (t1 - t0).abs();
                }
                // Composite Simpson on the smooth, periodic speed |E'(t)|.
                let n = 1024;
                let h = (t1 - t0) / n as f64;
                let speed = |t: f64| (minor * t.cos() - major * t.sin()).norm();
                let inner: f64 = (1..n)
                    .map(|i| speed(t0 + h * i as f64) * if i % 2 == 1 { 4.0 } else { 2.0 })
                    .sum();
                ((speed(*t0) + speed(*t1) + inner) * h / 3.0).abs()
            }
            Curve::Intersection { .. } => {
                let points = self.samples(512);
                points.windows(2).map(|w| (w[1] - w[0]).norm()).sum()
            }
            Curve::PointCalculus(c) => c.length(),
            Curve::Chain { points } => points.windows(2).map(|w| (w[1] - w[0]).norm()).sum(),
        }
    }

    /// The nearest point of the (unbounded) carrier to `p` with the unit
    /// tangent there; the building block of [`super::intersect_curves`].
    pub(super) fn carrier_project(&self, p: &Point3) -> Option<(Point3, Vec3)> {
        match self {
            Curve::Segment { a, b } | Curve::Contour { a, b, .. } => {
                let d = b - a;
                let len2 = d.norm_squared();
                if len2 <= 0.0 || !len2.is_finite() {
                    return None;
                }
                Some((a + d * ((p - a).dot(&d) / len2), d / len2.sqrt()))
            }
            Curve::Ellipse {
                center,
                major,
                minor,
                ..
            } => {
                let t = nearest_angle(center, major, minor, p)?;
                let tangent = unit(minor * t.cos() - major * t.sin());
                (tangent.norm() > 0.0).then(|| (ellipse_point(center, major, minor, t), tangent))
            }
            Curve::Intersection { surfaces, .. } => {
                let q = project_onto_pair([&surfaces[0], &surfaces[1]], p)?;
                let t = unit(surfaces[0].gradient(&q).cross(&surfaces[1].gradient(&q)));
                (t.norm() > 0.0).then_some((q, t))
            }
            Curve::PointCalculus(c) => {
                let (u, q) = c.project(p)?;
                let t = c.tangent(u);
                (t.norm() > 0.0).then_some((q, t))
            }
            Curve::Chain { points } => nearest_on_polyline(points, p),
        }
    }

    /// Projects a point near an intersection curve back onto it, keeping the
    /// point itself when the projection fails.
    fn on_curve(&self, p: Point3) -> Point3 {
        match self {
            Curve::Intersection { surfaces, .. } => {
                project_onto_pair([&surfaces[0], &surfaces[1]], &p).unwrap_or(p)
            }
            _ => p,
        }
    }
}

/// The point of f = 0 on the normal to the chord a → b through its point
/// at s: the sign change nearest the chord, searched in steps doubling up to
/// half the chord's length either side, then Illinois steps. The chord point
/// itself when f has no sign change there (or is not finite).
fn contour_point(a: &Point3, b: &Point3, f: &Ssa, s: f64) -> Point3 {
    let c = a + (b - a) * s.clamp(0.0, 1.0);
    let d = b - a;
    let length = d.norm();
    if s <= 0.0 || s >= 1.0 || length.is_nan() || length <= 0.0 {
        return c;
    }
    let normal = Vec3::new(-d.y, d.x, 0.0) / length;
    let g = |t: f64| {
        let p = c + normal * t;
        f.eval_point([p.x, p.y, p.z])
    };
    let g0 = g(0.0);
    if g0 == 0.0 || !g0.is_finite() {
        return c;
    }
    let mut step = 1e-3 * length;
    while step <= 0.5 * length {
        for t in [step, -step] {
            let gt = g(t);
            if gt.is_finite() && (gt > 0.0) != (g0 > 0.0) {
                return c + normal * illinois(&g, (0.0, g0), (t, gt), 1e-14 * length);
            }
        }
        step *= 2.0;
    }
    c
}

/// A root of g between x0 and x1, where g changes sign (Illinois variant
/// of regula falsi: halves the stale end's value so both ends move).
fn illinois(
    g: &dyn Fn(f64) -> f64,
    (mut x0, mut g0): (f64, f64),
    (mut x1, mut g1): (f64, f64),
    tolerance: f64,
) -> f64 {
    let mut side = 0;
    for _ in 0..100 {
        let x = (x0 * g1 - x1 * g0) / (g1 - g0);
        if !x.is_finite() {
            break;
        }
        let gx = g(x);
        if gx == 0.0 || (x1 - x0).abs() <= tolerance {
            return x;
        }
        if (gx > 0.0) == (g1 > 0.0) {
            (x1, g1) = (x, gx);
            if side == 1 {
                g0 *= 0.5;
            }
            side = 1;
        } else {
            (x0, g0) = (x, gx);
            if side == -1 {
                g1 *= 0.5;
            }
            side = -1;
        }
    }
    0.5 * (x0 + x1)
}

fn ellipse_point(center: &Point3, major: &Vec3, minor: &Vec3, t: f64) -> Point3 {
    ellipse_point_trig(center, major, minor, (t.cos(), t.sin()))
}

/// [`Curve::point`]'s ellipse point at the angle whose cosine and sine are
/// given (for callers that computed them once for many ellipses).
pub(crate) fn ellipse_point_trig(
    center: &Point3,
    major: &Vec3,
    minor: &Vec3,
    (cos, sin): (f64, f64),
) -> Point3 {
    center + major * cos + minor * sin
}

/// The angle of the point of the full ellipse nearest `p`: the best of a
/// coarse scan, refined by golden-section search in its bracket.
fn nearest_angle(center: &Point3, major: &Vec3, minor: &Vec3, p: &Point3) -> Option<f64> {
    let dist2 = |t: f64| (ellipse_point(center, major, minor, t) - p).norm_squared();
    let n = 64;
    let step = TAU / n as f64;
    let (mut best, mut best_d) = (0.0, f64::INFINITY);
    for i in 0..n {
        let t = step * i as f64;
        let d = dist2(t);
        if d < best_d {
            (best, best_d) = (t, d);
        }
    }
    if !best_d.is_finite() {
        return None;
    }
    let ratio = (5f64.sqrt() - 1.0) / 2.0;
    let (mut lo, mut hi) = (best - step, best + step);
    let mut c = hi - ratio * (hi - lo);
    let mut d = lo + ratio * (hi - lo);
    let (mut fc, mut fd) = (dist2(c), dist2(d));
    for _ in 0..80 {
        if fc < fd {
            (hi, d, fd) = (d, c, fc);
            c = hi - ratio * (hi - lo);
            fc = dist2(c);
        } else {
            (lo, c, fc) = (c, d, fd);
            d = lo + ratio * (hi - lo);
            fd = dist2(d);
        }
    }
    Some((lo + hi) / 2.0)
}

/// |major| = |minor| and major ⊥ minor, to a relative 1e-12.
fn is_circle(major: &Vec3, minor: &Vec3) -> bool {
    let (a, b) = (major.norm(), minor.norm());
    a > 0.0 && (a - b).abs() <= 1e-12 * a && major.dot(minor).abs() <= 1e-12 * a * b
}

fn same_point(a: &Point3, b: &Point3) -> bool {
    (a - b).norm() <= 1e-12 * (1.0 + a.coords.amax().max(b.coords.amax()))
}

/// `v / |v|`, or the zero vector when `v` has no direction.
fn unit(v: Vec3) -> Vec3 {
    let len = v.norm();
    if len > 0.0 && len.is_finite() {
        v / len
    } else {
        Vec3::zeros()
    }
}

/// The point of a polyline nearest `p` with the unit direction of its segment.
fn nearest_on_polyline(line: &[Point3], p: &Point3) -> Option<(Point3, Vec3)> {
    let mut best: Option<(f64, Point3, Vec3)> = None;
    for w in line.windows(2) {
        let d = w[1] - w[0];
        let len2 = d.norm_squared();
        if len2 <= 0.0 {
            continue;
        }
        let t = ((p - w[0]).dot(&d) / len2).clamp(0.0, 1.0);
        let q = w[0] + d * t;
        let dist = (q - p).norm_squared();
        if best.as_ref().is_none_or(|b| dist < b.0) {
            best = Some((dist, q, unit(d)));
        }
    }
    best.map(|(_, q, t)| (q, t))
}
