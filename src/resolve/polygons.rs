//! The 2D polygon primitives — `polygon`, `rectangle`, `regular_polygon` —
//! as [`SolidShape::Polygon`]s in the local plane of their coordinate system,
//! with the checks that make them simple polygons.

use super::geometry::Geometry;
use super::objects::Resolver;
use super::shapes::{fmt, fmt_point, positive};
use crate::diag::{Code, Diagnostic};
use crate::doc::{Number, Object, PointSpec};
use crate::geom::{Frame, Point3, SolidShape, polygon};
use std::f64::consts::TAU;

/// Largest number of sides of a regular polygon.
const MAX_SIDES: f64 = 100_000.0;

/// A polygon whose vertices are given one by one, in either orientation.
pub(super) fn polygon(
    r: &mut Resolver,
    object: &Object,
    specs: &[PointSpec],
    frame: &Frame,
) -> Option<Geometry> {
    let name = object.name.text.as_str();
    let mut global = Vec::with_capacity(specs.len());
    for spec in specs {
        global.push(r.point(spec, frame, false)?);
    }
    let origin = *global.first()?;
    let local: Vec<Point3> = global
        .iter()
        .map(|p| {
            let q = frame.to_local(p)?;
            let o = frame.to_local(&origin)?;
            Some(Point3::new(q.x - o.x, q.y - o.y, 0.0))
        })
        .collect::<Option<_>>()?;
    let n = local.len();
    let scale = local.iter().map(|p| p.coords.norm()).fold(0.0, f64::max);
    for i in 0..n {
        let j = (i + 1) % n;
        if (local[j] - local[i]).norm() <= 1e-12 * scale.max(1e-300) {
            r.diags.push(
                Diagnostic::new(
                    Code::CoincidentPoints,
                    specs[j].span,
                    format!(
                        "vertices {} and {} of polygon '{name}' coincide at {}",
                        i + 1,
                        j + 1,
                        fmt_point(&global[i])
                    ),
                )
                .with_help("remove the repeated vertex; the polygon closes by itself"),
            );
            return None;
        }
    }
    if let Some((a, b)) = polygon::first_crossing(&local) {
        r.diags.push(
            Diagnostic::new(
                Code::PolygonEdgesCross,
                specs[b].span,
                format!(
                    "edges e{} and e{} of polygon '{name}' meet away from a shared vertex",
                    a + 1,
                    b + 1
                ),
            )
            .with_help(
                "list the vertices in order around the boundary, so that no two edges cross",
            ),
        );
        return None;
    }
    if polygon::twice_signed_area(&local).abs() <= 1e-12 * scale * scale {
        r.diags.push(
            Diagnostic::new(
                Code::CollinearPoints,
                object.span,
                format!("the vertices of polygon '{name}' lie on one line"),
            )
            .with_help("move a vertex off the line through the others"),
        );
        return None;
    }
    Some(solid(frame, origin, local))
}

/// A rectangle with sides along its coordinate system's axes, by opposite corners.
pub(super) fn rectangle(
    r: &mut Resolver,
    object: &Object,
    first: &PointSpec,
    second: &PointSpec,
    frame: &Frame,
) -> Option<Geometry> {
    let name = object.name.text.as_str();
    let p = frame.to_local(&r.point(first, frame, false)?)?;
    let q = frame.to_local(&r.point(second, frame, false)?)?;
    let (lo, hi) = (p.inf(&q), p.sup(&q));
    let (dx, dy) = (hi.x - lo.x, hi.y - lo.y);
    let size = dx.max(dy);
    if dx <= 1e-12 * size || dy <= 1e-12 * size || size <= 0.0 {
        r.diags.push(
            Diagnostic::new(
                Code::CoincidentPoints,
                second.span,
                format!(
                    "the corners of rectangle '{name}' share a coordinate ({} by {}), so it is flat",
                    fmt(dx),
                    fmt(dy)
                ),
            )
            .with_help("give two opposite corners that differ in both x and y"),
        );
        return None;
    }
    let origin = frame.to_global(&Point3::new(lo.x, lo.y, lo.z));
    let local = vec![
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(dx, 0.0, 0.0),
        Point3::new(dx, dy, 0.0),
        Point3::new(0.0, dy, 0.0),
    ];
    Some(solid(frame, origin, local))
}

/// A regular polygon by centre, circumradius and number of sides; vertex v1
/// lies on the local x axis and the others follow counter-clockwise.
pub(super) fn regular_polygon(
    r: &mut Resolver,
    object: &Object,
    center: &PointSpec,
    radius: &Number,
    sides: &Number,
    frame: &Frame,
) -> Option<Geometry> {
    let name = object.name.text.as_str();
    let c = r.point(center, frame, false)?;
    let radius = positive(r, radius, "the radius", name)?;
    let n = r.number(sides)?;
    if n.fract() != 0.0 || !(3.0..=MAX_SIDES).contains(&n) {
        r.diags.push(
            Diagnostic::new(
                Code::BadCount,
                sides.span,
                format!(
                    "regular_polygon '{name}' has sides={}; it must be a whole number from 3 to 100000",
                    fmt(n)
                ),
            )
            .with_help("give the number of sides, e.g. sides=\"6\""),
        );
        return None;
    }
    let n = n as usize;
    let local = (0..n)
        .map(|k| {
            let t = TAU * k as f64 / n as f64;
            Point3::new(radius * t.cos(), radius * t.sin(), 0.0)
        })
        .collect();
    Some(solid(frame, c, local))
}

fn solid(frame: &Frame, origin: Point3, vertices: Vec<Point3>) -> Geometry {
    Geometry::Solid(SolidShape::Polygon {
        frame: Frame {
            origin,
            linear: frame.linear,
        },
        vertices,
    })
}
