use super::{assert_close, assert_points_close, similarity, skew_frame};
use crate::geom::{Frame, Mat3, Point3, Surface, Vec3};

fn sphere(center: Point3, radius: f64) -> Surface {
    Surface::Ellipsoid {
        frame: similarity(center, radius),
    }
}

fn implicit(text: &str) -> Surface {
    let expr = crate::expr::parse(text, 0).expect("test expression parses");
    Surface::Implicit { expr }
}

#[test]
fn sphere_value_distance_and_projection() {
    let s = sphere(Point3::new(1.0, 2.0, 3.0), 2.0);
    assert_close(s.value(&Point3::new(1.0, 2.0, 3.0)), -1.0, 1e-12);
    // |q| = 1.5 locally: value 1.25, exact distance 1.
    let p = Point3::new(4.0, 2.0, 3.0);
    assert_close(s.value(&p), 1.25, 1e-12);
    assert_close(s.distance(&p), 1.0, 1e-12);
    assert_close(s.distance(&Point3::new(1.0, 2.0, 3.5)), 1.5, 1e-12);
    let projected = s.project(&p).expect("sphere projection");
    assert_points_close(&projected, &Point3::new(3.0, 2.0, 3.0), 1e-12);
    assert!(
        s.project(&Point3::new(1.0, 2.0, 3.0)).is_none(),
        "centre has no unique projection"
    );
    assert!(
        s.gradient(&p).dot(&Vec3::x()) > 0.0,
        "gradient points outward"
    );
}

#[test]
fn ellipsoid_projection_by_newton_lands_on_surface() {
    let s = Surface::Ellipsoid {
        frame: skew_frame(),
    };
    let p = Point3::new(3.0, 1.0, -2.0);
    let q = s.project(&p).expect("converges");
    assert!(s.value(&q).abs() < 1e-12);
    assert!(s.distance(&q) < 1e-12);
}

#[test]
fn plane_value_distance_projection() {
    let s = Surface::Plane {
        origin: Point3::new(0.0, 0.0, 1.0),
        normal: Vec3::z(),
    };
    let p = Point3::new(3.0, -2.0, 4.0);
    assert_close(s.value(&p), 3.0, 1e-15);
    assert_close(s.distance(&p), 3.0, 1e-15);
    assert_points_close(
        &s.project(&p).expect("plane"),
        &Point3::new(3.0, -2.0, 1.0),
        1e-15,
    );
}

#[test]
fn cone_values_at_known_points() {
    let s = Surface::Cone {
        frame: Frame::identity(),
        r0: 1.0,
        r1: 0.5,
    };
    assert_close(s.value(&Point3::new(1.0, 0.0, 0.0)), 0.0, 1e-15);
    assert_close(s.value(&Point3::new(0.0, 0.75, 0.5)), 0.0, 1e-15);
    assert_close(s.value(&Point3::new(0.0, 0.0, 0.5)), -0.5625, 1e-15);
    assert_close(s.value(&Point3::new(2.0, 0.0, 0.0)), 3.0, 1e-15);
    // Apex cone: beyond the apex (r < 0) is outside, not a mirrored inside.
    let apex = Surface::Cone {
        frame: Frame::identity(),
        r0: 0.0,
        r1: 1.0,
    };
    assert_close(apex.value(&Point3::new(0.0, 0.0, -1.0)), 1.0, 1e-15);
    assert_close(apex.value(&Point3::new(0.0, 0.0, 1.0)), -1.0, 1e-15);
    // Cylinder scaled by 2 and shifted: the radius doubles.
    let frame = Frame {
        origin: Point3::new(0.0, 0.0, 5.0),
        linear: Mat3::identity() * 2.0,
    };
    let cylinder = Surface::Cone {
        frame,
        r0: 1.0,
        r1: 1.0,
    };
    assert_close(cylinder.value(&Point3::new(2.0, 0.0, 9.0)), 0.0, 1e-15);
    assert_close(cylinder.distance(&Point3::new(3.0, 0.0, 9.0)), 1.0, 0.3);
}

