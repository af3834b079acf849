use super::assert_points_close;
use crate::geom::{Curve, Frame, Point3, Surface, Vec3, intersect_curves, intersect_surfaces};

fn plane(origin: Point3, normal: Vec3) -> Surface {
    Surface::Plane { origin, normal }
}

#[test]
fn three_planes_meet_in_a_point() {
    let a = plane(
        Point3::new(1.0, 1.0, 1.0),
        Vec3::new(1.0, 1.0, 1.0) / 3f64.sqrt(),
    );
    let b = plane(Point3::origin(), Vec3::new(1.0, -1.0, 0.0) / 2f64.sqrt());
    let c = plane(Point3::new(0.0, 0.0, 1.0), Vec3::z());
    let p = intersect_surfaces([&a, &b, &c], Point3::new(5.0, -3.0, 0.0), 1e-9);
    assert_points_close(
        &p.expect("transversal planes"),
        &Point3::new(1.0, 1.0, 1.0),
        1e-12,
    );
}

#[test]
fn parallel_planes_have_no_vertex() {
    let a = plane(Point3::origin(), Vec3::z());
    let b = plane(Point3::new(0.0, 0.0, 1.0), Vec3::z());
    let c = plane(Point3::origin(), Vec3::x());
    assert!(intersect_surfaces([&a, &b, &c], Point3::origin(), 1e-9).is_none());
}

#[test]
fn sphere_and_two_planes_pick_the_point_near_the_hint() {
    let sphere = Surface::Ellipsoid {
        frame: Frame::identity(),
    };
    let x0 = plane(Point3::origin(), Vec3::x());
    let y0 = plane(Point3::origin(), Vec3::y());
    let top = intersect_surfaces([&sphere, &x0, &y0], Point3::new(0.1, 0.1, 0.8), 1e-9);
    assert_points_close(&top.expect("top"), &Point3::new(0.0, 0.0, 1.0), 1e-12);
    let bottom = intersect_surfaces([&sphere, &x0, &y0], Point3::new(0.2, -0.1, -0.5), 1e-9);
    assert_points_close(
        &bottom.expect("bottom"),
        &Point3::new(0.0, 0.0, -1.0),
        1e-12,
    );
    // A plane that misses the sphere: no vertex.
    let far = plane(Point3::new(0.0, 0.0, 2.0), Vec3::z());
    assert!(intersect_surfaces([&sphere, &x0, &far], Point3::new(0.0, 0.5, 1.5), 1e-9).is_none());
}

#[test]
fn two_segments_meet_on_their_carriers() {
    let a = Curve::Segment {
        a: Point3::origin(),
        b: Point3::new(2.0, 2.0, 0.0),
    };
    let b = Curve::Segment {
        a: Point3::new(0.0, 2.0, 0.0),
        b: Point3::new(2.0, 0.0, 0.0),
    };
    let p = intersect_curves(&a, &b, Point3::new(0.0, 0.0, 0.0), 1e-9);
    assert_points_close(
        &p.expect("crossing segments"),
        &Point3::new(1.0, 1.0, 0.0),
        1e-12,
    );
    // Carriers are unbounded: a short segment's line still meets.
    let short = Curve::Segment {
        a: Point3::new(5.0, 0.0, 0.0),
        b: Point3::new(5.0, 0.1, 0.0),
    };
    let p = intersect_curves(&a, &short, Point3::origin(), 1e-9);
    assert_points_close(&p.expect("lines meet"), &Point3::new(5.0, 5.0, 0.0), 1e-12);
    // Skew lines one unit apart.
    let skew = Curve::Segment {
        a: Point3::new(0.0, 2.0, 1.0),
        b: Point3::new(2.0, 0.0, 1.0),
    };
    assert!(intersect_curves(&a, &skew, Point3::origin(), 1e-6).is_none());
    let near = intersect_curves(&a, &skew, Point3::origin(), 1.5).expect("within a loose tol");
    assert_points_close(&near, &Point3::new(1.0, 1.0, 0.5), 1e-12);
}

#[test]
fn segment_meets_circle() {
    let circle = Curve::Ellipse {
        center: Point3::origin(),
        major: Vec3::x(),
        minor: Vec3::y(),
        t0: 0.0,
        t1: std::f64::consts::TAU,
    };
    let line = Curve::Segment {
        a: Point3::new(-2.0, 0.5, 0.0),
        b: Point3::new(2.0, 0.5, 0.0),
    };
    let p = intersect_curves(&circle, &line, Point3::new(1.0, 0.4, 0.0), 1e-9);
    assert_points_close(
        &p.expect("right"),
        &Point3::new(0.75f64.sqrt(), 0.5, 0.0),
        1e-9,
    );
    let p = intersect_curves(&circle, &line, Point3::new(-1.0, 0.4, 0.0), 1e-9);
    assert_points_close(
        &p.expect("left"),
        &Point3::new(-(0.75f64.sqrt()), 0.5, 0.0),
        1e-9,
    );
}
