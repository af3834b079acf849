//! The geometric kernel: affine frames, the analytic surfaces and curves that
//! carry faces and edges, and the primitive solids with their implicit
//! functions. Plain math on `f64`; it knows nothing of XML or names.
//!
//! Conventions: a surface's implicit value is negative on the side its normal
//! points away from, i.e. for closed surfaces negative inside and positive
//! outside, so the gradient is the outward normal. A solid's [`SolidShape::value`]
//! is the opposite: positive inside (paper 001's convention f ≥ 0 inside).

mod curve;
mod frame;
mod intersect;
mod newton;
pub mod point_calculus;
pub mod polygon;
mod sampling;
mod shape_eval;
mod solid;
pub(crate) mod solid_carriers;
mod surface;
#[cfg(test)]
mod tests;
mod trace;

pub use curve::Curve;
pub(crate) use curve::ellipse_point_trig;
pub use frame::Frame;
pub use intersect::{BoundaryRelation, boundary_relation};
pub use newton::{intersect_curves, intersect_surfaces};
pub use solid::SolidShape;
pub use surface::Surface;

pub type Point3 = nalgebra::Point3<f64>;
pub type Vec3 = nalgebra::Vector3<f64>;
pub type Mat3 = nalgebra::Matrix3<f64>;

/// An axis-aligned bounding box.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aabb {
    pub min: Point3,
    pub max: Point3,
}

impl Aabb {
    pub fn empty() -> Aabb {
        Aabb {
            min: Point3::new(f64::INFINITY, f64::INFINITY, f64::INFINITY),
            max: Point3::new(f64::NEG_INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY),
        }
    }

    pub fn is_empty(&self) -> bool {
        self.min.x > self.max.x
    }

    pub fn include(&mut self, p: &Point3) {
        self.min = self.min.inf(p);
        self.max = self.max.sup(p);
    }

    pub fn union(&self, other: &Aabb) -> Aabb {
        Aabb {
            min: self.min.inf(&other.min),
            max: self.max.sup(&other.max),
        }
    }

    pub fn diagonal(&self) -> f64 {
        if self.is_empty() {
            0.0
        } else {
            (self.max - self.min).norm()
        }
    }

    pub fn overlaps(&self, other: &Aabb, margin: f64) -> bool {
        (0..3).all(|i| self.min[i] - margin <= other.max[i] && other.min[i] - margin <= self.max[i])
    }
}
