//! Each primitive's geometry from its resolved points and numbers, with the
//! checks that make it well-defined (positive radii, independent vectors) and
//! the documented interpretations of paper 000's quirks.

use super::geometry::{Geometry, LineCarrier, Link};
use super::objects::Resolver;
use crate::diag::{Code, Diagnostic};
use crate::doc::{
    LineSpec, Number, Object, ObjectKind, ParallelepipedForm, PointSpec, Ref, Step, SurfaceSpec,
    VertexSpec,
};
use crate::expr::{Expr, ExprKind};
use crate::geom::{
    Curve, Frame, Mat3, Point3, SolidShape, Surface, Vec3, intersect_curves, intersect_surfaces,
};
use crate::span::Span;

/// Relative tolerance of degeneracy tests at resolution time.
const REL: f64 = 1e-9;

pub(super) fn resolve_kind(r: &mut Resolver, object: &Object, frame: &Frame) -> Option<Geometry> {
    let name = object.name.text.as_str();
    let need3 = r.doc.dimension == 3;
    match &object.kind {
        ObjectKind::Point { values } => {
            let mut points = Vec::with_capacity(values.len());
            let mut partial = Vec::with_capacity(values.len());
            for v in values {
                points.push(Point3::from(r.vector(v, frame)?) + frame.origin.coords);
                partial.push(v.x.is_none() || v.y.is_none() || (need3 && v.z.is_none()));
            }
            Some(Geometry::Points { points, partial })
        }
        ObjectKind::Circle { center, radius } => {
            let c = r.point(center.as_ref()?, frame, false)?;
            let radius = positive(r, radius.as_ref()?, "radius", name)?;
            let axes = frame.linear;
            Some(Geometry::Solid(SolidShape::Disk {
                frame: Frame {
                    origin: c,
                    linear: Mat3::from_columns(&[
                        axes.column(0) * radius,
                        axes.column(1) * radius,
                        axes.column(2).into_owned(),
                    ]),
                },
            }))
        }
        ObjectKind::Ellipse {
            center,
            radius_vertices,
        } => {
            let c = r.point(center.as_ref()?, frame, false)?;
            let [v1, v2] = radius_vertices.as_slice() else {
                return None;
            };
            let p1 = r.point(v1, frame, false)?;
            let p2 = r.point(v2, frame, false)?;
            let a = p1 - c;
            let mut b = p2 - c;
            let scale = a.norm().max(b.norm());
            if a.norm() <= REL * scale.max(1.0) || b.norm() <= REL * scale.max(1.0) {
                let span = if a.norm() <= REL * scale.max(1.0) {
                    v1.span
                } else {
                    v2.span
                };
                r.diags.push(
                    Diagnostic::new(
                        Code::CoincidentPoints,
                        span,
                        format!("a radius vertex of ellipse '{name}' coincides with its centre"),
                    )
                    .with_help("give the ends of the two semi-axes, away from the centre"),
                );
                return None;
            }
            let plane_normal = frame.linear.column(2).into_owned();
            if a.cross(&b).norm() <= 1e-9 * a.norm() * b.norm() {
                // Paper 000's own example: both vertices on one line through the centre.
                let radius = a.norm();
                b = plane_normal.cross(&a).normalize() * radius;
                r.diags.push(
                    Diagnostic::new(
                        Code::EllipseRadiusCollinear,
                        v2.span,
                        format!(
                            "the radius vertices of ellipse '{name}' lie on one line through the centre; taken as a circle of radius {}",
                            fmt(radius)
                        ),
                    )
                    .with_help("give the second radius vertex on the perpendicular axis"),
                );
            }
            let n = a.cross(&b).normalize();
            Some(Geometry::Solid(SolidShape::Disk {
                frame: Frame {
                    origin: c,
                    linear: Mat3::from_columns(&[a, b, n]),
                },
            }))
        }
        ObjectKind::Triangle { vertices } => {
            let [v1, v2, v3] = vertices.as_slice() else {
                return None;
            };
            let p = [
                r.point(v1, frame, false)?,
                r.point(v2, frame, false)?,
                r.point(v3, frame, false)?,
            ];
            let (a, b) = (p[1] - p[0], p[2] - p[0]);
            if a.cross(&b).norm() <= 1e-9 * a.norm() * b.norm()
                || a.norm() == 0.0
                || b.norm() == 0.0
            {
                r.diags.push(
                    Diagnostic::new(
                        Code::CollinearPoints,
                        object.span,
                        format!("the three vertices of triangle '{name}' lie on one line"),
                    )
                    .with_help("move one vertex off the line through the other two"),
                );
                return None;
            }
            let n = a.cross(&b).normalize();
            Some(Geometry::Solid(SolidShape::Polygon {
                frame: Frame {
                    origin: p[0],
                    linear: Mat3::from_columns(&[a, b, n]),
                },
                vertices: vec![
                    Point3::new(0.0, 0.0, 0.0),
                    Point3::new(1.0, 0.0, 0.0),
                    Point3::new(0.0, 1.0, 0.0),
                ],
            }))
        }
        ObjectKind::Parallelogram { base, vertices } => {
            let o = r.point(base.as_ref()?, frame, false)?;
            let [v1, v2] = vertices.as_slice() else {
                return None;
            };
            let (a, b) = (
                r.point(v1, frame, false)? - o,
                r.point(v2, frame, false)? - o,
            );
            if a.cross(&b).norm() <= 1e-9 * a.norm() * b.norm()
                || a.norm() == 0.0
                || b.norm() == 0.0
            {
                r.diags.push(
                    Diagnostic::new(Code::CollinearPoints, object.span, format!("the base point and vertices of parallelogram '{name}' lie on one line"))
                        .with_help("the two vertices are the ends of two non-parallel edges from the base point"),
                );
                return None;
            }
            let n = a.cross(&b).normalize();
            Some(Geometry::Solid(SolidShape::Polygon {
                frame: Frame {
                    origin: o,
                    linear: Mat3::from_columns(&[a, b, n]),
                },
                vertices: vec![
                    Point3::new(0.0, 0.0, 0.0),
                    Point3::new(1.0, 0.0, 0.0),
                    Point3::new(1.0, 1.0, 0.0),
                    Point3::new(0.0, 1.0, 0.0),
                ],
            }))
        }
        ObjectKind::Polygon { vertices } => super::polygons::polygon(r, object, vertices, frame),
        ObjectKind::Rectangle { first, second } => {
            super::polygons::rectangle(r, object, first.as_ref()?, second.as_ref()?, frame)
        }
        ObjectKind::RegularPolygon {
            center,
            radius,
            sides,
        } => super::polygons::regular_polygon(
            r,
            object,
            center.as_ref()?,
            radius.as_ref()?,
            sides.as_ref()?,
            frame,
        ),
        ObjectKind::PolyLine { segments, crack } => {
            let mut points: Vec<Point3> = Vec::new();
            for (k, (begin, end)) in segments.iter().enumerate() {
                let b = r.point(begin.as_ref()?, frame, false)?;
                let e = r.point(end.as_ref()?, frame, false)?;
                if let Some(&last) = points.last() {
                    let gap = (b - last).norm();
                    if gap > REL * last.coords.norm().max(b.coords.norm()).max(1.0) {
                        let span = begin.as_ref().map_or(object.span, |s| s.span);
                        r.diags.push(
                            Diagnostic::new(
                                Code::PolylineGap,
                                span,
                                format!(
                                    "line {} of poly_line '{name}' begins at {} but line {} ends at {}",
                                    k + 1,
                                    fmt_point(&b),
                                    k,
                                    fmt_point(&last)
                                ),
                            )
                            .with_help("make each begin_point equal to the previous end_point"),
                        );
                        return None;
                    }
                } else {
                    points.push(b);
                }
                points.push(e);
            }
            Some(Geometry::Polyline {
                points,
                crack: *crack,
            })
        }
        ObjectKind::TruncatedCone {
            bottom_center,
            top_center,
            bottom_radius,
            top_radius,
        } => {
            let bc = r.point(bottom_center.as_ref()?, frame, need3)?;
            let tc = r.point(top_center.as_ref()?, frame, need3)?;
            let rb = non_negative(r, bottom_radius.as_ref()?, "bottom_radius", name)?;
            let rt = match top_radius {
                Some(n) => non_negative(r, n, "top_radius", name)?,
                None => {
                    r.diags.push(
                        Diagnostic::new(
                            Code::ConeTopRadiusMissing,
                            object.span,
                            format!("truncated_cone '{name}' has no <top_radius>; taken as {}, equal to bottom_radius (a cylinder)", fmt(rb)),
                        )
                        .with_help("add <top_radius value=\"…\"/> (0 for a full cone)"),
                    );
                    rb
                }
            };
            let axis = tc - bc;
            if axis.norm() <= REL * bc.coords.norm().max(tc.coords.norm()).max(1.0) {
                r.diags.push(
                    Diagnostic::new(Code::DegenerateCone, object.span, format!("truncated_cone '{name}' has its bottom and top centres at the same point {}", fmt_point(&bc)))
                        .with_help("move top_center away from bottom_center along the cone's axis"),
                );
                return None;
            }
            if rb == 0.0 && rt == 0.0 {
                r.diags.push(
                    Diagnostic::new(
                        Code::DegenerateCone,
                        object.span,
                        format!("truncated_cone '{name}' has both radii zero"),
                    )
                    .with_help(
                        "give at least one of bottom_radius and top_radius a positive value",
                    ),
                );
                return None;
            }
            let (x, y) = perpendicular_pair(&axis, &frame.linear.column(0).into_owned());
            Some(Geometry::Solid(SolidShape::Cone {
                frame: Frame {
                    origin: bc,
                    linear: Mat3::from_columns(&[x, y, axis]),
                },
                r0: rb,
                r1: rt,
            }))
        }
        ObjectKind::Parallelepiped(form) => parallelepiped(r, object, form.as_ref()?, frame),
        ObjectKind::Sphere { center, radius } => {
            let c = r.point(center.as_ref()?, frame, need3)?;
            let radius = positive(r, radius.as_ref()?, "radius", name)?;
            Some(Geometry::Solid(SolidShape::Ball {
                frame: Frame {
                    origin: c,
                    linear: frame.linear * radius,
                },
            }))
        }
        ObjectKind::Ellipsoid { center, semi_axes } => {
            let c = r.point(center.as_ref()?, frame, need3)?;
            let spec = semi_axes.as_ref()?;
            let axes = r.numbers3(spec)?;
            if axes.iter().any(|&v| v <= 0.0) {
                r.diags.push(
                    Diagnostic::new(
                        Code::NonPositiveSize,
                        spec.span,
                        format!(
                            "ellipsoid '{name}' has semi-axes ({}, {}, {}); all must be positive",
                            fmt(axes.x),
                            fmt(axes.y),
                            fmt(axes.z)
                        ),
                    )
                    .with_help("give x=, y= and z= of <semi_axes> positive values"),
                );
                return None;
            }
            Some(Geometry::Solid(SolidShape::Ball {
                frame: Frame {
                    origin: c,
                    linear: frame.linear * Mat3::from_diagonal(&axes),
                },
            }))
        }
        ObjectKind::Torus {
            center,
            major,
            minor,
            axis,
        } => {
            let c = r.point(center.as_ref()?, frame, need3)?;
            let major_r = positive(r, major.as_ref()?, "major_radius", name)?;
            let minor_r = positive(r, minor.as_ref()?, "minor_radius", name)?;
            if minor_r >= major_r {
                r.diags.push(
                    Diagnostic::new(
                        Code::SelfIntersectingTorus,
                        minor.as_ref().map_or(object.span, |n| n.span),
                        format!(
                            "torus '{name}' has minor_radius {} not smaller than major_radius {}",
                            fmt(minor_r),
                            fmt(major_r)
                        ),
                    )
                    .with_help("make minor_radius smaller than major_radius"),
                );
                return None;
            }
            let axis_dir = match axis {
                Some(spec) => nonzero_vector(r, spec, frame, "axis", name)?,
                None => frame.linear.column(2).into_owned(),
            };
            let (x, y) = perpendicular_pair(&axis_dir, &frame.linear.column(0).into_owned());
            Some(Geometry::Solid(SolidShape::Torus {
                frame: Frame {
                    origin: c,
                    linear: Mat3::from_columns(&[x, y, axis_dir.normalize()]),
                },
                major: major_r,
                minor: minor_r,
            }))
        }
        ObjectKind::Plane { base, normal } => {
            let origin = r.point(base.as_ref()?, frame, need3)?;
            let spec = normal.as_ref()?;
            let n = nonzero_vector(r, spec, frame, "normal", name)?;
            Some(Geometry::Surface(Surface::Plane {
                origin,
                normal: n.normalize(),
            }))
        }
        ObjectKind::Transform { target, steps } => {
            let (_, geometry) = r.linked_geometry(target.as_ref()?, &["*"])?;
            let map = steps_map(r, steps, name)?;
            transformed(r, &geometry, &map, target.as_ref()?, name)
        }
        ObjectKind::Replicate {
            target,
            count,
            steps,
        } => {
            let target = target.as_ref()?;
            let (_, geometry) = r.linked_geometry(target, &["*"])?;
            let count_spec = count.as_ref()?;
            let n = r.number(count_spec)?;
            if n.fract() != 0.0 || !(1.0..=100_000.0).contains(&n) {
                r.diags.push(
                    Diagnostic::new(Code::BadCount, count_spec.span, format!("replicate '{name}' has count {}; it must be a whole number from 1 to 100000", fmt(n)))
                        .with_help("give the number of copies, e.g. count=\"4\""),
                );
                return None;
            }
            if matches!(geometry, Geometry::Group(_)) {
                r.diags.push(
                    Diagnostic::new(Code::WrongKind, target.span, format!("replicate '{name}' names the replicated group '{}'", target.name()))
                        .with_help(format!("replicate one member, e.g. ref=\"{}[1]\", or replicate the original object", target.name())),
                );
                return None;
            }
            let step = steps_map(r, steps, name)?;
            let mut map = Frame::identity();
            let mut members = Vec::with_capacity(n as usize);
            for _ in 0..n as usize {
                members.push(transformed(r, &geometry, &map, target, name)?);
                map = step.compose(&map);
            }
            Some(Geometry::Group(members))
        }
        ObjectKind::PcCurve {
            kind,
            points,
            discriminant,
        } => super::point_calculus::curve(r, object, *kind, points, discriminant.as_ref(), frame),
        ObjectKind::Patch9 { rows } => super::point_calculus::patch(r, object, rows, frame),
        ObjectKind::Trimmed(spec) => super::trimmed::surface(r, object, spec, frame),
        ObjectKind::Surface(spec) => surface(r, spec.as_ref()?, object, frame),
        ObjectKind::Line(spec) => line(r, spec.as_ref()?, object, frame),
        ObjectKind::Vertex(spec) => vertex(r, spec.as_ref()?, object, frame),
        ObjectKind::Edge { line, begin, end } => {
            let line = match line {
                Some(l) => Some(r.link(
                    l,
                    &["line", "segment", "conic_arc", "desargues_arc", "patch9"],
                )?),
                None => None,
            };
            let begin = r.link(begin.as_ref()?, &["vertex"])?;
            let end = r.link(end.as_ref()?, &["vertex"])?;
            Some(Geometry::Edge { line, begin, end })
        }
        ObjectKind::Face {
            surface,
            loops,
            loop_spans,
        } => {
            let surface = r.link(
                surface.as_ref()?,
                &[
                    "surface",
                    "plane",
                    "sphere",
                    "ellipsoid",
                    "truncated_cone",
                    "torus",
                    "patch9",
                ],
            )?;
            let mut out = Vec::new();
            let mut ok = true;
            for l in loops {
                let mut edges = Vec::new();
                for e in l {
                    if e.entity().is_some() {
                        r.diags.push(
                            Diagnostic::new(Code::WrongKind, e.span, format!("'{}' names an entity of a primitive; a face's loops take explicit <edge> names", e.text))
                                .with_help("define the edge with <edge> and name it here"),
                        );
                        ok = false;
                        continue;
                    }
                    match r.link(e, &["edge"]) {
                        Some(link) => edges.push((link, None)),
                        None => ok = false,
                    }
                }
                out.push(edges);
            }
            ok.then_some(Geometry::Face {
                surface,
                loops: out,
                loop_spans: loop_spans.clone(),
            })
        }
    }
}

