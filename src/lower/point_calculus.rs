//! Paper 003's curves and patches in the model: standalone curves become
//! poly_lines that meshing samples exactly, curves and patch sides become the
//! curves of explicit edges, and patches the surfaces of explicit faces.

use crate::diag::{Code, Diagnostic, Diagnostics};
use crate::geom::point_calculus::PcCurve;
use crate::geom::{Curve, Point3};
use crate::ir::Polyline;
use crate::resolve::{Geometry, Resolved, fmt};
use crate::span::Span;
use std::collections::HashSet;

/// A standalone curve as a named line element.
pub(super) fn standalone(name: &str, curve: &PcCurve) -> Polyline {
    Polyline {
        name: name.to_string(),
        points: curve.samples(32),
        curve: Some(Curve::PointCalculus(Box::new(curve.clone()))),
        crack: false,
    }
}

/// Names of the objects some edge uses as its line.
pub(super) fn edge_lines(resolved: &Resolved) -> HashSet<&str> {
    resolved
        .objects
        .iter()
        .filter_map(|o| match &o.geometry {
            Some(Geometry::Edge {
                line: Some(link), ..
            }) => resolved.objects.get(link.object).map(|l| l.name.as_str()),
            _ => None,
        })
        .collect()
}

/// W180 for patches that no face is on.
pub(super) fn report_unused_patches(resolved: &Resolved, diags: &mut Diagnostics) {
    let carriers: HashSet<usize> = resolved
        .objects
        .iter()
        .filter_map(|o| match &o.geometry {
            Some(Geometry::Face { surface, .. }) => Some(surface.object),
            _ => None,
        })
        .collect();
    for (i, o) in resolved.objects.iter().enumerate() {
        if matches!(o.geometry, Some(Geometry::Patch(_))) && !carriers.contains(&i) {
            diags.push(
                Diagnostic::new(
                    Code::UnusedPatch,
                    o.span,
                    format!("patch9 '{}' is not the surface of any face, so it is not meshed", o.name),
                )
                .with_help(format!(
                    "add <face name=\"…\" surface=\"{}\" edges=\"…\"/> bounded by edges along its sides",
                    o.name
                )),
            );
        }
    }
}

/// The curve of an edge whose line is a point-calculus curve (which must
/// run between the edge's vertices, in either direction: E694) or a patch
/// (whose side between two adjacent corners it follows: E695).
pub(super) fn edge_curve(
    geometry: &Geometry,
    a: Point3,
    b: Point3,
    tol: f64,
    name: &str,
    span: Span,
    diags: &mut Diagnostics,
) -> Option<Curve> {
    let near = |p: &Point3, q: &Point3| (p - q).norm() <= tol;
    match geometry {
        Geometry::PointCurve(c) => {
            let (begin, end) = (c.begin(), c.end());
            if near(&a, &begin) && near(&b, &end) {
                return Some(Curve::PointCalculus(Box::new(c.clone())));
            }
            if near(&a, &end) && near(&b, &begin) {
                return Some(Curve::PointCalculus(Box::new(c.reversed())));
            }
            let off = (a - begin)
                .norm()
                .min((a - end).norm())
                .max((b - begin).norm().min((b - end).norm()));
            diags.push(
                Diagnostic::new(
                    Code::EdgeNotAtCurveEnds,
                    span,
                    format!(
                        "the vertices of edge '{name}' are not the end points of its {}: one lies {} from the nearest end",
                        c.element(),
                        fmt(off)
                    ),
                )
                .with_help(format!(
                    "put the edge's begin and end vertices at the curve's ends {} and {} (tolerance {})",
                    crate::resolve::fmt_point(&begin),
                    crate::resolve::fmt_point(&end),
                    fmt(tol)
                )),
            );
            None
        }
        Geometry::Patch(patch) => {
            let corners = patch.corners();
            let find = |p: &Point3| corners.iter().position(|c| near(c, p));
            let side = match (find(&a), find(&b)) {
                (Some(i), Some(j)) => patch.side(i, j),
                _ => None,
            };
            if let Some(side) = side {
                return Some(Curve::PointCalculus(Box::new(side)));
            }
            diags.push(
                Diagnostic::new(
                    Code::EdgeNotOnPatchSide,
                    span,
                    format!(
                        "edge '{name}' runs along a patch9, but its vertices {} and {} are not two corners joined by a side",
                        crate::resolve::fmt_point(&a),
                        crate::resolve::fmt_point(&b)
                    ),
                )
                .with_help(format!(
                    "use two adjacent corners of the patch: {}",
                    corners
                        .iter()
                        .map(crate::resolve::fmt_point)
                        .collect::<Vec<_>>()
                        .join(", ")
                )),
            );
            None
        }
        _ => None,
    }
}
