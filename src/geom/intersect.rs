//! How the boundaries of two solids relate: disjoint, nested, touching on
//! shared faces, or crossing (which the boundary-representation path cannot
//! combine and reports).

use super::{Point3, SolidShape};

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
    let _ = (a, b, tol);
    todo!("geom kernel")
}
