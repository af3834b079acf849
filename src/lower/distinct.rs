//! Which primitive boundaries weld nothing with themselves, told from the
//! shape alone. The isolated runs (`isolated.rs`) need every solid's entity
//! counts before they write; building the boundary and welding it for them
//! was a twentieth of the front end's instructions on files of many
//! primitives, although a regular solid merges nothing. Here only the
//! comparisons that could merge something are made, with the points the
//! boundary builders (`brep.rs`) place, computed the same way, so the answer
//! is the weld's; anything else (2D regions, zero radii, a torus whose two
//! circles meet) is left to it.

use super::weld::{probe_points, same_edge};
use crate::geom::solid_carriers::{box_corner, cone_rims, torus_meridian, torus_parallel};
use crate::geom::{Curve, Frame, Point3, SolidShape, ellipse_point_trig};
use std::f64::consts::TAU;
use std::sync::OnceLock;

/// The boundary's (vertices, edges, faces) when welding it with tolerance
/// `tol` merges none of its entities; `None` when it might (then weld it).
///
/// The local weld merges a vertex with an earlier one within `tol`, an edge
/// with an earlier one between the same two vertices whose curve agrees, and
/// a face with an earlier one of the same edges whose sample point lies within
/// `tol`. With distinct vertices, a box's edges join different corner pairs
/// and its faces have different edges; a ball's two faces share its equator,
/// and a cone's cap and side share its rim when there is only one; a
/// torus's one vertex and one face have nothing to merge with, and its two
/// edges (both from the seam to itself) merge when their probe points agree.
pub(super) fn unwelded_counts(shape: &SolidShape, tol: f64) -> Option<[u32; 3]> {
    // The weld's test, negated (a distance that is not a number is apart).
    let near = |a: Point3, b: Point3| (a - b).norm() <= tol;
    let apart = |a: Point3, b: Point3| !near(a, b);
    match shape {
        SolidShape::Box { frame } => {
            let corners: [Point3; 8] = std::array::from_fn(|n| box_corner(frame, n));
            let distinct = (0..8).all(|j| (0..j).all(|i| apart(corners[i], corners[j])));
            distinct.then_some([8, 12, 6])
        }
        // The faces' samples, as `Brep::ball` places them.
        SolidShape::Ball { frame } => {
            let (north, south) = (at(frame, 0.0, 0.0, 1.0), at(frame, 0.0, 0.0, -1.0));
            apart(north, south).then_some([1, 1, 2])
        }
        SolidShape::Cone { frame, r0, r1 } => {
            let rims: Vec<(f64, f64)> = cone_rims(*r0, *r1).map(|(z, r, _)| (z, r)).collect();
            match rims.as_slice() {
                // The two rims' vertices; their edges and the three faces
                // differ once these do.
                [(z0, r0), (z1, r1)] => {
                    apart(at(frame, *r0, 0.0, *z0), at(frame, *r1, 0.0, *z1)).then_some([2, 2, 3])
                }
                // One rim: its cap's centre against the side's sample.
                [(z, _)] => {
                    let mid_r = 0.5 * (r0 + r1);
                    let cap = at(frame, 0.0, 0.0, *z);
                    apart(cap, at(frame, -mid_r, 0.0, 0.5)).then_some([1, 1, 2])
                }
                _ => None,
            }
        }
        // The weld's own test of the meridian (edge 1) against the parallel
        // (edge 0), with the curves `Brep::torus` makes.
        SolidShape::Torus {
            frame,
            major,
            minor,
        } => {
            let parallel = ellipse_probes(&torus_parallel(frame, *major, *minor));
            let meridian = ellipse_probes(&torus_meridian(frame, *major, *minor));
            (same_edge(&meridian, &parallel, (0, 0, 0), tol).is_none()).then_some([1, 2, 1])
        }
        SolidShape::Disk { .. } | SolidShape::Polygon { .. } => None,
    }
}

