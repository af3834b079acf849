//! Analytic surfaces that carry faces.

use super::point_calculus::Patch9;
use super::{Frame, Point3, Vec3};
use crate::expr::{Expr, eval};
use crate::span::Span;

/// A surface S(p) = 0. `value` is negative on the side opposite the normal
/// (inside, for closed surfaces), so `gradient` points along the outward normal.
#[derive(Debug, Clone, PartialEq)]
pub enum Surface {
    /// Through `origin` with unit `normal`; value = normal · (p − origin).
    Plane { origin: Point3, normal: Vec3 },
    /// The unit sphere |q| = 1 in `frame` local coordinates: a sphere when the
    /// frame is a similarity, an ellipsoid otherwise. Local value |q|² − 1.
    Ellipsoid { frame: Frame },
    /// x² + y² = (r0 + (r1 − r0)·z)² in local coordinates, z unbounded; r0 = r1
    /// is a cylinder, r0 = 0 a cone with its apex at the local origin.
    /// Local value x² + y² − r(z)², made sign-correct where r(z) < 0.
    Cone { frame: Frame, r0: f64, r1: f64 },
    /// (√(x² + y²) − major)² + z² = minor² in local coordinates.
    Torus {
        frame: Frame,
        major: f64,
        minor: f64,
    },
    /// Global xx·x² + yy·y² + zz·z² + xy·xy + yz·yz + zx·zx + x·x + y·y + z·z + c,
    /// coefficients in that order.
    Quadric { coefficients: [f64; 10] },
    /// An expression in the free variables x, y, z (parameters already folded in).
    Implicit { expr: Expr },
    /// Paper 003's 9-point parabolic patch. Its value is the signed distance
    /// along the patch normal ∂M/∂u × ∂M/∂v from the nearest patch point.
    Patch9(Box<Patch9>),
    /// A trimmed parametric surface (issue 9). Its value is the signed
    /// distance along R_u × R_v from the nearest surface point; it is meshed
    /// by `crate::trimmed`, never through a chart.
    Parametric(Box<crate::trimmed::TrimmedSurface>),
}

impl Surface {
    /// The implicit value at a global point (sign convention above).
    pub fn value(&self, p: &Point3) -> f64 {
        self.value_and_gradient(p).0
    }

    /// The gradient of `value` at `p` (analytic where possible, else central differences).
    pub fn gradient(&self, p: &Point3) -> Vec3 {
        self.value_and_gradient(p).1
    }

    /// Distance from `p` to the surface: exact for planes and spheres, the
    /// first-order estimate |value| / |gradient| otherwise.
    pub fn distance(&self, p: &Point3) -> f64 {
        match self {
            Surface::Plane { origin, normal } => {
                first_order_distance(normal.dot(&(p - origin)), normal.norm())
            }
            Surface::Ellipsoid { frame } => match frame.similarity_scale() {
                Some(radius) => ((p - frame.origin).norm() - radius).abs(),
                None => {
                    let (v, g) = self.value_and_gradient(p);
                    first_order_distance(v, g.norm())
                }
            },
            _ => {
                let (v, g) = self.value_and_gradient(p);
                first_order_distance(v, g.norm())
            }
        }
    }

    /// The nearest point on the surface found by Newton steps along the
    /// gradient from `p`; `None` if it does not converge.
    pub fn project(&self, p: &Point3) -> Option<Point3> {
        if !p.coords.iter().all(|c| c.is_finite()) {
            return None;
        }
        match self {
            Surface::Plane { origin, normal } => {
                let n2 = normal.norm_squared();
                let out = p - normal * (normal.dot(&(p - origin)) / n2);
                (n2 > 0.0 && out.coords.iter().all(|c| c.is_finite())).then_some(out)
            }
            Surface::Ellipsoid { frame } => match frame.similarity_scale() {
                Some(radius) => {
                    let d = p - frame.origin;
                    let len = d.norm();
                    (len > 0.0).then(|| frame.origin + d * (radius / len))
                }
                None => self.newton_project(p),
            },
            Surface::Patch9(patch) => patch.project(p).map(|(_, q)| q),
            Surface::Parametric(s) => s.project(p).map(|(q, _)| q),
            _ => self.newton_project(p),
        }
    }

    /// True for surfaces with no boundary that enclose a finite volume.
    pub fn is_closed(&self) -> bool {
        matches!(self, Surface::Ellipsoid { .. } | Surface::Torus { .. })
    }

