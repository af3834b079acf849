//! Which primitive solids are isolated: no entity of another solid lies within
//! the welding tolerance of theirs. The welder welds an isolated solid's
//! entities in small tables restarted per solid, so on large files of separate
//! primitives its shared tables stay empty (time and peak memory).

use super::brep;
use crate::geom::{Aabb, SolidShape};
use crate::resolve::{Geometry, Resolved};
use rayon::prelude::*;
use std::collections::HashSet;

/// The primitive solids in the order `lower` lowers them (objects in order,
/// group members in order; failed objects and edge-carrying curves skipped).
pub(super) fn solid_shapes<'r>(
    resolved: &'r Resolved,
    edge_lines: &HashSet<&str>,
) -> Vec<&'r SolidShape> {
    let mut shapes = Vec::new();
    for object in &resolved.objects {
        let Some(geometry) = &object.geometry else {
            continue;
        };
        if edge_lines.contains(object.name.as_str()) {
            continue;
        }
        match geometry {
            Geometry::Group(members) => shapes.extend(members.iter().filter_map(|m| match m {
                Geometry::Solid(shape) => Some(shape),
                _ => None,
            })),
            Geometry::Solid(shape) => shapes.push(shape),
            _ => {}
        }
    }
    shapes
}

/// Each shape's `bbox()`, in order, made on the workers.
pub(super) fn shape_boxes(shapes: &[&SolidShape]) -> Vec<Aabb> {
    (shapes.par_iter())
        .with_min_len(1024)
        .map(|shape| shape.bbox())
        .collect()
}

/// What one candidate grid over the primitive solids gives: which solids are
/// isolated (for the welder), and which pairs' bounding boxes overlap within
/// the tolerance (for the crossing check, `booleans::check_relations`, which
/// otherwise sorts a grid of nearly the same boxes a second time).
pub(super) struct SolidPairs {
    /// Per shape: whether it is isolated.
    pub isolated: Vec<bool>,
    /// `None` when a box is not finite or inverted (`candidate_pairs` leaves
    /// such boxes out, so the crossing check makes its own grid then).
    pub overlapping: Option<Overlapping>,
}

/// The shapes whose bounding boxes overlap within the tolerance.
pub(super) struct Overlapping {
    /// How many shapes there were: the solids lowered from them, in order,
    /// have these indices as ids.
    pub solids: usize,
    /// Pairs (i, j), i < j, sorted: exactly what `candidate_pairs` over the
    /// shapes' `bbox()`es gives.
    pub pairs: Vec<(u32, u32)>,
}

/// Per shape: whether it is isolated, and the overlapping bounding boxes.
/// `boxes` are the shapes' `bbox()`es ([`shape_boxes`]); their vector
/// becomes the grid's (each box widened to its hull in place).
/// Entities weld only when their positions are within `tol` (edges need
/// welded ends, faces welded edges or, without edges, interior samples within
/// `tol`), so a solid is isolated when the box of its vertex positions and
/// face samples (its anchors), widened by twice the tolerance (a margin for
/// rounding), meets no other solid's. A box that is not finite (a position
/// the welder cannot place) is never called isolated.
///
/// One grid serves both questions: its boxes hold each shape's anchors and
/// its `bbox()` with the larger margin, so every pair either question
/// finds is among the grid's pairs, which are then tested exactly.
pub(super) fn pairs(shapes: &[&SolidShape], boxes: Vec<Aabb>, tol: f64) -> SolidPairs {
    debug_assert_eq!(shapes.len(), boxes.len());
    // Each hull is a pure function of its shape: made in parallel, in order.
    let mut hulls = boxes;
    let placeable: Vec<(bool, bool)> = (hulls.par_iter_mut().zip(shapes))
        .with_min_len(1024)
        .map(|(bbox, shape)| {
            let anchors = anchor_box(shape);
            let placeable = (finite(&anchors), in_order(&anchors) && in_order(bbox));
            *bbox = anchors.union(bbox);
            placeable
        })
        .collect();
    let mut isolated: Vec<bool> = placeable.iter().map(|&(finite, _)| finite).collect();
    let margin = 2.0 * tol;
    if !placeable.iter().all(|&(finite, ordered)| finite && ordered) {
        // Boxes the grid leaves out: each question on its own boxes, as before.
        drop(hulls);
        let anchors: Vec<Aabb> = shapes.par_iter().map(|s| anchor_box(s)).collect();
        for (i, j) in super::booleans::candidate_pairs(&anchors, margin) {
            isolated[i] = false;
            isolated[j] = false;
        }
        return SolidPairs {
            isolated,
            overlapping: None,
        };
    }
    let mut overlapping = Vec::new();
    // Every pair of either question is here: a hull holds both boxes and the
    // margin is the larger one (the rounding of `min - margin` is monotone).
    for (i, j) in super::booleans::candidate_pairs(&hulls, margin) {
        let (a, b) = (shapes[i], shapes[j]);
        if anchor_box(a).overlaps(&anchor_box(b), margin) {
            isolated[i] = false;
            isolated[j] = false;
        }
        if a.bbox().overlaps(&b.bbox(), tol) {
            overlapping.push((i as u32, j as u32));
        }
    }
    SolidPairs {
        isolated,
        overlapping: Some(Overlapping {
            solids: shapes.len(),
            pairs: overlapping,
        }),
    }
}

