//! Paper 003's point-calculus elements: segments, conic arcs (checked by their
//! discriminant), Desargues arcs and 9-point patches, from their resolved
//! points. Points may be coordinates, parameters, basis coordinates or point
//! references, as everywhere in the format.

use super::geometry::Geometry;
use super::objects::Resolver;
use super::shapes::{fmt, fmt_point};
use crate::diag::{Code, Diagnostic};
use crate::doc::{Number, Object, PcCurveKind, PointSpec};
use crate::geom::point_calculus::{ConicKind, Patch9, PcCurve};
use crate::geom::{Frame, Point3};

/// Relative size below which two points coincide or three are collinear.
const REL: f64 = 1e-9;

pub(super) fn curve(
    r: &mut Resolver,
    object: &Object,
    kind: PcCurveKind,
    specs: &[Option<PointSpec>],
    discriminant: Option<&Number>,
    frame: &Frame,
) -> Option<Geometry> {
    let name = object.name.text.as_str();
    let mut points = Vec::with_capacity(specs.len());
    for spec in specs {
        points.push(r.point(spec.as_ref()?, frame, false)?);
    }
    let scale = points.iter().map(|p| p.coords.amax()).fold(1.0, f64::max);
    let same = |p: &Point3, q: &Point3| (p - q).norm() <= REL * scale;
    let (first, last) = (points[0], points[points.len() - 1]);
    if same(&first, &last) {
        let ends = if kind == PcCurveKind::Desargues {
            "point_a and point_d"
        } else {
            "point_a and point_b"
        };
        r.diags.push(
            Diagnostic::new(
                Code::CurveEndsCoincide,
                object.span,
                format!(
                    "{} '{name}' begins and ends at {}",
                    object.kind.element(),
                    fmt_point(&first)
                ),
            )
            .with_help(format!(
                "give {ends} distinct positions; a closed contour takes several arcs"
            )),
        );
        return None;
    }
    let curve = match kind {
        PcCurveKind::Segment => PcCurve::Segment {
            a: points[0],
            b: points[1],
        },
        PcCurveKind::Desargues => PcCurve::Desargues {
            points: [points[0], points[1], points[2], points[3]],
        },
        PcCurveKind::Conic => {
            let (a, b, c) = (points[0], points[1], points[2]);
            let number = discriminant?;
            let k = r.number(number)?;
            if ConicKind::of(k).is_none() {
                r.diags.push(
                    Diagnostic::new(
                        Code::DiscriminantOutOfRange,
                        number.span,
                        format!(
                            "conic_arc '{name}' has discriminant {}; it must lie strictly between 0 and 1",
                            fmt(k)
                        ),
                    )
                    .with_help(
                        "use 0 < k < 0.5 for a hyperbola, 0.5 for a parabola, 0.5 < k < 1 for an ellipse",
                    ),
                );
                return None;
            }
            let (ca, cb) = (a - c, b - c);
            if ca.norm() <= REL * scale
                || cb.norm() <= REL * scale
                || ca.cross(&cb).norm() <= REL * ca.norm() * cb.norm()
            {
                let span = specs
                    .get(2)
                    .and_then(|s| s.as_ref())
                    .map_or(object.span, |s| s.span);
                r.diags.push(
                    Diagnostic::new(
                        Code::DegenerateConic,
                        span,
                        format!(
                            "the tangent point {} of conic_arc '{name}' lies on the line through its ends {} and {}",
                            fmt_point(&c),
                            fmt_point(&a),
                            fmt_point(&b)
                        ),
                    )
                    .with_help("move point_c off the chord AB, where the end tangents meet; use <segment> for a straight piece"),
                );
                return None;
            }
            PcCurve::Conic { a, b, c, k }
        }
    };
    Some(Geometry::PointCurve(curve))
}

pub(super) fn patch(
    r: &mut Resolver,
    object: &Object,
    rows: &[Vec<PointSpec>],
    frame: &Frame,
) -> Option<Geometry> {
    let name = object.name.text.as_str();
    if rows.len() != 3 || rows.iter().any(|row| row.len() != 3) {
        // Already reported by the structural check.
        return None;
    }
    let mut grid = [[Point3::origin(); 3]; 3];
    let mut ok = true;
    for (i, row) in rows.iter().enumerate() {
        for (j, spec) in row.iter().enumerate() {
            match r.point(spec, frame, false) {
                Some(p) => grid[i][j] = p,
                None => ok = false,
            }
        }
    }
    if !ok {
        return None;
    }
    let patch = Patch9 { rows: grid };
    let scale = grid
        .iter()
        .flatten()
        .map(|p| (p - grid[0][0]).norm())
        .fold(0.0, f64::max);
    // The normal must exist everywhere on [0, 1]²: test a 9 × 9 grid.
    let n = 8;
    for i in 0..=n {
        for j in 0..=n {
            let (u, v) = (j as f64 / n as f64, i as f64 / n as f64);
            let (mu, mv) = patch.derivatives(u, v);
            let area = mu.cross(&mv).norm();
            if area.is_nan() || area <= REL * scale * scale {
                r.diags.push(
                    Diagnostic::new(
                        Code::DegeneratePatch,
                        object.span,
                        format!(
                            "patch9 '{name}' has no normal at (u, v) = ({}, {}), at {}",
                            fmt(u),
                            fmt(v),
                            fmt_point(&patch.point(u, v))
                        ),
                    )
                    .with_help(
                        "spread the nine points so that rows and columns run in different directions",
                    ),
                );
                return None;
            }
        }
    }
    Some(Geometry::Patch(Box::new(patch)))
}
