//! Analytic surfaces that carry faces.

use super::{Frame, Point3, Vec3};
use crate::expr::Expr;

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
    Torus { frame: Frame, major: f64, minor: f64 },
    /// Global xx·x² + yy·y² + zz·z² + xy·xy + yz·yz + zx·zx + x·x + y·y + z·z + c,
    /// coefficients in that order.
    Quadric { coefficients: [f64; 10] },
    /// An expression in the free variables x, y, z (parameters already folded in).
    Implicit { expr: Expr },
}

impl Surface {
    /// The implicit value at a global point (sign convention above).
    pub fn value(&self, p: &Point3) -> f64 {
        let _ = p;
        todo!("geom kernel")
    }

    /// The gradient of `value` at `p` (analytic where possible, else central differences).
    pub fn gradient(&self, p: &Point3) -> Vec3 {
        let _ = p;
        todo!("geom kernel")
    }

    /// Distance from `p` to the surface: exact for planes and spheres, the
    /// first-order estimate |value| / |gradient| otherwise.
    pub fn distance(&self, p: &Point3) -> f64 {
        let _ = p;
        todo!("geom kernel")
    }

    /// The nearest point on the surface found by Newton steps along the
    /// gradient from `p`; `None` if it does not converge.
    pub fn project(&self, p: &Point3) -> Option<Point3> {
        let _ = p;
        todo!("geom kernel")
    }

    /// True for surfaces with no boundary that enclose a finite volume.
    pub fn is_closed(&self) -> bool {
        matches!(self, Surface::Ellipsoid { .. } | Surface::Torus { .. })
    }
}