fn parallelepiped(
    r: &mut Resolver,
    object: &Object,
    form: &ParallelepipedForm,
    frame: &Frame,
) -> Option<Geometry> {
    let name = object.name.text.as_str();
    let need3 = r.doc.dimension == 3;
    let (origin, edges) = match form {
        ParallelepipedForm::Edges { base, vertices } => {
            let o = r.point(base, frame, need3)?;
            let [v1, v2, v3] = vertices.as_slice() else {
                return None;
            };
            let a = [
                r.point(v1, frame, need3)? - o,
                r.point(v2, frame, need3)? - o,
                r.point(v3, frame, need3)? - o,
            ];
            (o, a)
        }
        ParallelepipedForm::Corners { first, second } => {
            // Opposite corners of a box aligned with the (local) axes.
            let p = r.point(first, frame, need3)?;
            let q = r.point(second, frame, need3)?;
            let lp = frame.to_local(&p)?;
            let lq = frame.to_local(&q)?;
            let lo = lp.inf(&lq);
            let d = lp.sup(&lq) - lo;
            let o = frame.to_global(&lo);
            let cols = [
                frame.linear.column(0) * d.x,
                frame.linear.column(1) * d.y,
                frame.linear.column(2) * d.z,
            ];
            (o, cols)
        }
        ParallelepipedForm::PointEquation { points } => {
            // M = Au + Bv + Cw + D(1 − u − v − w) = D + (A − D)u + (B − D)v +
            // (C − D)w: paper 000's base point D with vertices A, B, C, and the
            // same arithmetic, so both forms give the identical solid.
            let [a, b, c, d] = points.as_slice() else {
                return None;
            };
            let o = r.point(d, frame, need3)?;
            let edges = [
                r.point(a, frame, need3)? - o,
                r.point(b, frame, need3)? - o,
                r.point(c, frame, need3)? - o,
            ];
            (o, edges)
        }
    };
    let lengths = edges.map(|e| e.norm());
    let det = Mat3::from_columns(&edges).determinant();
    if lengths.contains(&0.0) || det.abs() <= 1e-9 * lengths.iter().product::<f64>() {
        let detail = match form {
            ParallelepipedForm::Corners { .. } => {
                "its two corners share a coordinate, so it is flat".to_string()
            }
            ParallelepipedForm::Edges { .. } => {
                "its three edge vectors are coplanar, so it has no volume".to_string()
            }
            ParallelepipedForm::PointEquation { .. } => {
                "A − D, B − D and C − D are coplanar, so it has no volume".to_string()
            }
        };
        r.diags.push(
            Diagnostic::new(Code::DegenerateParallelepiped, object.span, format!("parallelepiped '{name}' is degenerate: {detail}"))
                .with_help("give three independent edge vectors, or opposite corners that differ in x, y and z"),
        );
        return None;
    }
    Some(Geometry::Solid(SolidShape::Box {
        frame: Frame {
            origin,
            linear: Mat3::from_columns(&edges),
        },
    }))
}