#[test]
fn torus_values_at_known_points() {
    let s = Surface::Torus {
        frame: Frame::identity(),
        major: 2.0,
        minor: 0.5,
    };
    assert_close(s.value(&Point3::new(2.5, 0.0, 0.0)), 0.0, 1e-15);
    assert_close(s.value(&Point3::new(0.0, -2.0, 0.5)), 0.0, 1e-15);
    assert_close(s.value(&Point3::new(2.0, 0.0, 0.0)), -0.25, 1e-15);
    assert_close(s.value(&Point3::origin()), 3.75, 1e-15);
    // First-order estimate |f| / |∇f| = 0.75 / 2 (the true distance is 0.5).
    let p = Point3::new(3.0, 0.0, 0.0);
    assert_close(s.distance(&p), 0.375, 1e-12);
    let q = s.project(&p).expect("torus projection");
    assert_points_close(&q, &Point3::new(2.5, 0.0, 0.0), 1e-9);
}

#[test]
fn quadric_and_implicit_match_the_sphere() {
    let quadric = Surface::Quadric {
        coefficients: [1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -4.0],
    };
    let expr = implicit("x^2 + y^2 + z^2 - 4");
    let p = Point3::new(1.0, 2.0, -3.0);
    assert_close(quadric.value(&p), 10.0, 1e-12);
    assert_close(expr.value(&p), 10.0, 1e-12);
    assert!((quadric.gradient(&p) - Vec3::new(2.0, 4.0, -6.0)).norm() < 1e-12);
    assert!((expr.gradient(&p) - Vec3::new(2.0, 4.0, -6.0)).norm() < 1e-6);
    let q = expr.project(&p).expect("implicit projection");
    assert_close(q.coords.norm(), 2.0, 1e-9);
}

#[test]
fn implicit_failures_are_nan_not_panics() {
    for text in ["ln(x)", "sqrt(x) + w", "1 / (x - x)"] {
        let s = implicit(text);
        let p = Point3::new(-1.0, 0.0, 0.0);
        assert!(s.value(&p).is_nan(), "{text}");
        assert!(s.gradient(&p).iter().all(|c| c.is_nan()), "{text}");
        assert_eq!(s.distance(&p), f64::INFINITY, "{text}");
        assert!(s.project(&p).is_none(), "{text}");
    }
}

#[test]
fn degenerate_inputs_do_not_panic() {
    let flat = Frame {
        origin: Point3::origin(),
        linear: Mat3::zeros(),
    };
    let surfaces = [
        Surface::Ellipsoid { frame: flat },
        Surface::Cone {
            frame: flat,
            r0: 1.0,
            r1: 1.0,
        },
        Surface::Torus {
            frame: flat,
            major: 1.0,
            minor: 0.1,
        },
        Surface::Plane {
            origin: Point3::origin(),
            normal: Vec3::zeros(),
        },
    ];
    let nan = Point3::new(f64::NAN, 0.0, 0.0);
    for s in &surfaces {
        let _ = (
            s.value(&Point3::origin()),
            s.gradient(&nan),
            s.distance(&nan),
        );
        assert!(s.project(&Point3::new(1.0, 2.0, 3.0)).is_none());
        assert!(s.project(&nan).is_none());
    }
}

#[test]
fn gradients_match_finite_differences() {
    let frame = skew_frame();
    let surfaces = [
        Surface::Plane {
            origin: Point3::new(1.0, 0.0, 0.0),
            normal: Vec3::new(0.6, 0.8, 0.0),
        },
        Surface::Ellipsoid { frame },
        Surface::Cone {
            frame,
            r0: 1.0,
            r1: 0.4,
        },
        Surface::Torus {
            frame,
            major: 2.0,
            minor: 0.7,
        },
        Surface::Quadric {
            coefficients: [1.0, -2.0, 0.5, 0.3, -0.7, 1.1, 0.2, -0.4, 0.9, -1.0],
        },
        implicit("sin(x) * y + z^3 - exp(x * z / 4)"),
    ];
    let points = [Point3::new(1.3, -0.4, 2.2), Point3::new(-0.7, 1.9, 0.6)];
    let h = 1e-6;
    for s in &surfaces {
        for p in &points {
            let g = s.gradient(p);
            for i in 0..3 {
                let mut e = Vec3::zeros();
                e[i] = h;
                let fd = (s.value(&(p + e)) - s.value(&(p - e))) / (2.0 * h);
                assert_close(g[i], fd, 1e-5 * (1.0 + fd.abs()));
            }
        }
    }
}
