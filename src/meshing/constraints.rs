//! Poly_lines as internal constraints of 2D meshes (cracks, interfaces,
//! sensor lines): each poly_line that lies inside one subdomain's region is
//! handed to that face's triangulation, which must follow it.
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

/// Even–odd over all loops.
fn in_loops(loops: &[Vec<Point3>], p: &Point3) -> bool {
    loops
        .iter()
        .filter(|lp| polygon::contains(lp, [p.x, p.y]))
        .count()
        % 2
        == 1
}
