use super::{assert_close, similarity, skew_frame};
use crate::geom::{Frame, Mat3, Point3, SolidShape, Vec3};
use std::f64::consts::PI;

fn axis_box(min: Point3, size: Vec3) -> SolidShape {
    SolidShape::Box {
        frame: Frame {
            origin: min,
            linear: Mat3::from_diagonal(&size),
        },
    }
}

/// A cone frame with unit x, y columns perpendicular to the axis vector.
fn cone_frame(base: Point3, axis: Vec3) -> Frame {
    let z = axis.normalize();
    let x = z.cross(&Vec3::new(0.3, 0.1, 0.9)).normalize();
    let y = z.cross(&x);
    Frame {
        origin: base,
        linear: Mat3::from_columns(&[x, y, axis]),
    }
}

#[test]
fn measures_are_exact() {
    let ball = SolidShape::Ball {
        frame: similarity(Point3::new(1.0, 2.0, 3.0), 2.0),
    };
    assert_close(ball.measure(), 32.0 * PI / 3.0, 1e-12);

    let frame = skew_frame();
    // rotation · shear · diag(1.5, 0.7, 2): |det| = 2.1.
    assert_close(SolidShape::Box { frame }.measure(), 2.1, 1e-12);

    let cone = SolidShape::Cone {
        frame: cone_frame(Point3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 3.0, 0.0)),
        r0: 1.0,
        r1: 2.0,
    };
    // π h (r0² + r0 r1 + r1²) / 3 with h = 3.
    assert_close(cone.measure(), 7.0 * PI, 1e-12);

    let torus = SolidShape::Torus {
        frame: similarity(Point3::origin(), 1.0),
        major: 3.0,
        minor: 0.5,
    };
    assert_close(torus.measure(), 2.0 * PI * PI * 3.0 * 0.25, 1e-12);

    let rotation = Frame::rotation_degrees(Vec3::new(30.0, 40.0, 0.0)).linear;
    let disk_frame = Frame {
        origin: Point3::origin(),
        linear: rotation * Mat3::from_diagonal(&Vec3::new(3.0, 2.0, 1.0)),
    };
    assert_close(
        SolidShape::Disk { frame: disk_frame }.measure(),
        6.0 * PI,
        1e-12,
    );

    let triangle = SolidShape::Polygon {
        frame: disk_frame,
        vertices: vec![
            Point3::origin(),
            Point3::new(2.0, 0.0, 0.0),
            Point3::new(0.0, 1.0, 0.0),
        ],
    };
    assert_close(triangle.measure(), 6.0, 1e-12);
}

