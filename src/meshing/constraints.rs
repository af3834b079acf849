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
//! The one contact allowed is at a tip: a poly_line whose first or last
//! point lies on the region's boundary (within the tolerance) and whose
//! other points are inside is an edge crack or an interface reaching the
//! boundary. The boundary edge is split at the nearest curve point, and
//! the tip moved onto that node, so the mesh stays conforming.
//!
//! # Limitations
//! - Touching or crossing a subdomain boundary anywhere but at a tip is
//!   refused, as are two poly_lines of one region that cross or touch
//!   (named both). Outside every region a poly_line stays a free line of
//!   nodes, as in 3D.
//! - The mesh follows the line; `crack="true"` lines are then opened by
//!   `crack.rs`.

use super::MeshError;
use super::edges::EdgeNodes;
use crate::geom::{Point3, polygon};
use crate::ir::{Dimension, Model, SubdomainCells};
use std::collections::BTreeMap;

/// Poly_lines per face index: (poly_line index, its points).
pub(crate) type Constraints = BTreeMap<usize, Vec<(usize, Vec<Point3>)>>;

/// One segment of a face loop: its ends and the edge and curve parameters
/// they come from.
struct LoopSegment {
    a: Point3,
    b: Point3,
    edge: usize,
    sa: f64,
    sb: f64,
}

/// `lines[i]`: poly_line i's points as meshing samples them. A tip on a
/// region's boundary adds a node to the boundary edge in `edge_nodes`.
pub(crate) fn assign(
    model: &Model,
    edge_nodes: &mut [EdgeNodes],
    lines: &[Vec<Point3>],
) -> Result<Constraints, MeshError> {
    let mut out = Constraints::new();
    if model.dimension != Dimension::Two || model.polylines.is_empty() {
        return Ok(out);
    }
    let mut regions: Vec<(usize, Vec<Vec<LoopSegment>>)> = Vec::new();
    for sub in &model.subdomains {
        if let SubdomainCells::Region { faces } = &sub.cells {
            for f in faces {
                if let Some(face) = model.faces.get(f.index()) {
                    regions.push((f.index(), face_loops(face, edge_nodes)));
                }
            }
        }
    }
    let tolerance = model.tolerance;
    for ((index, line), points) in model.polylines.iter().enumerate().zip(lines) {
        let mut probes: Vec<Point3> = points.clone();
        probes.extend(
            points
                .windows(2)
                .map(|w| Point3::from((w[0].coords + w[1].coords) / 2.0)),
        );
        let last = points.len().saturating_sub(1);
        let mut home = None;
        for (face, loops) in &regions {
            let refuse = |reason: String| MeshError::Face {
                face: model.faces[*face].name.to_string(),
                reason,
            };
            let touching = |p: &Point3| nearest_segment(loops, p).filter(|(_, d)| *d <= tolerance);
            // Tips on the boundary are allowed; any other contact is not.
            let tips: Vec<(usize, usize, usize)> = [0, last]
                .into_iter()
                .filter(|&k| k < points.len())
                .filter_map(|k| touching(&points[k]).map(|((l, s), _)| (k, l, s)))
                .collect();
            let tip_ends: Vec<usize> = tips.iter().map(|t| t.0).collect();
            let other_contact = probes
                .iter()
                .enumerate()
                .any(|(k, p)| !tip_ends.contains(&k) && touching(p).is_some())
                || crosses(loops, points, &tip_ends, tolerance)
                || runs_along_at_tip(loops, points, &tip_ends, tolerance);
            if other_contact {
                return Err(refuse(format!(
                    "poly_line `{}` touches or crosses its boundary (within the tolerance {:e}) away from its end points; a poly_line constraint must lie inside one subdomain, touching its boundary only at its first or last point",
                    line.name, tolerance
                )));
            }
            let inside = probes
                .iter()
                .enumerate()
                .filter(|(k, p)| !tip_ends.contains(k) && in_loops(loops, p))
                .count();
            if inside == probes.len() - tip_ends.len() && inside > 0 {
                let mut points = points.clone();
                for &(k, l, s) in &tips {
                    points[k] = tip_on_edge(model, edge_nodes, &loops[l][s], &points[k]);
                }
                home = Some((*face, points));
                break;
            }
            if inside > 0 {
                return Err(refuse(format!(
                    "poly_line `{}` is partly outside it; a poly_line constraint must lie inside one subdomain",
                    line.name
                )));
            }
        }
        if let Some((face, points)) = home {
            out.entry(face).or_default().push((index, points));
        }
    }
    for (face, lines) in &out {
        refuse_crossing_lines(model, *face, lines, tolerance)?;
    }
    Ok(out)
}

/// The face's loops as segments of the edges' discretisations.
fn face_loops(face: &crate::ir::Face, edge_nodes: &[EdgeNodes]) -> Vec<Vec<LoopSegment>> {
    face.loops
        .iter()
        .map(|lp| {
            let mut segments = Vec::new();
            for oe in lp {
                let Some(nodes) = edge_nodes.get(oe.edge.index()) else {
                    continue;
                };
                for k in 1..nodes.points.len() {
                    let (i, j) = if oe.forward { (k - 1, k) } else { (k, k - 1) };
                    segments.push(LoopSegment {
                        a: nodes.points[i],
                        b: nodes.points[j],
                        edge: oe.edge.index(),
                        sa: nodes.params[i],
                        sb: nodes.params[j],
                    });
                }
            }
            segments
        })
        .collect()
}