fn surface(
    r: &mut Resolver,
    spec: &SurfaceSpec,
    object: &Object,
    frame: &Frame,
) -> Option<Geometry> {
    let name = object.name.text.as_str();
    let s = match spec {
        SurfaceSpec::Plane { base, normal } => {
            let origin = r.point(base.as_ref()?, frame, true)?;
            let n_spec = normal.as_ref()?;
            let n = nonzero_vector(r, n_spec, frame, "normal", name)?;
            Surface::Plane {
                origin,
                normal: n.normalize(),
            }
        }
        SurfaceSpec::Sphere { center, radius } => {
            let c = r.point(center.as_ref()?, frame, true)?;
            let radius = positive(r, radius.as_ref()?, "radius", name)?;
            Surface::Ellipsoid {
                frame: Frame {
                    origin: c,
                    linear: frame.linear * radius,
                },
            }
        }
        SurfaceSpec::Cylinder { base, axis, radius } => {
            let o = r.point(base.as_ref()?, frame, true)?;
            let a_spec = axis.as_ref()?;
            let a = nonzero_vector(r, a_spec, frame, "axis", name)?.normalize();
            let radius = positive(r, radius.as_ref()?, "radius", name)?;
            let (x, y) = perpendicular_pair(&a, &frame.linear.column(0).into_owned());
            Surface::Cone {
                frame: Frame {
                    origin: o,
                    linear: Mat3::from_columns(&[x, y, a]),
                },
                r0: radius,
                r1: radius,
            }
        }
        SurfaceSpec::Cone {
            apex,
            axis,
            half_angle,
        } => {
            let o = r.point(apex.as_ref()?, frame, true)?;
            let a_spec = axis.as_ref()?;
            let a = nonzero_vector(r, a_spec, frame, "axis", name)?.normalize();
            let angle_spec = half_angle.as_ref()?;
            let angle = r.number(angle_spec)?;
            if !(angle > 0.0 && angle < 90.0) {
                r.diags.push(
                    Diagnostic::new(Code::NonPositiveSize, angle_spec.span, format!("cone '{name}' has half_angle {}°; it must lie strictly between 0 and 90 degrees", fmt(angle)))
                        .with_help("give the angle between the axis and the surface in degrees"),
                );
                return None;
            }
            let (x, y) = perpendicular_pair(&a, &frame.linear.column(0).into_owned());
            Surface::Cone {
                frame: Frame {
                    origin: o,
                    linear: Mat3::from_columns(&[x, y, a]),
                },
                r0: 0.0,
                r1: angle.to_radians().tan(),
            }
        }
        SurfaceSpec::Quadric { coefficients, span } => {
            let mut c = [0.0; 10];
            for (slot, n) in c.iter_mut().zip(coefficients) {
                if let Some(n) = n {
                    *slot = r.number(n)?;
                }
            }
            if c[..9].iter().all(|&v| v == 0.0) {
                r.diags.push(
                    Diagnostic::new(
                        Code::ZeroVector,
                        *span,
                        format!("quadric '{name}' has all coefficients of x, y and z zero"),
                    )
                    .with_help("give at least one non-zero coefficient"),
                );
                return None;
            }
            Surface::Quadric {
                coefficients: transform_quadric(&c, frame),
            }
        }
        SurfaceSpec::Implicit { equation } => {
            let eq = equation.as_ref()?;
            if object.cs.is_some() {
                r.diags.push(
                    Diagnostic::new(
                        Code::ConflictingForms,
                        object.span,
                        format!("surface '{name}': cs= does not apply to an <implicit> equation"),
                    )
                    .with_help("write the equation in global x, y, z and remove cs="),
                );
                return None;
            }
            Surface::Implicit {
                expr: fold_parameters(r, &*eq.expr()?)?,
            }
        }
    };
    Some(Geometry::Surface(s))
}

