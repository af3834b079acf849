//! Affine frames: local coordinates q map to global p = origin + linear · q.

use super::{Mat3, Point3, Vec3};

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    pub origin: Point3,
    /// Columns are the images of the local x, y, z unit vectors. Rigid for
    /// coordinate systems; may scale (never mirror) after <scale>.
    pub linear: Mat3,
}

impl Default for Frame {
    fn default() -> Frame {
        Frame::identity()
    }
}

impl Frame {
    pub fn identity() -> Frame {
        Frame {
            origin: Point3::origin(),
            linear: Mat3::identity(),
        }
    }

    pub fn translation(shift: Vec3) -> Frame {
        Frame {
            origin: Point3::from(shift),
            linear: Mat3::identity(),
        }
    }

    /// Rotation by angles in degrees about the x, then y, then z axis
    /// (extrinsic: R = Rz · Ry · Rx), about the origin.
    pub fn rotation_degrees(angles: Vec3) -> Frame {
        let r = nalgebra::Rotation3::from_axis_angle(&Vec3::z_axis(), angles.z.to_radians())
            * nalgebra::Rotation3::from_axis_angle(&Vec3::y_axis(), angles.y.to_radians())
            * nalgebra::Rotation3::from_axis_angle(&Vec3::x_axis(), angles.x.to_radians());
        Frame {
            origin: Point3::origin(),
            linear: *r.matrix(),
        }
    }

    pub fn scaling(factors: Vec3) -> Frame {
        Frame {
            origin: Point3::origin(),
            linear: Mat3::from_diagonal(&factors),
        }
    }

    pub fn to_global(&self, q: &Point3) -> Point3 {
        self.origin + self.linear * q.coords
    }

    pub fn vector_to_global(&self, v: &Vec3) -> Vec3 {
        self.linear * v
    }

    /// Global → local; `None` when the frame is singular.
    pub fn to_local(&self, p: &Point3) -> Option<Point3> {
        self.linear
            .try_inverse()
            .map(|inv| Point3::from(inv * (p - self.origin)))
    }

    /// `self ∘ inner`: first `inner`, then `self`.
    pub fn compose(&self, inner: &Frame) -> Frame {
        Frame {
            origin: self.to_global(&inner.origin),
            linear: self.linear * inner.linear,
        }
    }

    /// Maps a normal vector (covector) to global coordinates: (L⁻¹)ᵀ n, normalised.
    pub fn normal_to_global(&self, n: &Vec3) -> Vec3 {
        let m = self
            .linear
            .try_inverse()
            .map(|inv| inv.transpose() * n)
            .unwrap_or(*n);
        let len = m.norm();
        if len > 0.0 { m / len } else { m }
    }

    /// The smallest factor by which the frame stretches a length (its smallest singular value).
    pub fn min_scale(&self) -> f64 {
        self.linear.singular_values().min()
    }

    pub fn max_scale(&self) -> f64 {
        self.linear.singular_values().max()
    }

    /// L⁻¹, or `None` when the frame is singular or its inverse not finite
    /// (callers then treat the frame's shape as empty).
    pub fn inverse(&self) -> Option<Mat3> {
        let inv = self.linear.try_inverse()?;
        inv.iter().all(|v| v.is_finite()).then_some(inv)
    }

    pub fn determinant(&self) -> f64 {
        self.linear.determinant()
    }

    /// `Some(s)` when the linear map is s times a rotation (to 1e-9 relative),
    /// which lets spheres and balls use exact distances.
    pub fn similarity_scale(&self) -> Option<f64> {
        let m = self.linear.transpose() * self.linear;
        let s2 = m.trace() / 3.0;
        if s2.is_nan() || s2 <= 0.0 || !s2.is_finite() {
            return None;
        }
        let deviation = (m - Mat3::identity() * s2).abs().max();
        (deviation <= 1e-9 * s2).then(|| s2.sqrt())
    }
}