/// `probe_points` of `curve`. A whole ellipse (t from 0 to 2π, as
/// `solid_carriers::ellipse` makes them) takes the cosines and sines of the
/// probes' angles computed once, in `Curve::point`'s operations, so the same
/// bits: the six `sincos` calls were most of a torus's test.
fn ellipse_probes(curve: &Curve) -> [Point3; 3] {
    match curve {
        Curve::Ellipse {
            center,
            major,
            minor,
            t0,
            t1,
        } if (t0.to_bits(), t1.to_bits()) == (0.0f64.to_bits(), TAU.to_bits()) => {
            PROBE_TRIG
                .get_or_init(|| {
                    [0.25, 0.5, 0.75].map(|s| {
                        // Computed at run time as `Curve::point` computes
                        // them (never folded by the compiler's own libm).
                        let t = t0 + (t1 - t0) * std::hint::black_box(s);
                        (t.cos(), t.sin())
                    })
                })
                .map(|trig| ellipse_point_trig(center, major, minor, trig))
        }
        _ => probe_points(curve),
    }
}

/// The cosines and sines of a whole ellipse's three probe angles.
static PROBE_TRIG: OnceLock<[(f64, f64); 3]> = OnceLock::new();

fn at(frame: &Frame, x: f64, y: f64, z: f64) -> Point3 {
    frame.to_global(&Point3::new(x, y, z))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::{Mat3, Vec3};

    fn frame(linear: Mat3) -> Frame {
        Frame {
            origin: Point3::new(3.0, -1.0, 0.5),
            linear,
        }
    }

    /// The counts of welding `shape` through the local weld's rules.
    fn welded(shape: &SolidShape, tol: f64) -> [u32; 3] {
        super::super::isolated::weld_counts(shape, tol)
    }

    /// Regular shapes, and ones degenerate at, just under and just over the
    /// tolerance (a box edge, a ball's axis, a cone's height and radii).
    fn shapes(tol: f64) -> Vec<SolidShape> {
        let turned = Mat3::new(0.0, -2.0, 0.1, 1.5, 0.0, 0.0, 0.2, 0.0, 0.7);
        let mut linears = vec![
            Mat3::identity(),
            turned,
            Mat3::from_diagonal(&Vec3::new(-1.0, 0.5, 2.0)),
            Mat3::zeros(),
        ];
        for size in [0.0, 0.5 * tol, tol, 1.0001 * tol, 3.0 * tol] {
            linears.push(Mat3::from_diagonal(&Vec3::new(1.0, size, 2.0)));
            linears.push(Mat3::from_diagonal(&Vec3::new(0.5, 1.0, size)));
        }
        let mut shapes = Vec::new();
        for linear in linears {
            let f = frame(linear);
            shapes.push(SolidShape::Box { frame: f });
            shapes.push(SolidShape::Ball { frame: f });
            for (r0, r1) in [(0.4, 0.2), (0.0, 0.3), (0.3, 0.0), (0.25, 0.25), (0.0, 0.0)] {
                shapes.push(SolidShape::Cone { frame: f, r0, r1 });
            }
            for (major, minor) in [(0.5, 0.1), (0.0, 0.5), (0.5, 0.0), (0.0, 0.0), (-0.5, 0.5)] {
                shapes.push(SolidShape::Torus {
                    frame: f,
                    major,
                    minor,
                });
            }
        }
        // A cone whose one rim's cap centre lies on the side's sample, and
        // two rims at the same point (a flat cone of equal radii).
        let flat = frame(Mat3::from_diagonal(&Vec3::new(1.0, 1.0, 0.0)));
        shapes.push(SolidShape::Cone {
            frame: flat,
            r0: 0.0,
            r1: 0.0,
        });
        shapes.push(SolidShape::Cone {
            frame: flat,
            r0: 0.5,
            r1: 0.5,
        });
        shapes
    }

    #[test]
    fn unwelded_counts_are_given_exactly_when_the_weld_merges_nothing() {
        let tol = 1e-3;
        let (mut told, mut welds) = (0, 0);
        for shape in &shapes(tol) {
            let brep = super::super::brep::of(shape);
            let whole = [brep.vertices.len(), brep.edges.len(), brep.faces.len()].map(|n| n as u32);
            let counts = welded(shape, tol);
            let judged = match shape {
                SolidShape::Box { .. } | SolidShape::Ball { .. } | SolidShape::Torus { .. } => true,
                SolidShape::Cone { r0, r1, .. } => *r0 > 0.0 || *r1 > 0.0,
                _ => false,
            };
            let expected = (judged && counts == whole).then_some(counts);
            assert_eq!(unwelded_counts(shape, tol), expected, "{shape:?}");
            match expected {
                Some(_) => told += 1,
                None if judged => welds += 1,
                None => {}
            }
        }
        // Both answers occur: regular shapes and degenerate ones.
        assert!(told > 20 && welds > 10, "{told} told apart, {welds} welded");
    }

    #[test]
    fn whole_ellipses_probe_bit_for_bit_as_their_curves() {
        use crate::geom::solid_carriers::{ellipse, torus_meridian, torus_parallel};
        let mut linears = vec![
            Mat3::identity(),
            Mat3::zeros(),
            Mat3::new(0.0, -2.0, 0.1, 1.5, 0.0, 0.0, 0.2, 0.0, 0.7),
            Mat3::from_diagonal(&Vec3::new(-1.0, 0.5, 0.0)),
            Mat3::identity() * 1e300,
            Mat3::identity() * f64::NAN,
        ];
        let mut x = 0.61_f64;
        for _ in 0..30 {
            linears.push(Mat3::from_fn(|_, _| {
                x = (x * 3.9 * (1.0 - x)).clamp(1e-9, 1.0 - 1e-9);
                7.0 * x - 3.5
            }));
        }
        let bits = |points: [Point3; 3]| points.map(|p| p.coords.map(f64::to_bits));
        let mut whole = 0;
        for linear in linears {
            let f = frame(linear);
            for (major, minor) in [(0.5, 0.1), (0.0, 0.0), (-0.5, 2.0), (1e-300, 3e7)] {
                let curves = [
                    torus_parallel(&f, major, minor),
                    torus_meridian(&f, major, minor),
                    ellipse(&f, Vec3::zeros(), Vec3::x() * major, Vec3::y() * minor),
                ];
                for curve in &curves {
                    assert_eq!(bits(ellipse_probes(curve)), bits(probe_points(curve)));
                    whole += 1;
                }
            }
            // Not whole ellipses: the curve's own probes.
            let Curve::Ellipse {
                center,
                major,
                minor,
                ..
            } = ellipse(&f, Vec3::zeros(), Vec3::x(), Vec3::z())
            else {
                unreachable!("ellipse makes an ellipse")
            };
            let half = Curve::Ellipse {
                center,
                major,
                minor,
                t0: 0.0,
                t1: std::f64::consts::PI,
            };
            let segment = Curve::Segment {
                a: f.origin,
                b: f.to_global(&Point3::new(1.0, 2.0, 3.0)),
            };
            for curve in [half, segment] {
                assert_eq!(bits(ellipse_probes(&curve)), bits(probe_points(&curve)));
            }
        }
        assert_eq!(whole, 36 * 4 * 3);
    }

    #[test]
    fn regular_primitives_need_no_weld_and_degenerate_ones_do() {
        let tol = 1e-6;
        let f = frame(Mat3::identity());
        let regular = [
            (SolidShape::Box { frame: f }, [8, 12, 6]),
            (SolidShape::Ball { frame: f }, [1, 1, 2]),
            (
                SolidShape::Cone {
                    frame: f,
                    r0: 0.4,
                    r1: 0.2,
                },
                [2, 2, 3],
            ),
            (
                SolidShape::Cone {
                    frame: f,
                    r0: 0.0,
                    r1: 0.3,
                },
                [1, 1, 2],
            ),
        ];
        for (shape, counts) in regular {
            assert_eq!(unwelded_counts(&shape, tol), Some(counts), "{shape:?}");
        }
        let flat = frame(Mat3::from_diagonal(&Vec3::new(1.0, 1.0, 0.0)));
        // A flat box's corners pair up; a flat ball's poles meet.
        assert_eq!(unwelded_counts(&SolidShape::Box { frame: flat }, tol), None);
        assert_eq!(
            unwelded_counts(&SolidShape::Ball { frame: flat }, tol),
            None
        );
        // A torus's circles meet only when both shrink to its centre.
        let torus = |major, minor| SolidShape::Torus {
            frame: f,
            major,
            minor,
        };
        assert_eq!(unwelded_counts(&torus(0.5, 0.1), tol), Some([1, 2, 1]));
        assert_eq!(unwelded_counts(&torus(0.0, 0.5), tol), Some([1, 2, 1]));
        assert_eq!(unwelded_counts(&torus(0.0, 0.0), tol), None);
    }
}