fn line(r: &mut Resolver, spec: &LineSpec, object: &Object, frame: &Frame) -> Option<Geometry> {
    let name = object.name.text.as_str();
    Some(Geometry::Line(match spec {
        LineSpec::Straight => LineCarrier::Straight,
        LineSpec::CircleArc { center, normal } => {
            let c = r.point(center.as_ref()?, frame, true)?;
            let n = match normal {
                Some(spec) => nonzero_vector(r, spec, frame, "normal", name)?,
                None => frame.linear.column(2).into_owned(),
            };
            LineCarrier::Circle {
                center: c,
                normal: n.normalize(),
            }
        }
        LineSpec::EllipseArc {
            center,
            radius_vertices,
        } => {
            let c = r.point(center.as_ref()?, frame, true)?;
            let [v1, v2] = radius_vertices.as_slice() else {
                return None;
            };
            let major = r.point(v1, frame, true)? - c;
            let minor = r.point(v2, frame, true)? - c;
            if major.cross(&minor).norm() <= 1e-9 * major.norm() * minor.norm()
                || major.norm() == 0.0
                || minor.norm() == 0.0
            {
                r.diags.push(
                    Diagnostic::new(Code::DegenerateCurve, object.span, format!("ellipse_arc '{name}': the two radius vertices and the centre lie on one line"))
                        .with_help("give the ends of two non-parallel semi-axes"),
                );
                return None;
            }
            LineCarrier::Ellipse {
                center: c,
                major,
                minor,
            }
        }
        LineSpec::Intersection { surfaces, span } => {
            let [a, b] = surfaces.as_slice() else {
                r.diags.push(
                    Diagnostic::new(Code::MissingAttribute, *span, format!("the intersection line '{name}' names {} surfaces; it needs exactly two", surfaces.len()))
                        .with_help("write surfaces=\"s1 s2\""),
                );
                return None;
            };
            let sa = surface_of(r, a)?;
            let sb = surface_of(r, b)?;
            LineCarrier::Intersection {
                surfaces: Box::new([sa, sb]),
            }
        }
    }))
}

