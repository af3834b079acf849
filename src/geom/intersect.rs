//! How the boundaries of two solids relate: disjoint, nested, touching on
//! shared faces, or crossing (which the boundary-representation path cannot
//! combine and reports).

use super::shape_eval::ShapeEval;
use super::{Point3, SolidShape, Vec3};

/// Where the boundary samples of one solid lie relative to another solid.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Coverage {
    /// Samples strictly inside the other solid (value > tol).
    pub inside: usize,
    /// Samples strictly outside (value < −tol).
    pub outside: usize,
    /// Samples on the other solid's boundary (|value| ≤ tol).
    pub on: usize,
    /// When both inside and outside samples occur: a point near where the
    /// boundary crosses, refined by bisection between an inside and an outside
    /// sample that are neighbours.
    pub crossing_near: Option<Point3>,
}

impl Coverage {
    pub fn crosses(&self) -> bool {
        self.inside > 0 && self.outside > 0
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BoundaryRelation {
    /// ∂a against b.
    pub a_in_b: Coverage,
    /// ∂b against a.
    pub b_in_a: Coverage,
}

/// Classifies the boundary samples of each solid against the other, with a
/// bounding-box shortcut for solids far apart (then every sample is outside
/// and no sampling is done: both coverages report `outside = 1`).
/// `tol` is the absolute geometric tolerance.
pub fn boundary_relation(a: &SolidShape, b: &SolidShape, tol: f64) -> BoundaryRelation {
    let tol = if tol.is_finite() { tol.abs() } else { 0.0 };
    if !a.bbox().overlaps(&b.bbox(), tol) {
        let far = Coverage {
            outside: 1,
            ..Coverage::default()
        };
        return BoundaryRelation {
            a_in_b: far,
            b_in_a: far,
        };
    }
    let (ea, eb) = (ShapeEval::new(a), ShapeEval::new(b));
    BoundaryRelation {
        a_in_b: coverage(&a.boundary_samples(SAMPLE_DENSITY), &ea, &eb, tol),
        b_in_a: coverage(&b.boundary_samples(SAMPLE_DENSITY), &eb, &ea, tol),
    }
}

/// Samples per parametric direction of each face.
const SAMPLE_DENSITY: usize = 48;

#[derive(Clone, Copy, PartialEq)]
enum Class {
    Inside,
    Outside,
    On,
}

/// Where the boundary samples of `own` lie relative to `other`. NaN values
/// count as outside.
fn coverage(samples: &[Point3], own: &ShapeEval, other: &ShapeEval, tol: f64) -> Coverage {
    let mut cov = Coverage::default();
    let classes: Vec<Class> = samples
        .iter()
        .map(|p| {
            let v = other.value(p);
            if v > tol {
                cov.inside += 1;
                Class::Inside
            } else if v >= -tol {
                cov.on += 1;
                Class::On
            } else {
                cov.outside += 1;
                Class::Outside
            }
        })
        .collect();
    if cov.crosses() {
        cov.crossing_near = closest_mixed_pair(samples, &classes)
            .map(|(inside, outside)| locate_crossing(&inside, &outside, own, other));
    }
    cov
}

/// An inside and an outside sample close to each other: the closest
/// consecutive pair (samples come in rows, so these are neighbours), else the
/// closest pair between a few inside samples and all outside ones.
fn closest_mixed_pair(samples: &[Point3], classes: &[Class]) -> Option<(Point3, Point3)> {
    let mut best = None;
    for i in 1..samples.len() {
        match (classes[i - 1], classes[i]) {
            (Class::Inside, Class::Outside) => consider(&mut best, samples[i - 1], samples[i]),
            (Class::Outside, Class::Inside) => consider(&mut best, samples[i], samples[i - 1]),
            _ => {}
        }
    }
    if best.is_none() {
        let of = |class: Class| (0..samples.len()).filter(move |&i| classes[i] == class);
        let inside: Vec<usize> = of(Class::Inside).collect();
        let stride = (inside.len() / 16).max(1);
        for &i in inside.iter().step_by(stride) {
            for j in of(Class::Outside) {
                consider(&mut best, samples[i], samples[j]);
            }
        }
    }
    best.map(|(_, inside, outside)| (inside, outside))
}

/// Keeps the closer of `best` and the pair (inside, outside).
fn consider(best: &mut Option<(f64, Point3, Point3)>, inside: Point3, outside: Point3) {
    let d = (inside - outside).norm_squared();
    if best.is_none_or(|(bd, _, _)| d < bd) {
        *best = Some((d, inside, outside));
    }
}

/// Bisects the segment inside → outside on `other`'s value, then pulls the
/// result onto both boundaries (the segment is a chord of `own`'s boundary)
/// when a few Newton steps manage that without wandering off.
fn locate_crossing(
    inside: &Point3,
    outside: &Point3,
    own: &ShapeEval,
    other: &ShapeEval,
) -> Point3 {
    let (mut lo, mut hi) = (*inside, *outside);
    for _ in 0..64 {
        let mid = nalgebra::center(&lo, &hi);
        if other.value(&mid) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
        if (hi - lo).norm() <= 1e-15 * (1.0 + lo.coords.amax()) {
            break;
        }
    }
    let mid = nalgebra::center(&lo, &hi);
    let reach = 2.0 * (inside - outside).norm();
    match refine_on_both(&mid, own, other) {
        Some(p) if (p - mid).norm() <= reach => p,
        _ => mid,
    }
}

/// Minimum-norm Newton steps on (own, other) = (0, 0) with central-difference
/// gradients; `None` unless both values end up negligible.
fn refine_on_both(start: &Point3, own: &ShapeEval, other: &ShapeEval) -> Option<Point3> {
    let scale = 1.0 + start.coords.amax();
    let h = 1e-7 * scale;
    let grad = |e: &ShapeEval, p: &Point3| {
        Vec3::from_fn(|i, _| {
            let mut d = Vec3::zeros();
            d[i] = h;
            (e.value(&(p + d)) - e.value(&(p - d))) / (2.0 * h)
        })
    };
    let mut x = *start;
    for _ in 0..20 {
        let (v1, v2) = (own.value(&x), other.value(&x));
        if !v1.is_finite() || !v2.is_finite() {
            return None;
        }
        if v1.abs().max(v2.abs()) <= 1e-13 * scale {
            return Some(x);
        }
        let (g1, g2) = (grad(own, &x), grad(other, &x));
        let (a, b, c) = (g1.norm_squared(), g1.dot(&g2), g2.norm_squared());
        let det = a * c - b * b;
        if !det.is_finite() || det <= 1e-10 * a * c {
            return None;
        }
        let l1 = (c * v1 - b * v2) / det;
        let l2 = (a * v2 - b * v1) / det;
        x -= g1 * l1 + g2 * l2;
    }
    let (v1, v2) = (own.value(&x), other.value(&x));
    (v1.abs().max(v2.abs()) <= 1e-10 * scale).then_some(x)
}