    /// Value and global gradient together, sharing the frame inversion.
    /// Singular frames and failed expressions give NaN.
    pub fn value_and_gradient(&self, p: &Point3) -> (f64, Vec3) {
        let nan = (f64::NAN, Vec3::repeat(f64::NAN));
        match self {
            Surface::Plane { origin, normal } => (normal.dot(&(p - origin)), *normal),
            Surface::Ellipsoid { frame }
            | Surface::Cone { frame, .. }
            | Surface::Torus { frame, .. } => {
                let Some(inv) = frame.inverse() else {
                    return nan;
                };
                let q = inv * (p - frame.origin);
                let (v, g) = self.local_value_and_gradient(&q);
                // Chain rule: ∇_p f = L⁻ᵀ ∇_q f.
                (v, inv.transpose() * g)
            }
            Surface::Quadric { coefficients } => quadric(coefficients, p),
            Surface::Implicit { expr } => {
                let v = implicit_value(expr, p);
                if v.is_nan() {
                    return nan;
                }
                let h = 1e-6 * (1.0 + p.coords.amax());
                let mut g = Vec3::zeros();
                for i in 0..3 {
                    let mut e = Vec3::zeros();
                    e[i] = h;
                    g[i] = (implicit_value(expr, &(p + e)) - implicit_value(expr, &(p - e)))
                        / (2.0 * h);
                }
                (v, g)
            }
            Surface::Patch9(patch) => match patch.project(p) {
                Some((uv, q)) => {
                    let n = patch.normal(uv[0], uv[1]);
                    (n.dot(&(p - q)), n)
                }
                None => nan,
            },
            Surface::Parametric(s) => match s.project(p) {
                Some((q, n)) => (n.dot(&(p - q)), n),
                None => nan,
            },
        }
    }

    /// Local value and local gradient of the frame-based surfaces.
    fn local_value_and_gradient(&self, q: &Vec3) -> (f64, Vec3) {
        let (x, y, z) = (q.x, q.y, q.z);
        match *self {
            Surface::Ellipsoid { .. } => (q.norm_squared() - 1.0, q * 2.0),
            Surface::Cone { r0, r1, .. } => {
                // r·|r| instead of r² keeps the mirrored nappe beyond the apex
                // (r < 0) outside instead of counting it as a second inside.
                let r = r0 + (r1 - r0) * z;
                let v = x * x + y * y - r * r.abs();
                (v, Vec3::new(2.0 * x, 2.0 * y, -2.0 * r.abs() * (r1 - r0)))
            }
            Surface::Torus { major, minor, .. } => {
                let rho = x.hypot(y);
                let v = (rho - major).powi(2) + z * z - minor * minor;
                let radial = if rho > 0.0 {
                    2.0 * (rho - major) / rho
                } else {
                    0.0
                };
                (v, Vec3::new(radial * x, radial * y, 2.0 * z))
            }
            _ => (f64::NAN, Vec3::repeat(f64::NAN)),
        }
    }

    /// Newton iteration p ← p − f ∇f / |∇f|² towards the zero set.
    fn newton_project(&self, p: &Point3) -> Option<Point3> {
        let scale = 1.0 + p.coords.amax();
        let mut x = *p;
        let mut last_step = f64::INFINITY;
        for _ in 0..50 {
            let (v, g) = self.value_and_gradient(&x);
            let g2 = g.norm_squared();
            if !v.is_finite() || !g2.is_finite() || g2 <= 0.0 {
                return None;
            }
            let step = g * (v / g2);
            x -= step;
            last_step = step.norm();
            if !x.coords.iter().all(|c| c.is_finite()) || (x - p).norm() > 1e12 * scale {
                return None;
            }
            if last_step <= 1e-13 * scale {
                return Some(x);
            }
        }
        (last_step <= 1e-9 * scale).then_some(x)
    }
}

/// |value| / |gradient| with the degenerate cases made explicit: a point with
/// zero value is on the surface; otherwise an unusable gradient means "far".
fn first_order_distance(value: f64, gradient_norm: f64) -> f64 {
    if value == 0.0 {
        0.0
    } else if value.is_finite() && gradient_norm.is_finite() && gradient_norm > 0.0 {
        value.abs() / gradient_norm
    } else {
        f64::INFINITY
    }
}

/// The general quadric in global coordinates and its analytic gradient.
fn quadric(c: &[f64; 10], p: &Point3) -> (f64, Vec3) {
    let (x, y, z) = (p.x, p.y, p.z);
    let [xx, yy, zz, xy, yz, zx, cx, cy, cz, c0] = *c;
    let v = xx * x * x
        + yy * y * y
        + zz * z * z
        + xy * x * y
        + yz * y * z
        + zx * z * x
        + cx * x
        + cy * y
        + cz * z
        + c0;
    let g = Vec3::new(
        2.0 * xx * x + xy * y + zx * z + cx,
        2.0 * yy * y + xy * x + yz * z + cy,
        2.0 * zz * z + yz * y + zx * x + cz,
    );
    (v, g)
}

/// Evaluates the expression at `p`; unknown names, errors and non-finite
/// results all become NaN so callers can reject the point without panicking.
fn implicit_value(expr: &Expr, p: &Point3) -> f64 {
    let mut lookup = |name: &str, _: Span| match name {
        "x" => Some(p.x),
        "y" => Some(p.y),
        "z" => Some(p.z),
        _ => None,
    };
    match eval(expr, &mut lookup) {
        Ok(v) if v.is_finite() => v,
        _ => f64::NAN,
    }
}