fn vertex(r: &mut Resolver, spec: &VertexSpec, object: &Object, frame: &Frame) -> Option<Geometry> {
    let name = object.name.text.as_str();
    match spec {
        VertexSpec::Coordinates(p) => Some(Geometry::Vertex(r.point(p, frame, true)?)),
        VertexSpec::Surfaces {
            surfaces,
            near,
            span,
        } => {
            let [a, b, c] = surfaces.as_slice() else {
                r.diags.push(
                    Diagnostic::new(
                        Code::MissingAttribute,
                        *span,
                        format!(
                            "vertex '{name}' names {} surfaces; an intersection vertex needs three",
                            surfaces.len()
                        ),
                    )
                    .with_help("write surfaces=\"s1 s2 s3\""),
                );
                return None;
            };
            let s = [surface_of(r, a)?, surface_of(r, b)?, surface_of(r, c)?];
            let hint = hint_point(r, near.as_ref(), frame)?;
            let tol = 1e-9 * hint.coords.norm().max(1.0);
            match intersect_surfaces([&s[0], &s[1], &s[2]], hint, tol) {
                Some(p) => Some(Geometry::Vertex(p)),
                None => {
                    r.diags.push(
                        Diagnostic::new(Code::NoConvergence, *span, format!("vertex '{name}': no intersection of {}, {} and {} found near {}", a.text, b.text, c.text, fmt_point(&hint)))
                            .with_help("check that the three surfaces meet in a point, and move <near> closer to it"),
                    );
                    None
                }
            }
        }
        VertexSpec::Lines { lines, near, span } => {
            let [a, b] = lines.as_slice() else {
                r.diags.push(
                    Diagnostic::new(
                        Code::MissingAttribute,
                        *span,
                        format!(
                            "vertex '{name}' names {} lines; an intersection vertex needs two",
                            lines.len()
                        ),
                    )
                    .with_help("write lines=\"l1 l2\""),
                );
                return None;
            };
            let hint = hint_point(r, near.as_ref(), frame)?;
            if let (Some(sa), Some(sb)) = (intersection_surfaces(r, a), intersection_surfaces(r, b))
            {
                // Two intersection lines meet where three of their four surfaces
                // meet and the fourth passes through that point.
                let tol = 1e-7 * hint.coords.norm().max(1.0);
                let all = [&sa[0], &sa[1], &sb[0], &sb[1]];
                let found = [(0, 1, 2, 3), (0, 1, 3, 2), (0, 2, 3, 1), (1, 2, 3, 0)]
                    .iter()
                    .find_map(|&(i, j, k, rest)| {
                        let p = intersect_surfaces([all[i], all[j], all[k]], hint, tol * 1e-2)?;
                        (all[rest].distance(&p) <= tol).then_some(p)
                    });
                return match found {
                    Some(p) => Some(Geometry::Vertex(p)),
                    None => {
                        r.diags.push(
                            Diagnostic::new(Code::NoConvergence, *span, format!("vertex '{name}': lines {} and {} do not meet near {}", a.text, b.text, fmt_point(&hint)))
                                .with_help("check that the two lines intersect, and move <near> closer to the intersection"),
                        );
                        None
                    }
                };
            }
            let ca = curve_of(r, a)?;
            let cb = curve_of(r, b)?;
            let tol = 1e-7 * hint.coords.norm().max(1.0);
            match intersect_curves(&ca, &cb, hint, tol) {
                Some(p) => Some(Geometry::Vertex(p)),
                None => {
                    r.diags.push(
                        Diagnostic::new(Code::NoConvergence, *span, format!("vertex '{name}': lines {} and {} do not meet near {}", a.text, b.text, fmt_point(&hint)))
                            .with_help("check that the two lines intersect, and move <near> closer to the intersection"),
                    );
                    None
                }
            }
        }
    }
}

