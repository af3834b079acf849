//! Curves that carry edges. Each curve is parametrised over s ∈ [0, 1] from
//! the edge's begin vertex to its end vertex.

use super::{Point3, Surface, Vec3};

#[derive(Debug, Clone, PartialEq)]
pub enum Curve {
    /// The straight segment a → b.
    Segment { a: Point3, b: Point3 },
    /// center + major·cos t + minor·sin t for t from t0 to t1 (t1 > t0; a closed
    /// curve has t1 = t0 + 2π). Circles have |major| = |minor| and major ⊥ minor.
    Ellipse { center: Point3, major: Vec3, minor: Vec3, t0: f64, t1: f64 },
    /// The intersection curve of two surfaces, traced from a to b.
    Intersection { surfaces: Box<[Surface; 2]>, a: Point3, b: Point3 },
}

impl Curve {
    /// The point at normalised parameter s ∈ [0, 1]. For `Intersection`, the
    /// point found by marching along the curve (linear interpolation of a and b
    /// projected onto both surfaces as a fallback).
    pub fn point(&self, s: f64) -> Point3 {
        let _ = s;
        todo!("geom kernel")
    }

    /// `n + 1` points at s = 0, 1/n, …, 1 (n ≥ 1).
    pub fn samples(&self, n: usize) -> Vec<Point3> {
        let _ = n;
        todo!("geom kernel")
    }

    /// The unit tangent at s, in the direction of increasing s.
    pub fn tangent(&self, s: f64) -> Vec3 {
        let _ = s;
        todo!("geom kernel")
    }

    pub fn is_closed(&self) -> bool {
        todo!("geom kernel")
    }

    /// Distance from `p` to the curve (to its carrier line, circle or ellipse,
    /// unbounded in parameter), used to check that a vertex lies on a line.
    pub fn distance_to_carrier(&self, p: &Point3) -> f64 {
        let _ = p;
        todo!("geom kernel")
    }

    /// The length, exact for segments and circles, by quadrature otherwise.
    pub fn length(&self) -> f64 {
        todo!("geom kernel")
    }
}