/// The box of a shape's anchors (the points the welder places).
fn anchor_box(shape: &SolidShape) -> Aabb {
    let mut bbox = Aabb::empty();
    brep::anchors(shape, |p| bbox.include(&p));
    bbox
}

/// Finite and not empty: a box the welder can place.
fn finite(b: &Aabb) -> bool {
    [b.min, b.max]
        .iter()
        .all(|p| p.iter().all(|c| c.is_finite()))
        && !b.is_empty()
}

/// Finite with min ≤ max on every axis: a box `candidate_pairs` pairs with
/// every box it overlaps.
fn in_order(b: &Aabb) -> bool {
    finite(b) && (0..3).all(|k| b.min[k] <= b.max[k])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::{Frame, Mat3, Point3, Vec3};

    fn unit_box(x: f64, y: f64, z: f64) -> SolidShape {
        SolidShape::Box {
            frame: Frame {
                origin: Point3::new(x, y, z),
                linear: Mat3::from_diagonal(&Vec3::new(1.0, 1.0, 1.0)),
            },
        }
    }

    #[test]
    fn touching_solids_are_not_isolated_and_distant_ones_are() {
        let tol = 1e-6;
        // The first two share the face x = 1; the third is 2 away; the fourth
        // is 1.5 tolerances away from the third's corner x = 4 (within the
        // doubled margin), the fifth 0.001 away from everything.
        let shapes = [
            unit_box(0.0, 0.0, 0.0),
            unit_box(1.0, 0.0, 0.0),
            unit_box(3.0, 0.0, 0.0),
            unit_box(4.0 + 1.5e-6, 0.0, 0.0),
            unit_box(0.0, 0.0, 1.001),
        ];
        let refs: Vec<&SolidShape> = shapes.iter().collect();
        assert_eq!(
            pairs(&refs, shape_boxes(&refs), tol).isolated,
            vec![false, false, false, false, true]
        );
    }

    #[test]
    fn a_solid_with_a_non_finite_position_is_never_isolated() {
        let shapes = [unit_box(f64::NAN, 0.0, 0.0), unit_box(5.0, 0.0, 0.0)];
        let refs: Vec<&SolidShape> = shapes.iter().collect();
        let found = pairs(&refs, shape_boxes(&refs), 1e-6);
        assert_eq!(found.isolated, vec![false, true]);
        // The grid leaves the NaN box out, so the crossing check makes its own.
        assert!(found.overlapping.is_none());
    }

    fn unit_ball(x: f64) -> SolidShape {
        SolidShape::Ball {
            frame: Frame {
                origin: Point3::new(x, 0.0, 0.0),
                linear: Mat3::identity(),
            },
        }
    }

    #[test]
    fn overlapping_pairs_are_those_of_a_grid_of_the_bounding_boxes() {
        let tol = 1e-6;
        // Two boxes sharing the face x = 1; two balls whose bounding boxes
        // overlap (x in [4, 6] and [5.5, 7.5]) while their anchors (x from 5
        // to 6 and from 6.5 to 7.5) are apart, so both stay isolated; a box
        // far from everything.
        let shapes = [
            unit_box(0.0, 0.0, 0.0),
            unit_box(1.0, 0.0, 0.0),
            unit_ball(5.0),
            unit_ball(6.5),
            unit_box(20.0, 0.0, 0.0),
        ];
        let refs: Vec<&SolidShape> = shapes.iter().collect();
        let found = pairs(&refs, shape_boxes(&refs), tol);
        assert_eq!(found.isolated, vec![false, false, true, true, true]);
        let overlapping = found.overlapping.map(|o| o.pairs);
        assert_eq!(overlapping, Some(vec![(0, 1), (2, 3)]));
        let boxes: Vec<Aabb> = shapes.iter().map(SolidShape::bbox).collect();
        let by_grid: Vec<(u32, u32)> = super::super::booleans::candidate_pairs(&boxes, tol)
            .into_iter()
            .map(|(i, j)| (i as u32, j as u32))
            .collect();
        assert_eq!(overlapping, Some(by_grid));
    }
}