fn hint_point(r: &mut Resolver, near: Option<&PointSpec>, frame: &Frame) -> Option<Point3> {
    match near {
        Some(p) => r.point(p, frame, false),
        None => Some(frame.origin),
    }
}

/// The surface a reference names: an explicit surface, a plane primitive, or
/// the carrier of a one-surface solid (sphere, ellipsoid; a cone's side).
pub(super) fn surface_of(r: &mut Resolver, reference: &Ref) -> Option<Surface> {
    let (_, g) = r.linked_geometry(
        reference,
        &[
            "surface",
            "plane",
            "sphere",
            "ellipsoid",
            "truncated_cone",
            "torus",
        ],
    )?;
    match g {
        Geometry::Surface(s) => Some(s),
        Geometry::Solid(SolidShape::Ball { frame }) => Some(Surface::Ellipsoid { frame }),
        Geometry::Solid(SolidShape::Cone { frame, r0, r1 }) => {
            Some(Surface::Cone { frame, r0, r1 })
        }
        Geometry::Solid(SolidShape::Torus {
            frame,
            major,
            minor,
        }) => Some(Surface::Torus {
            frame,
            major,
            minor,
        }),
        other => {
            r.diags.push(
                Diagnostic::new(
                    Code::WrongKind,
                    reference.span,
                    format!(
                        "'{}' is a {}, which is not one surface",
                        reference.text,
                        other.kind()
                    ),
                )
                .with_help("name a <surface>, a plane, or a sphere"),
            );
            None
        }
    }
}

/// The two surfaces of an intersection line, without reporting anything.
fn intersection_surfaces(r: &mut Resolver, reference: &Ref) -> Option<Box<[Surface; 2]>> {
    let i = r.by_name_index(reference.name())?;
    match r.geometry(i)? {
        Geometry::Line(LineCarrier::Intersection { surfaces }) => Some(surfaces),
        _ => None,
    }
}

