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

/// Per shape: whether it is isolated. Entities weld only when their positions
/// are within `tol` (edges need welded ends, faces welded edges or, without
/// edges, interior samples within `tol`), so a solid is isolated when the box
/// of its vertex positions and face samples, widened by twice the tolerance
/// (a margin for rounding), meets no other solid's. A box that is not finite
/// (a position the welder cannot place) is never called isolated.
pub(super) fn isolated(shapes: &[&SolidShape], tol: f64) -> Vec<bool> {
    // Each box is a pure function of its shape: made in parallel, in order.
    let boxes: Vec<Aabb> = shapes
        .par_iter()
        .with_min_len(1024)
        .map(|shape| {
            let mut bbox = Aabb::empty();
            brep::anchors(shape, |p| bbox.include(&p));
            bbox
        })
        .collect();
    let finite = |b: &Aabb| {
        [b.min, b.max]
            .iter()
            .all(|p| p.iter().all(|c| c.is_finite()))
            && !b.is_empty()
    };
    let mut isolated: Vec<bool> = boxes.iter().map(finite).collect();
    // Non-finite boxes are left out of the pairs (and not isolated above).
    for (i, j) in super::booleans::candidate_pairs(&boxes, 2.0 * tol) {
        isolated[i] = false;
        isolated[j] = false;
    }
    isolated
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
        assert_eq!(isolated(&refs, tol), vec![false, false, false, false, true]);
    }

    #[test]
    fn a_solid_with_a_non_finite_position_is_never_isolated() {
        let shapes = [unit_box(f64::NAN, 0.0, 0.0), unit_box(5.0, 0.0, 0.0)];
        let refs: Vec<&SolidShape> = shapes.iter().collect();
        assert_eq!(isolated(&refs, 1e-6), vec![false, true]);
    }
}
