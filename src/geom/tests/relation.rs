use super::similarity;
use crate::geom::{Frame, Mat3, Point3, SolidShape, Vec3, boundary_relation};

fn ball(center: Point3, radius: f64) -> SolidShape {
    SolidShape::Ball {
        frame: similarity(center, radius),
    }
}

fn axis_box(min: Point3, size: Vec3) -> SolidShape {
    SolidShape::Box {
        frame: Frame {
            origin: min,
            linear: Mat3::from_diagonal(&size),
        },
    }
}

fn unit_box_at(x: f64, y: f64, z: f64) -> SolidShape {
    axis_box(Point3::new(x, y, z), Vec3::repeat(1.0))
}

#[test]
fn disjoint_balls_take_the_bbox_shortcut() {
    let (a, b) = (
        ball(Point3::origin(), 1.0),
        ball(Point3::new(3.0, 0.0, 0.0), 1.0),
    );
    let r = boundary_relation(&a, &b, 1e-9);
    for cov in [r.a_in_b, r.b_in_a] {
        assert_eq!((cov.inside, cov.outside, cov.on), (0, 1, 0));
        assert!(cov.crossing_near.is_none());
    }
}

#[test]
fn ball_inside_box_is_nested() {
    let a = ball(Point3::new(0.5, 0.5, 0.5), 0.3);
    let b = unit_box_at(0.0, 0.0, 0.0);
    let r = boundary_relation(&a, &b, 1e-9);
    assert!(r.a_in_b.inside > 0);
    assert_eq!((r.a_in_b.outside, r.a_in_b.on), (0, 0));
    assert!(r.b_in_a.outside > 0);
    assert_eq!((r.b_in_a.inside, r.b_in_a.on), (0, 0));
    assert!(!r.a_in_b.crosses() && !r.b_in_a.crosses());
}

#[test]
fn crossing_balls_report_a_point_on_the_intersection_circle() {
    let a = ball(Point3::origin(), 1.0);
    let b = ball(Point3::new(1.0, 0.0, 0.0), 1.0);
    let r = boundary_relation(&a, &b, 1e-9);
    for cov in [r.a_in_b, r.b_in_a] {
        assert!(cov.crosses());
        let p = cov.crossing_near.expect("a crossing point");
        // The circle x = 1/2, y² + z² = 3/4.
        assert!((p.x - 0.5).abs() < 1e-6, "{p}");
        assert!((p.y.hypot(p.z) - 0.75f64.sqrt()).abs() < 1e-6, "{p}");
    }
}

#[test]
fn boxes_sharing_a_face_touch_without_crossing() {
    let (a, b) = (unit_box_at(0.0, 0.0, 0.0), unit_box_at(1.0, 0.0, 0.0));
    let r = boundary_relation(&a, &b, 1e-9);
    for cov in [r.a_in_b, r.b_in_a] {
        assert_eq!(cov.inside, 0);
        assert!(cov.on > 0 && cov.outside > 0);
        assert!(!cov.crosses() && cov.crossing_near.is_none());
    }
}

#[test]
fn box_partially_covering_a_face() {
    // b sits on a's top face, covering the quarter [0.5, 1]² of it.
    let a = unit_box_at(0.0, 0.0, 0.0);
    let b = unit_box_at(0.5, 0.5, 1.0);
    let r = boundary_relation(&a, &b, 1e-9);
    for cov in [r.a_in_b, r.b_in_a] {
        assert_eq!(cov.inside, 0);
        assert!(cov.on > 0 && cov.outside > 0);
        assert!(!cov.crosses());
    }
    // Sunk halfway into a, b's boundary crosses a's.
    let sunk = unit_box_at(0.5, 0.5, 0.5);
    let r = boundary_relation(&a, &sunk, 1e-9);
    assert!(r.a_in_b.crosses() && r.b_in_a.crosses());
    let p = r.b_in_a.crossing_near.expect("crossing");
    assert!(
        a.value(&p).abs() < 1e-6 && sunk.value(&p).abs() < 1e-6,
        "{p}"
    );
}
