//! The welding tolerance: a millionth of the diagonal of everything the
//! file places.

use crate::geom::{Aabb, SolidShape};
use crate::resolve::{Geometry, Resolved};

/// 1e-6 of the diagonal of everything the file places, at least 1e-12.
/// `known` are solids met in this order by the walk below (the isolation's
/// shapes, a subsequence of it) with their boxes `boxes`: those are taken,
/// not remade, and the boxes are united in the same order as before.
pub(super) fn of(resolved: &Resolved, known: &[&SolidShape], boxes: &[Aabb]) -> f64 {
    debug_assert_eq!(known.len(), boxes.len());
    let mut next = 0;
    let mut box_of = |s: &SolidShape| match known.get(next) {
        Some(&k) if std::ptr::eq(k, s) => {
            next += 1;
            boxes[next - 1]
        }
        _ => s.bbox(),
    };
    let mut bbox = Aabb::empty();
    fn visit(g: &Geometry, bbox: &mut Aabb, box_of: &mut impl FnMut(&SolidShape) -> Aabb) {
        match g {
            Geometry::Solid(s) => *bbox = bbox.union(&box_of(s)),
            Geometry::Points { points, .. } | Geometry::Polyline { points, .. } => {
                points.iter().for_each(|p| bbox.include(p))
            }
            Geometry::Vertex(p) => bbox.include(p),
            Geometry::PointCurve(c) => c.samples(32).iter().for_each(|p| bbox.include(p)),
            Geometry::Patch(patch) => patch.rows.iter().flatten().for_each(|p| bbox.include(p)),
            Geometry::Trimmed(s) => s.samples(8).iter().for_each(|p| bbox.include(p)),
            Geometry::Group(members) => members.iter().for_each(|m| visit(m, bbox, box_of)),
            _ => {}
        }
    }
    for o in &resolved.objects {
        if let Some(g) = &o.geometry {
            visit(g, &mut bbox, &mut box_of);
        }
    }
    debug_assert_eq!(next, known.len(), "every known box is used");
    (1e-6 * bbox.diagonal()).max(1e-12)
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::geom::{Frame, Mat3, Point3};
    use crate::resolve::{Link, NameIndex, ResolvedObject};
    use crate::test_rng::TestRng;

    /// A coordinate: mostly random, sometimes zero, huge, infinite or NaN.
    fn value(rng: &mut TestRng) -> f64 {
        match rng.below(24) {
            0 => f64::NAN,
            1 => f64::INFINITY,
            2 => -1e300,
            3 => 0.0,
            4 => -0.0,
            _ => rng.within(1_000_000) as f64 / 1000.0,
        }
    }

    /// Random primitive shapes of every kind, most of them finite.
    pub(in crate::lower) fn random_shape(rng: &mut TestRng, odd: bool) -> SolidShape {
        let number = |rng: &mut TestRng| {
            if odd {
                value(rng)
            } else {
                rng.within(1_000_000) as f64 / 1000.0
            }
        };
        let frame = Frame {
            origin: Point3::new(number(rng), number(rng), number(rng)),
            linear: Mat3::from_fn(|_, _| rng.within(3000) as f64 / 1000.0),
        };
        let (a, b) = (number(rng).abs(), number(rng).abs());
        match rng.below(6) {
            0 => SolidShape::Ball { frame },
            1 => SolidShape::Box { frame },
            2 => SolidShape::Cone {
                frame,
                r0: a,
                r1: b,
            },
            3 => SolidShape::Torus {
                frame,
                major: a,
                minor: b,
            },
            4 => SolidShape::Disk { frame },
            _ => SolidShape::Polygon {
                frame,
                vertices: (0..3 + rng.below(4))
                    .map(|_| Point3::new(number(rng), number(rng), 0.0))
                    .collect(),
            },
        }
    }

    /// Objects of every kind the walk visits: solids, groups (some nested),
    /// points, vertices, failed objects, and solids that carry an edge
    /// (which the isolation leaves out).
    fn random_objects(rng: &mut TestRng, odd: bool) -> Resolved {
        let mut objects = Vec::new();
        for k in 0..60 {
            let geometry = match rng.below(8) {
                0 => None,
                1 => Some(Geometry::Group(
                    (0..rng.below(4))
                        .map(|_| match rng.below(3) {
                            0 => Geometry::Group(vec![Geometry::Solid(random_shape(rng, odd))]),
                            _ => Geometry::Solid(random_shape(rng, odd)),
                        })
                        .collect(),
                )),
                2 => Some(Geometry::Vertex(Point3::new(value(rng), 1.0, 2.0))),
                3 if k > 0 => Some(Geometry::Edge {
                    line: Some(Link {
                        object: rng.below(k),
                        span: Default::default(),
                    }),
                    begin: Link {
                        object: 0,
                        span: Default::default(),
                    },
                    end: Link {
                        object: 0,
                        span: Default::default(),
                    },
                }),
                4 => Some(Geometry::Points {
                    points: vec![Point3::new(value(rng), -3.0, 4.0)],
                    partial: vec![false],
                }),
                _ => Some(Geometry::Solid(random_shape(rng, odd))),
            };
            objects.push(ResolvedObject {
                name: format!("o{k}"),
                span: Default::default(),
                geometry,
            });
        }
        Resolved {
            dimension: 3,
            objects,
            by_name: NameIndex::default(),
            parameters: Vec::new(),
            subdomain_areas: Vec::new(),
        }
    }

    /// The tolerance from the isolation's boxes is the one with every box
    /// made again (`known` empty: every solid's `bbox()` in walk order, as
    /// before the boxes were kept), bit for bit, NaN and infinite boxes too.
    #[test]
    fn the_kept_boxes_give_the_tolerance_of_boxes_made_again() {
        let mut rng = TestRng::new(0x70_1e_5a_7c);
        let (mut skipped, mut taken, mut not_finite) = (0, 0, 0);
        for case in 0..400 {
            let resolved = random_objects(&mut rng, case % 2 == 1);
            let edge_lines = super::super::point_calculus::edge_lines(&resolved);
            let shapes = super::super::isolation::solid_shapes(&resolved, &edge_lines);
            let boxes = super::super::isolation::shape_boxes(&shapes);
            let kept = of(&resolved, &shapes, &boxes);
            let made = of(&resolved, &[], &[]);
            assert_eq!(kept.to_bits(), made.to_bits(), "case {case}");
            let mut all = 0;
            fn count(g: &Geometry, all: &mut usize) {
                match g {
                    Geometry::Solid(_) => *all += 1,
                    Geometry::Group(m) => m.iter().for_each(|g| count(g, all)),
                    _ => {}
                }
            }
            (resolved.objects.iter().filter_map(|o| o.geometry.as_ref()))
                .for_each(|g| count(g, &mut all));
            skipped += all - shapes.len();
            taken += shapes.len();
            not_finite += usize::from(!made.is_finite());
        }
        // Every path was taken: boxes kept, solids left to be made again
        // (edge lines, nested groups), and tolerances that are not finite.
        assert!(taken > 10_000 && skipped > 1_000, "{taken} {skipped}");
        assert!(not_finite > 10 && not_finite < 390, "{not_finite}");
    }
}
