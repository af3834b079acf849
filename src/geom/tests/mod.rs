//! Unit tests of the geometric kernel, one file per concept.

mod curves;
mod newton;
mod relation;
mod solids;
mod surfaces;

use super::{Frame, Mat3, Point3, Vec3};

/// A frame that rotates, shears and scales: the general case for chain rules
/// and determinant factors.
pub(super) fn skew_frame() -> Frame {
    let rotation = Frame::rotation_degrees(Vec3::new(20.0, -35.0, 50.0)).linear;
    let shear = Mat3::new(1.0, 0.3, 0.0, 0.0, 1.0, -0.2, 0.0, 0.0, 1.0);
    let scale = Mat3::from_diagonal(&Vec3::new(1.5, 0.7, 2.0));
    Frame {
        origin: Point3::new(0.4, -1.0, 2.5),
        linear: rotation * shear * scale,
    }
}

/// A rotation and uniform scale about a translated origin.
pub(super) fn similarity(center: Point3, radius: f64) -> Frame {
    let rotation = Frame::rotation_degrees(Vec3::new(10.0, 70.0, -25.0)).linear;
    Frame {
        origin: center,
        linear: rotation * radius,
    }
}

pub(super) fn assert_close(actual: f64, expected: f64, tol: f64) {
    assert!(
        (actual - expected).abs() <= tol,
        "expected {expected}, got {actual} (tolerance {tol})"
    );
}

pub(super) fn assert_points_close(actual: &Point3, expected: &Point3, tol: f64) {
    assert!(
        (actual - expected).norm() <= tol,
        "expected {expected}, got {actual}"
    );
}
