//! Newton's method for vertices given as intersections.

use super::{Curve, Point3, Surface};

/// The intersection point of three surfaces nearest the hint, or `None` when
/// Newton's method does not converge to a point within `tol` of all three
/// (singular Jacobian, divergence, or more than 50 iterations).
pub fn intersect_surfaces(surfaces: [&Surface; 3], near: Point3, tol: f64) -> Option<Point3> {
    let _ = (surfaces, near, tol);
    todo!("geom kernel")
}

/// The point where two curves meet (their carriers, unbounded in parameter)
/// nearest the hint, or `None` if their closest points stay farther apart than `tol`.
pub fn intersect_curves(a: &Curve, b: &Curve, near: Point3, tol: f64) -> Option<Point3> {
    let _ = (a, b, near, tol);
    todo!("geom kernel")
}
