//! The primitive solids in canonical local form, with implicit functions
//! (positive inside), exact measures, and boundary samples for the checks
//! that find crossing boundaries.

use super::{Aabb, Frame, Point3};

#[derive(Debug, Clone, PartialEq)]
pub enum SolidShape {
    /// The unit ball |q| ≤ 1 in `frame` (sphere, ellipsoid).
    Ball { frame: Frame },
    /// The unit cube [0, 1]³ in `frame` (parallelepiped: the columns of the
    /// frame's linear map are the three edge vectors).
    Box { frame: Frame },
    /// 0 ≤ z ≤ 1 and x² + y² ≤ (r0 + (r1 − r0)·z)² in `frame`: the frame's z
    /// column runs from the bottom centre to the top centre, x and y columns are
    /// unit vectors perpendicular to it (before any scaling).
    Cone { frame: Frame, r0: f64, r1: f64 },
    /// (√(x² + y²) − major)² + z² ≤ minor² in `frame`.
    Torus { frame: Frame, major: f64, minor: f64 },
    /// 2D: the unit disk x² + y² ≤ 1, z = 0 of `frame` (circle, ellipse).
    Disk { frame: Frame },
    /// 2D: a convex polygon in the z = 0 plane of `frame`, vertices
    /// counter-clockwise (triangle, parallelogram), local coordinates.
    Polygon { frame: Frame, vertices: Vec<Point3> },
}

impl SolidShape {
    /// Positive inside, zero on the boundary, negative outside; scaled to be
    /// close to a signed distance near the boundary (for tolerance tests).
    pub fn value(&self, p: &Point3) -> f64 {
        let _ = p;
        todo!("geom kernel")
    }

    pub fn is_planar(&self) -> bool {
        matches!(self, SolidShape::Disk { .. } | SolidShape::Polygon { .. })
    }

    pub fn bbox(&self) -> Aabb {
        todo!("geom kernel")
    }

    /// The exact volume (3D) or area (2D).
    pub fn measure(&self) -> f64 {
        todo!("geom kernel")
    }

    /// A point strictly inside.
    pub fn interior_point(&self) -> Point3 {
        todo!("geom kernel")
    }

    /// Points spread over the whole boundary (including its edges and corners)
    /// with spacing about `1/density` of the solid's size in each parametric
    /// direction; for 2D shapes, points along the boundary curve.
    pub fn boundary_samples(&self, density: usize) -> Vec<Point3> {
        let _ = density;
        todo!("geom kernel")
    }
}