/// A full curve for a vertex given as the intersection of two lines: edges
/// (their curves) or lines whose carrier fixes the curve (ellipse arcs).
fn curve_of(r: &mut Resolver, reference: &Ref) -> Option<Curve> {
    let (_, g) = r.linked_geometry(reference, &["line", "edge"])?;
    match g {
        Geometry::Line(LineCarrier::Ellipse {
            center,
            major,
            minor,
        }) => Some(Curve::Ellipse {
            center,
            major,
            minor,
            t0: 0.0,
            t1: std::f64::consts::TAU,
        }),
        Geometry::Edge {
            line: None,
            begin,
            end,
        } => {
            let a = vertex_point(r, begin)?;
            let b = vertex_point(r, end)?;
            Some(Curve::Segment { a, b })
        }
        other => {
            r.diags.push(
                Diagnostic::new(
                    Code::WrongKind,
                    reference.span,
                    format!(
                        "'{}' is a {} whose position is not fixed by itself",
                        reference.text,
                        other.kind()
                    ),
                )
                .with_help("name straight edges or ellipse_arc lines"),
            );
            None
        }
    }
}

fn vertex_point(r: &mut Resolver, link: Link) -> Option<Point3> {
    match r.geometry(link.object)? {
        Geometry::Vertex(p) => Some(p),
        _ => None,
    }
}

fn steps_map(r: &mut Resolver, steps: &[Step], name: &str) -> Option<Frame> {
    let mut map = Frame::identity();
    for step in steps {
        let next = match step {
            Step::Shift(v) => Frame::translation(r.vector(v, &Frame::identity())?),
            Step::Rotate { angles, center } => {
                let rotation = Frame::rotation_degrees(r.numbers3(angles)?);
                match center {
                    Some(c) => {
                        let (_, g) = r.linked_geometry(c, &["point", "vertex"])?;
                        let p = match g {
                            Geometry::Points { points, .. } if points.len() == 1 => points[0],
                            Geometry::Vertex(p) => p,
                            _ => {
                                r.diags.push(
                                    Diagnostic::new(
                                        Code::IndexOutOfRange,
                                        c.span,
                                        format!(
                                            "center=\"{}\" holds several points; name one",
                                            c.text
                                        ),
                                    )
                                    .with_help(format!("write {}[1]", c.name())),
                                );
                                return None;
                            }
                        };
                        Frame::translation(p.coords)
                            .compose(&rotation)
                            .compose(&Frame::translation(-p.coords))
                    }
                    None => rotation,
                }
            }
            Step::Scale { factors, factor } => {
                let f = match factor {
                    Some(n) => {
                        let v = r.number(n)?;
                        Vec3::new(v, v, v)
                    }
                    None => {
                        let mut v = r.numbers3(factors)?;
                        for (i, component) in
                            [&factors.x, &factors.y, &factors.z].iter().enumerate()
                        {
                            if component.is_none() {
                                v[i] = 1.0;
                            }
                        }
                        v
                    }
                };
                if f.iter().any(|&v| v <= 0.0) {
                    r.diags.push(
                        Diagnostic::new(
                            Code::NonPositiveSize,
                            factors.span,
                            format!(
                                "scale in '{name}' has factors ({}, {}, {}); all must be positive",
                                fmt(f.x),
                                fmt(f.y),
                                fmt(f.z)
                            ),
                        )
                        .with_help(
                            "scale factors must be greater than zero (mirroring is not supported)",
                        ),
                    );
                    return None;
                }
                Frame::scaling(f)
            }
        };
        map = next.compose(&map);
    }
    Some(map)
}

fn transformed(
    r: &mut Resolver,
    geometry: &Geometry,
    map: &Frame,
    target: &Ref,
    name: &str,
) -> Option<Geometry> {
    match geometry.transformed(map) {
        Some(g) => Some(g),
        None => {
            r.diags.push(
                Diagnostic::new(
                    Code::WrongKind,
                    target.span,
                    format!(
                        "'{name}' transforms '{}', a {}, which cannot be transformed",
                        target.text,
                        geometry.kind()
                    ),
                )
                .with_help("transforms apply to solids, 2D regions, points, poly_lines and planes"),
            );
            None
        }
    }
}

/// A subdomain's `area=` limit: positive, and only meaningful in 2D (W150).
pub(super) fn subdomain_area(
    r: &mut Resolver,
    def: &crate::doc::SubdomainDef,
    dimension: u8,
) -> Option<f64> {
    let spec = def.area.as_ref()?;
    let area = positive(r, spec, "the area limit", &def.name.text)?;
    if dimension != 2 {
        r.diags.push(
            Diagnostic::new(
                Code::AreaIn3d,
                spec.span,
                format!(
                    "subdomain '{}' gives area={} in a 3D model, where it is ignored",
                    def.name.text,
                    fmt(area)
                ),
            )
            .with_help("remove area=, or set dimension=\"2\" on <geometry> for a planar model"),
        );
        return None;
    }
    Some(area)
}

pub(super) fn positive(r: &mut Resolver, n: &Number, what: &str, name: &str) -> Option<f64> {
    let v = r.number(n)?;
    if v <= 0.0 {
        r.diags.push(
            Diagnostic::new(
                Code::NonPositiveSize,
                n.span,
                format!("{what} of '{name}' is {}; it must be positive", fmt(v)),
            )
            .with_help(format!("give {what} a value greater than zero")),
        );
        return None;
    }
    Some(v)
}