/// The loop segment nearest to `p` as (loop, segment) and its distance.
fn nearest_segment(loops: &[Vec<LoopSegment>], p: &Point3) -> Option<((usize, usize), f64)> {
    let mut best: Option<((usize, usize), f64)> = None;
    for (l, lp) in loops.iter().enumerate() {
        for (s, seg) in lp.iter().enumerate() {
            let d = polygon::segment_distance(p, &seg.a, &seg.b);
            if best.is_none_or(|(_, b)| d < b) {
                best = Some(((l, s), d));
            }
        }
    }
    best
}

/// Whether a segment of the line properly crosses a loop segment, leaving
/// out loop segments within `tolerance` of a tip on the boundary (the line
/// meets them there).
fn crosses(loops: &[Vec<LoopSegment>], line: &[Point3], tips: &[usize], tolerance: f64) -> bool {
    line.windows(2).enumerate().any(|(k, w)| {
        loops.iter().flatten().any(|seg| {
            let at_tip = [k, k + 1].iter().any(|i| {
                tips.contains(i)
                    && polygon::segment_distance(&line[*i], &seg.a, &seg.b) <= tolerance
            });
            !at_tip && segments_cross(&w[0], &w[1], &seg.a, &seg.b)
        })
    })
}

/// Whether a loop segment that meets a tip runs along the poly_line's piece
/// from that tip: its far end lies on the piece (within `tolerance`). The
/// probes (points and midpoints) miss such an overlap when it is shorter
/// than half the piece, and the triangulation would then take the shared
/// stretch as two constraints on one line (fuzz `triangulate`, session 7).
fn runs_along_at_tip(
    loops: &[Vec<LoopSegment>],
    line: &[Point3],
    tips: &[usize],
    tolerance: f64,
) -> bool {
    tips.iter().any(|&k| {
        let next = if k == 0 { 1 } else { k - 1 };
        let (Some(tip), Some(other)) = (line.get(k), line.get(next)) else {
            return false;
        };
        loops.iter().flatten().any(|seg| {
            polygon::segment_distance(tip, &seg.a, &seg.b) <= tolerance
                && [seg.a, seg.b].iter().any(|q| {
                    (q - tip).norm() > tolerance
                        && polygon::segment_distance(q, tip, other) <= tolerance
                })
        })
    })
}

/// Splits the boundary edge under a tip at the curve point nearest to it
/// and returns that node's position (the tip's new place).
fn tip_on_edge(
    model: &Model,
    edge_nodes: &mut [EdgeNodes],
    seg: &LoopSegment,
    tip: &Point3,
) -> Point3 {
    let (Some(edge), Some(nodes)) = (model.edges.get(seg.edge), edge_nodes.get_mut(seg.edge))
    else {
        return *tip;
    };
    let curve = edge.curve(&model.solids);
    let (lo, hi) = if seg.sa < seg.sb {
        (seg.sa, seg.sb)
    } else {
        (seg.sb, seg.sa)
    };
    // Golden-section search for the nearest curve point over the segment's
    // parameter range (exact for straight edges up to rounding).
    let distance = |s: f64| (curve.point(s) - tip).norm();
    let ratio = (5f64.sqrt() - 1.0) / 2.0;
    let (mut a, mut b) = (lo, hi);
    for _ in 0..80 {
        let (c, d) = (b - ratio * (b - a), a + ratio * (b - a));
        if distance(c) < distance(d) {
            b = d;
        } else {
            a = c;
        }
    }
    // The projection on the chord, exact for straight edges, unless the
    // search found a nearer point.
    let chord = seg.b - seg.a;
    let t = ((tip - seg.a).dot(&chord) / chord.norm_squared()).clamp(0.0, 1.0);
    let projected = seg.sa + t * (seg.sb - seg.sa);
    let searched = 0.5 * (a + b);
    let s = if distance(projected) <= distance(searched) {
        projected
    } else {
        searched
    };
    nodes.insert(&curve, s);
    // The node there (new, or an existing one within 1e-12 in parameter).
    nodes
        .points
        .iter()
        .min_by(|p, q| (*p - tip).norm().total_cmp(&(*q - tip).norm()))
        .copied()
        .unwrap_or(*tip)
}

/// Two poly_lines of one region that cross or touch: ambiguous (which one
/// is cut?), so refused naming both.
fn refuse_crossing_lines(
    model: &Model,
    face: usize,
    lines: &[(usize, Vec<Point3>)],
    tolerance: f64,
) -> Result<(), MeshError> {
    for (i, (a, pa)) in lines.iter().enumerate() {
        for (b, pb) in &lines[i + 1..] {
            let touch = pa.windows(2).any(|u| {
                pb.windows(2).any(|v| {
                    segments_cross(&u[0], &u[1], &v[0], &v[1])
                        || [&u[0], &u[1]]
                            .iter()
                            .any(|p| polygon::segment_distance(p, &v[0], &v[1]) <= tolerance)
                        || [&v[0], &v[1]]
                            .iter()
                            .any(|p| polygon::segment_distance(p, &u[0], &u[1]) <= tolerance)
                })
            });
            if touch {
                let name = |k: usize| model.polylines[k].name.clone();
                return Err(MeshError::Face {
                    face: model.faces[face].name.to_string(),
                    reason: format!(
                        "poly_lines `{}` and `{}` cross or touch (within the tolerance {:e}); constraints inside one subdomain must keep apart: end one short of the other or split them where they meet",
                        name(*a),
                        name(*b),
                        tolerance
                    ),
                });
            }
        }
    }
    Ok(())
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
fn in_loops(loops: &[Vec<LoopSegment>], p: &Point3) -> bool {
    let mut inside = false;
    for seg in loops.iter().flatten() {
        let (a, b) = (&seg.a, &seg.b);
        if (a.y > p.y) != (b.y > p.y) {
            let x = a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x);
            if x > p.x {
                inside = !inside;
            }
        }
    }
    inside
}