#[test]
fn values_approximate_signed_distances() {
    let ball = SolidShape::Ball {
        frame: similarity(Point3::new(1.0, 0.0, 0.0), 2.0),
    };
    assert_close(ball.value(&Point3::new(1.0, 0.0, 0.5)), 1.5, 1e-12);
    assert_close(ball.value(&Point3::new(4.0, 0.0, 0.0)), -1.0, 1e-12);

    let b = axis_box(Point3::origin(), Vec3::new(2.0, 4.0, 1.0));
    assert_close(b.value(&Point3::new(1.0, 2.0, 0.25)), 0.25, 1e-12);
    assert_close(b.value(&Point3::new(1.9, 2.0, 0.5)), 0.1, 1e-12);
    assert_close(b.value(&Point3::new(3.0, 2.0, 0.5)), -1.0, 1e-12);

    // Frustum along z from r0 = 1 to r1 = 0 over height 1: lateral distance
    // is (r(z) − ρ) cos 45°.
    let cone = SolidShape::Cone {
        frame: Frame::identity(),
        r0: 1.0,
        r1: 0.0,
    };
    assert_close(
        cone.value(&Point3::new(0.0, 0.0, 0.5)),
        0.5f64.sqrt() / 2.0,
        1e-12,
    );
    assert_close(cone.value(&Point3::new(0.1, 0.0, 0.05)), 0.05, 1e-12);
    assert!(cone.value(&Point3::new(0.0, 0.0, 1.2)) < 0.0);

    let torus = SolidShape::Torus {
        frame: similarity(Point3::origin(), 2.0),
        major: 2.0,
        minor: 0.5,
    };
    let core = torus.interior_point();
    assert_close(torus.value(&core), 1.0, 1e-12);
    assert_close(torus.value(&Point3::origin()), -3.0, 1e-12);

    let disk = SolidShape::Disk {
        frame: Frame {
            origin: Point3::origin(),
            linear: Mat3::from_diagonal(&Vec3::new(2.0, 2.0, 1.0)),
        },
    };
    assert_close(disk.value(&Point3::new(1.5, 0.0, 0.0)), 0.5, 1e-12);
    // Off the plane: the normal offset is ignored.
    assert_close(disk.value(&Point3::new(1.5, 0.0, 7.0)), 0.5, 1e-12);

    let triangle = SolidShape::Polygon {
        frame: Frame::identity(),
        vertices: vec![
            Point3::origin(),
            Point3::new(0.0, 1.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
        ],
    };
    assert_close(triangle.value(&Point3::new(0.25, 0.25, 0.0)), 0.25, 1e-12);
    assert_close(
        triangle.value(&Point3::new(1.0, 1.0, 0.0)),
        -(0.5f64.sqrt()),
        1e-12,
    );
}

#[test]
fn boundary_samples_lie_on_the_boundary_and_interior_points_inside() {
    let frame = skew_frame();
    let shapes = [
        SolidShape::Ball { frame },
        SolidShape::Ball {
            frame: similarity(Point3::new(1.0, 1.0, 1.0), 0.5),
        },
        SolidShape::Box { frame },
        SolidShape::Cone {
            frame,
            r0: 1.0,
            r1: 0.3,
        },
        SolidShape::Torus {
            frame,
            major: 2.0,
            minor: 0.5,
        },
        SolidShape::Disk { frame },
        SolidShape::Polygon {
            frame,
            vertices: vec![
                Point3::origin(),
                Point3::new(1.0, 0.0, 0.0),
                Point3::new(1.5, 1.0, 0.0),
            ],
        },
    ];
    for shape in &shapes {
        assert!(shape.value(&shape.interior_point()) > 0.0, "{shape:?}");
        let samples = shape.boundary_samples(12);
        assert!(samples.len() >= 30, "{shape:?}");
        let bbox = shape.bbox();
        for p in &samples {
            assert!(
                shape.value(p).abs() < 1e-9,
                "{shape:?} at {p}: {}",
                shape.value(p)
            );
            assert!(bbox.overlaps(&crate::geom::Aabb { min: *p, max: *p }, 1e-12));
        }
    }
}

#[test]
fn bboxes_are_tight_for_balls_and_tori() {
    let ball = SolidShape::Ball {
        frame: similarity(Point3::new(1.0, 2.0, 3.0), 2.0),
    };
    let bbox = ball.bbox();
    assert!((bbox.min - Point3::new(-1.0, 0.0, 1.0)).norm() < 1e-12);
    assert!((bbox.max - Point3::new(3.0, 4.0, 5.0)).norm() < 1e-12);
    let torus = SolidShape::Torus {
        frame: Frame::identity(),
        major: 2.0,
        minor: 0.5,
    };
    let bbox = torus.bbox();
    assert!((bbox.max - Point3::new(2.5, 2.5, 0.5)).norm() < 1e-12);
}

#[test]
fn degenerate_solids_do_not_panic() {
    let flat = Frame {
        origin: Point3::origin(),
        linear: Mat3::zeros(),
    };
    let shapes = [
        SolidShape::Ball { frame: flat },
        SolidShape::Box { frame: flat },
        SolidShape::Cone {
            frame: flat,
            r0: 1.0,
            r1: 0.0,
        },
        SolidShape::Torus {
            frame: flat,
            major: 1.0,
            minor: 0.5,
        },
        SolidShape::Disk { frame: flat },
        SolidShape::Polygon {
            frame: Frame::identity(),
            vertices: vec![Point3::origin()],
        },
        SolidShape::Polygon {
            frame: Frame::identity(),
            vertices: vec![],
        },
    ];
    for shape in &shapes {
        let v = shape.value(&Point3::new(0.1, 0.2, 0.3));
        assert!(v.is_nan() || v < 0.0, "{shape:?}");
        let _ = (
            shape.bbox(),
            shape.measure(),
            shape.interior_point(),
            shape.boundary_samples(0),
        );
    }
}
