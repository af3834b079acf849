use super::{assert_close, assert_points_close};
use crate::geom::{Curve, Frame, Point3, Surface, Vec3};
use std::f64::consts::{FRAC_PI_2, PI, TAU};

fn unit_sphere_and_plane(height: f64) -> Box<[Surface; 2]> {
    Box::new([
        Surface::Ellipsoid {
            frame: Frame::identity(),
        },
        Surface::Plane {
            origin: Point3::new(0.0, 0.0, height),
            normal: Vec3::z(),
        },
    ])
}

#[test]
fn segment_points_tangent_length_and_carrier() {
    let c = Curve::Segment {
        a: Point3::new(1.0, 0.0, 0.0),
        b: Point3::new(1.0, 4.0, 3.0),
    };
    assert_points_close(&c.point(0.5), &Point3::new(1.0, 2.0, 1.5), 1e-15);
    assert!((c.tangent(0.3) - Vec3::new(0.0, 0.8, 0.6)).norm() < 1e-15);
    assert_close(c.length(), 5.0, 1e-15);
    assert!(!c.is_closed());
    assert_eq!(c.samples(4).len(), 5);
    // Beyond the end, but on the carrier line.
    assert_close(
        c.distance_to_carrier(&Point3::new(1.0, 8.0, 6.0)),
        0.0,
        1e-12,
    );
    assert_close(
        c.distance_to_carrier(&Point3::new(3.0, 4.0, 3.0)),
        2.0,
        1e-12,
    );
}

#[test]
fn circle_and_ellipse_arcs() {
    let circle = Curve::Ellipse {
        center: Point3::new(0.0, 0.0, 1.0),
        major: Vec3::new(2.0, 0.0, 0.0),
        minor: Vec3::new(0.0, 2.0, 0.0),
        t0: 0.0,
        t1: FRAC_PI_2,
    };
    assert_points_close(&circle.point(1.0), &Point3::new(0.0, 2.0, 1.0), 1e-15);
    assert!((circle.tangent(0.0) - Vec3::y()).norm() < 1e-15);
    assert_close(circle.length(), PI, 1e-15);
    assert!(!circle.is_closed());
    assert_close(
        circle.distance_to_carrier(&Point3::new(-3.0, 0.0, 1.0)),
        1.0,
        1e-12,
    );
    assert_close(
        circle.distance_to_carrier(&Point3::new(0.0, 0.0, 2.0)),
        5f64.sqrt(),
        1e-12,
    );

    let ellipse = Curve::Ellipse {
        center: Point3::origin(),
        major: Vec3::new(2.0, 0.0, 0.0),
        minor: Vec3::new(0.0, 1.0, 0.0),
        t0: 0.0,
        t1: TAU,
    };
    assert!(ellipse.is_closed());
    // Perimeter of the 2 × 1 ellipse (Ramanujan-exact to many digits).
    assert_close(ellipse.length(), 9.688_448_220_547_675, 1e-9);
    assert_close(
        ellipse.distance_to_carrier(&Point3::new(3.0, 0.0, 0.0)),
        1.0,
        1e-9,
    );
    assert_close(
        ellipse.distance_to_carrier(&Point3::new(0.0, 0.0, 1.0)),
        2f64.sqrt(),
        1e-9,
    );
}

#[test]
fn closed_intersection_circle_is_traced() {
    let r = 0.75f64.sqrt();
    let a = Point3::new(r, 0.0, 0.5);
    let c = Curve::Intersection {
        surfaces: unit_sphere_and_plane(0.5),
        a,
        b: a,
    };
    assert!(c.is_closed());
    let samples = c.samples(32);
    assert_eq!(samples.len(), 33);
    for p in &samples {
        assert_close(p.z, 0.5, 1e-9);
        assert_close(p.coords.norm(), 1.0, 1e-9);
    }
    // The samples go round, not stay at a.
    assert!(samples.iter().any(|p| p.x < -0.8));
    assert_close(c.length(), TAU * r, 1e-4);
    assert_close(
        c.distance_to_carrier(&Point3::new(0.2, 0.0, 0.5)),
        r - 0.2,
        1e-9,
    );
    assert_close(c.distance_to_carrier(&Point3::new(0.0, -r, 0.0)), 0.5, 1e-9);
    assert!(c.tangent(0.25).z.abs() < 1e-9);
}

#[test]
fn open_intersection_arc_goes_from_a_to_b() {
    let r = 0.75f64.sqrt();
    let (a, b) = (Point3::new(r, 0.0, 0.5), Point3::new(0.0, r, 0.5));
    let c = Curve::Intersection {
        surfaces: unit_sphere_and_plane(0.5),
        a,
        b,
    };
    assert!(!c.is_closed());
    assert_points_close(&c.point(0.0), &a, 0.0);
    assert_points_close(&c.point(1.0), &b, 0.0);
    let mid = c.point(0.5);
    assert_points_close(
        &mid,
        &Point3::new(r / 2f64.sqrt(), r / 2f64.sqrt(), 0.5),
        1e-3,
    );
    assert_close(c.length(), FRAC_PI_2 * r, 1e-4);
    let t = c.tangent(0.0);
    assert!(t.y > 0.99, "tangent at a heads towards b: {t}");
}

#[test]
fn intersection_tracing_survives_bad_surfaces() {
    let expr = crate::expr::parse("ln(x)", 0).expect("parses");
    let surfaces = Box::new([
        Surface::Implicit { expr },
        Surface::Plane {
            origin: Point3::origin(),
            normal: Vec3::z(),
        },
    ]);
    let (a, b) = (Point3::new(-1.0, 0.0, 0.0), Point3::new(-2.0, 0.0, 0.0));
    let c = Curve::Intersection { surfaces, a, b };
    let samples = c.samples(8);
    assert_eq!(samples.len(), 9);
    let _ = (c.length(), c.tangent(0.5), c.distance_to_carrier(&a));
}