fn non_negative(r: &mut Resolver, n: &Number, what: &str, name: &str) -> Option<f64> {
    let v = r.number(n)?;
    if v < 0.0 {
        r.diags.push(
            Diagnostic::new(
                Code::NonPositiveSize,
                n.span,
                format!("{what} of '{name}' is {}; it must not be negative", fmt(v)),
            )
            .with_help(format!("give {what} a value of zero or more")),
        );
        return None;
    }
    Some(v)
}

fn nonzero_vector(
    r: &mut Resolver,
    spec: &crate::doc::VectorSpec,
    frame: &Frame,
    what: &str,
    name: &str,
) -> Option<Vec3> {
    let v = r.vector(spec, frame)?;
    nonzero(r, v, spec.span, what, name)
}

fn nonzero(r: &mut Resolver, v: Vec3, span: Span, what: &str, name: &str) -> Option<Vec3> {
    if v.norm() == 0.0 || !v.norm().is_finite() {
        r.diags.push(
            Diagnostic::new(
                Code::ZeroVector,
                span,
                format!("the {what} of '{name}' is the zero vector"),
            )
            .with_help(format!(
                "give the {what} a non-zero direction, e.g. z=\"1\""
            )),
        );
        return None;
    }
    Some(v)
}

/// Two unit vectors completing `axis` to a right-handed frame; `hint` fixes
/// the rotation about the axis so that seams are placed deterministically.
pub fn perpendicular_pair(axis: &Vec3, hint: &Vec3) -> (Vec3, Vec3) {
    let z = axis.normalize();
    let mut x = hint - z * hint.dot(&z);
    if x.norm() < 1e-6 {
        let fallback = if z.x.abs() < 0.9 {
            Vec3::x()
        } else {
            Vec3::y()
        };
        x = fallback - z * fallback.dot(&z);
    }
    let x = x.normalize();
    (x, z.cross(&x))
}

/// Rewrites a quadric given in a frame's local coordinates into global ones.
fn transform_quadric(c: &[f64; 10], frame: &Frame) -> [f64; 10] {
    if *frame == Frame::identity() {
        return *c;
    }
    let [xx, yy, zz, xy, yz, zx, x, y, z, k] = *c;
    let q = nalgebra::Matrix4::new(
        xx,
        xy / 2.0,
        zx / 2.0,
        x / 2.0,
        xy / 2.0,
        yy,
        yz / 2.0,
        y / 2.0,
        zx / 2.0,
        yz / 2.0,
        zz,
        z / 2.0,
        x / 2.0,
        y / 2.0,
        z / 2.0,
        k,
    );
    let Some(inv) = frame.linear.try_inverse() else {
        return *c;
    };
    // Local q = inv·(p − o): homogeneous map M with local = M·[p; 1].
    let t = -(inv * frame.origin.coords);
    let mut m = nalgebra::Matrix4::identity();
    m.fixed_view_mut::<3, 3>(0, 0).copy_from(&inv);
    m.fixed_view_mut::<3, 1>(0, 3).copy_from(&t);
    let g = m.transpose() * q * m;
    [
        g[(0, 0)],
        g[(1, 1)],
        g[(2, 2)],
        2.0 * g[(0, 1)],
        2.0 * g[(1, 2)],
        2.0 * g[(0, 2)],
        2.0 * g[(0, 3)],
        2.0 * g[(1, 3)],
        2.0 * g[(2, 3)],
        g[(3, 3)],
    ]
}

/// Replaces every parameter in an implicit equation by its value, leaving the
/// free variables x, y, z.
fn fold_parameters(r: &mut Resolver, expr: &Expr) -> Option<Expr> {
    Some(match &expr.kind {
        ExprKind::Name(n) if matches!(n.as_str(), "x" | "y" | "z" | "pi") => expr.clone(),
        ExprKind::Name(_) => {
            let number = Number::new(Some(expr.clone()), expr.span);
            Expr::number(r.number(&number)?, expr.span)
        }
        ExprKind::Number(_) => expr.clone(),
        ExprKind::Neg(inner) => Expr {
            kind: ExprKind::Neg(Box::new(fold_parameters(r, inner)?)),
            span: expr.span,
        },
        ExprKind::Binary(op, a, b) => Expr {
            kind: ExprKind::Binary(
                *op,
                Box::new(fold_parameters(r, a)?),
                Box::new(fold_parameters(r, b)?),
            ),
            span: expr.span,
        },
        ExprKind::Call(f, args) => Expr {
            kind: ExprKind::Call(
                *f,
                args.iter()
                    .map(|a| fold_parameters(r, a))
                    .collect::<Option<Vec<_>>>()?,
            ),
            span: expr.span,
        },
    })
}

/// A number as users write it: no trailing zeros, no exponent for ordinary sizes.
pub fn fmt(v: f64) -> String {
    let rounded = (v * 1e9).round() / 1e9;
    let mut s = format!("{rounded}");
    if s == "-0" {
        s = "0".into();
    }
    s
}

pub fn fmt_point(p: &Point3) -> String {
    format!("({}, {}, {})", fmt(p.x), fmt(p.y), fmt(p.z))
}
