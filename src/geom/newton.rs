//! Newton's method for vertices given as intersections, and the projection
//! onto the intersection of two surfaces that curve tracing relies on.

use super::{Curve, Mat3, Point3, Surface, Vec3};

/// The intersection point of three surfaces nearest the hint, or `None` when
/// Newton's method does not converge to a point within `tol` of all three
/// (singular Jacobian, divergence, or more than 50 iterations).
pub fn intersect_surfaces(surfaces: [&Surface; 3], near: Point3, tol: f64) -> Option<Point3> {
    if !is_finite(&near) {
        return None;
    }
    let scale = 1.0 + near.coords.amax();
    let mut x = near;
    for _ in 0..50 {
        // Rows normalised by |∇f| so the residuals are distances and the
        // determinant measures how transversal the three surfaces are.
        let mut jac = Mat3::zeros();
        let mut f = Vec3::zeros();
        for (i, s) in surfaces.iter().enumerate() {
            let (v, g) = s.value_and_gradient(&x);
            let len = g.norm();
            if !v.is_finite() || !len.is_finite() || len <= 0.0 {
                return None;
            }
            f[i] = v / len;
            jac.set_row(i, &(g / len).transpose());
        }
        if f.amax() <= 1e-15 * scale {
            break;
        }
        if jac.determinant().abs() < 1e-12 {
            return None;
        }
        let step = jac.lu().solve(&(-f))?;
        x += step;
        if !is_finite(&x) || (x - near).norm() > 1e8 * scale {
            return None;
        }
        if step.norm() <= 1e-14 * scale {
            break;
        }
    }
    surfaces.iter().all(|s| s.distance(&x) <= tol).then_some(x)
}

/// The point where two curves meet (their carriers, unbounded in parameter)
/// nearest the hint, or `None` if their closest points stay farther apart than `tol`.
pub fn intersect_curves(a: &Curve, b: &Curve, near: Point3, tol: f64) -> Option<Point3> {
    if !is_finite(&near) {
        return None;
    }
    let scale = 1.0 + near.coords.amax();
    let (mut x, mut ta) = a.carrier_project(&near)?;
    let (mut y, mut tb) = b.carrier_project(&near)?;
    // Gauss–Newton on the tangent lines: minimise |x + α ta − y − β tb| and
    // project the moved points back onto their carriers.
    for _ in 0..50 {
        let d = y - x;
        let c = ta.dot(&tb);
        let det = 1.0 - c * c;
        let (nx, ny) = if det > 1e-12 {
            let (ra, rb) = (ta.dot(&d), tb.dot(&d));
            let alpha = (ra - c * rb) / det;
            let beta = (c * ra - rb) / det;
            (x + ta * alpha, y + tb * beta)
        } else {
            // Parallel tangents: alternate projections instead.
            (y, x)
        };
        let (x2, ta2) = a.carrier_project(&nx)?;
        let (y2, tb2) = b.carrier_project(&ny)?;
        let moved = (x2 - x).norm().max((y2 - y).norm());
        (x, ta, y, tb) = (x2, ta2, y2, tb2);
        if moved <= 1e-14 * scale {
            break;
        }
    }
    ((x - y).norm() <= tol).then(|| nalgebra::center(&x, &y))
}

/// Moves `p` onto the intersection of two surfaces by Newton steps of minimum
/// norm on the 2×3 system; near-tangent surfaces fall back to projecting onto
/// the one with the larger residual. `None` when it does not converge.
pub(super) fn project_onto_pair(surfaces: [&Surface; 2], p: &Point3) -> Option<Point3> {
    if !is_finite(p) {
        return None;
    }
    let scale = 1.0 + p.coords.amax();
    let mut x = *p;
    for _ in 0..50 {
        let (v1, g1) = surfaces[0].value_and_gradient(&x);
        let (v2, g2) = surfaces[1].value_and_gradient(&x);
        let (a, b, c) = (g1.norm_squared(), g1.dot(&g2), g2.norm_squared());
        if ![v1, v2, a, b, c].iter().all(|v| v.is_finite()) || a <= 0.0 || c <= 0.0 {
            return None;
        }
        let det = a * c - b * b;
        let step = if det > 1e-10 * a * c {
            let l1 = (c * v1 - b * v2) / det;
            let l2 = (a * v2 - b * v1) / det;
            -(g1 * l1 + g2 * l2)
        } else if v1 * v1 / a >= v2 * v2 / c {
            -g1 * (v1 / a)
        } else {
            -g2 * (v2 / c)
        };
        x += step;
        if !is_finite(&x) || (x - p).norm() > 1e8 * scale {
            return None;
        }
        if step.norm() <= 1e-13 * scale {
            return Some(x);
        }
    }
    let on = surfaces.iter().all(|s| s.distance(&x) <= 1e-9 * scale);
    on.then_some(x)
}

pub(super) fn is_finite(p: &Point3) -> bool {
    p.coords.iter().all(|c| c.is_finite())
}
