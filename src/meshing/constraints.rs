//! Poly_lines as internal constraints of 2D meshes (cracks, interfaces,
//! sensor lines): each poly_line that lies inside one subdomain's region is
//! handed to that face's triangulation, which must follow it.
//!
//! A poly_line belongs to a region when all its points and segment middles
//! are inside it (even–odd over the face's loops). Any point within the
//! model tolerance of a loop, or a segment crossing a loop between those
//! probes, makes it touch the boundary: that is refused rather than decided
//! by rounding (a line drawn along the slanted side of a thin polygon lies
//! on it in decimals but a few ulps outside or inside in binary, and the
//! even–odd test alone put such a line inside).
//!
//! # Limitations
//! - A poly_line must lie strictly inside one region: touching or crossing a
//!   subdomain boundary is refused. Outside every region it stays a free
//!   line of nodes, as in 3D.
//! - The mesh follows the line; `crack="true"` lines are then opened by
//!   `crack.rs`.

use super::MeshError;
use super::edges::EdgeNodes;
use crate::geom::{Point3, polygon};
use crate::ir::{Dimension, Model, SubdomainCells};
use std::collections::BTreeMap;

/// Poly_lines per face index: (poly_line index, its points).
pub(crate) type Constraints = BTreeMap<usize, Vec<(usize, Vec<Point3>)>>;

/// `lines[i]`: poly_line i's points as meshing samples them.
pub(crate) fn assign(
    model: &Model,
    edge_nodes: &[EdgeNodes],
    lines: &[Vec<Point3>],
) -> Result<Constraints, MeshError> {
    let mut out = Constraints::new();
    if model.dimension != Dimension::Two || model.polylines.is_empty() {
        return Ok(out);
    }
    let mut regions: Vec<(usize, Vec<Vec<Point3>>)> = Vec::new();
    for sub in &model.subdomains {
        if let SubdomainCells::Region { faces } = &sub.cells {
            for f in faces {
                if let Some(face) = model.faces.get(f.index()) {
                    regions.push((f.index(), face_polygons(face, edge_nodes)));
                }
            }
        }
    }
    for ((index, line), points) in model.polylines.iter().enumerate().zip(lines) {
        let mut probes: Vec<Point3> = points.clone();
        probes.extend(
            points
                .windows(2)
                .map(|w| Point3::from((w[0].coords + w[1].coords) / 2.0)),
        );
        let mut home = None;
        for (face, loops) in &regions {
            if touches(loops, points, &probes, model.tolerance) {
                return Err(MeshError::Face {
                    face: model.faces[*face].name.clone(),
                    reason: format!(
                        "poly_line `{}` touches or crosses its boundary (within the tolerance {:e}); a poly_line constraint must lie strictly inside one subdomain",
                        line.name, model.tolerance
                    ),
                });
            }
            let inside = probes.iter().filter(|p| in_loops(loops, p)).count();
            if inside == probes.len() {
                home = Some(*face);
                break;
            }
            if inside > 0 {
                return Err(MeshError::Face {
                    face: model.faces[*face].name.clone(),
                    reason: format!(
                        "poly_line `{}` is partly outside it; a poly_line constraint must lie inside one subdomain",
                        line.name
                    ),
                });
            }
        }
        if let Some(face) = home {
            out.entry(face).or_default().push((index, points.clone()));
        }
    }
    Ok(out)
}

/// The face's loops as closed point lists (the edges' discretisations).
fn face_polygons(face: &crate::ir::Face, edge_nodes: &[EdgeNodes]) -> Vec<Vec<Point3>> {
    face.loops
        .iter()
        .map(|lp| {
            let mut points = Vec::new();
            for oe in lp {
                let Some(nodes) = edge_nodes.get(oe.edge.index()) else {
                    continue;
                };
                let n = nodes.points.len();
                let take = n.saturating_sub(1);
                if oe.forward {
                    points.extend(nodes.points.iter().take(take).copied());
                } else {
                    points.extend(nodes.points.iter().rev().take(take).copied());
                }
            }
            points
        })
        .collect()
}

/// Whether a probe lies within `tolerance` of a loop segment, or a segment
/// of the line crosses one.
fn touches(loops: &[Vec<Point3>], line: &[Point3], probes: &[Point3], tolerance: f64) -> bool {
    let loop_segments = || {
        loops
            .iter()
            .flat_map(|lp| (0..lp.len()).map(move |k| (&lp[k], &lp[(k + 1) % lp.len()])))
    };
    if probes
        .iter()
        .any(|p| loop_segments().any(|(a, b)| polygon::segment_distance(p, a, b) <= tolerance))
    {
        return true;
    }
    line.windows(2)
        .any(|w| loop_segments().any(|(a, b)| segments_cross(&w[0], &w[1], a, b)))
}

/// Proper crossing of segments p–q and a–b (each strictly separates the
/// other's ends).
fn segments_cross(p: &Point3, q: &Point3, a: &Point3, b: &Point3) -> bool {
    let orient =
        |u: &Point3, v: &Point3, w: &Point3| (v.x - u.x) * (w.y - u.y) - (v.y - u.y) * (w.x - u.x);
    let (d1, d2) = (orient(p, q, a), orient(p, q, b));
    let (d3, d4) = (orient(a, b, p), orient(a, b, q));
    d1 * d2 < 0.0 && d3 * d4 < 0.0
}

/// Even–odd over all loops.
fn in_loops(loops: &[Vec<Point3>], p: &Point3) -> bool {
    loops
        .iter()
        .filter(|lp| polygon::contains(lp, [p.x, p.y]))
        .count()
        % 2
        == 1
}
