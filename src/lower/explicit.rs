//! Explicit topology (paper 000's vertex, edge and face lists) and named
//! boundaries. Edges get their curves from their line and end vertices, faces
//! their loops chained and oriented counter-clockwise about the face normal.

use super::Entities;
use crate::diag::{Code, Diagnostic, Diagnostics};
use crate::doc::Document;
use crate::geom::{Curve, Point3, SolidShape, Surface, Vec3};
use crate::ir::{
    Boundary, Carrier, Dimension, Edge, EdgeId, Face, Model, OrientedEdge, Origin, SourceMap,
    Vertex, VertexId,
};
use crate::resolve::{Geometry, LineCarrier, Resolved};
use crate::span::Span;
use foldhash::{HashMap, HashMapExt};
use std::f64::consts::TAU;

pub(super) fn lower_topology(
    resolved: &Resolved,
    model: &mut Model,
    source_map: &mut SourceMap,
    entities: &mut Entities,
    diags: &mut Diagnostics,
) {
    let tol = model.tolerance;
    let mut vertex_of: HashMap<usize, VertexId> = HashMap::new();
    let mut edge_of: HashMap<usize, EdgeId> = HashMap::new();
    for (i, object) in resolved.objects.iter().enumerate() {
        if let Some(Geometry::Vertex(p)) = &object.geometry {
            let id = VertexId(model.vertices.len() as u32);
            model.vertices.push(Vertex {
                name: object.name.as_str().into(),
                position: *p,
            });
            source_map.vertices.insert(id, Origin { span: object.span });
            entities.vertices.insert(object.name.clone(), id);
            vertex_of.insert(i, id);
        }
    }
    for (i, object) in resolved.objects.iter().enumerate() {
        let Some(Geometry::Edge { line, begin, end }) = &object.geometry else {
            continue;
        };
        let (Some(&b), Some(&e)) = (vertex_of.get(&begin.object), vertex_of.get(&end.object))
        else {
            continue;
        };
        let a = model.vertex(b).position;
        let z = model.vertex(e).position;
        let carrier = match line {
            Some(link) => match resolved
                .objects
                .get(link.object)
                .and_then(|o| o.geometry.as_ref())
            {
                Some(Geometry::Line(c)) => Some(c.clone()),
                Some(g @ (Geometry::PointCurve(_) | Geometry::Patch(_))) => {
                    match super::point_calculus::edge_curve(
                        g,
                        a,
                        z,
                        tol,
                        &object.name,
                        object.span,
                        diags,
                    ) {
                        Some(curve) => {
                            push_edge(
                                model,
                                source_map,
                                entities,
                                &mut edge_of,
                                i,
                                object,
                                curve,
                                b,
                                e,
                            );
                            None
                        }
                        None => None,
                    }
                }
                _ => None,
            },
            None => Some(LineCarrier::Straight),
        };
        let Some(carrier) = carrier else {
            continue;
        };
        let Some(curve) = edge_curve(&carrier, a, z, tol, &object.name, object.span, diags) else {
            continue;
        };
        push_edge(
            model,
            source_map,
            entities,
            &mut edge_of,
            i,
            object,
            curve,
            b,
            e,
        );
    }
    // An edge that did not lower was reported where it failed; the faces,
    // subdomains and boundaries naming it must not repeat that as E200.
    for (i, object) in resolved.objects.iter().enumerate() {
        if matches!(object.geometry, Some(Geometry::Edge { .. })) && !edge_of.contains_key(&i) {
            entities.failed.insert(object.name.clone());
        }
    }
    for object in &resolved.objects {
        let Some(Geometry::Face {
            surface,
            loops,
            loop_spans,
        }) = &object.geometry
        else {
            continue;
        };
        let surface = match resolved
            .objects
            .get(surface.object)
            .and_then(|o| o.geometry.as_ref())
        {
            Some(Geometry::Surface(s)) => s.clone(),
            Some(Geometry::Patch(patch)) => Surface::Patch9(patch.clone()),
            Some(Geometry::Solid(SolidShape::Ball { frame })) => {
                Surface::Ellipsoid { frame: *frame }
            }
            Some(Geometry::Solid(SolidShape::Cone { frame, r0, r1 })) => Surface::Cone {
                frame: *frame,
                r0: *r0,
                r1: *r1,
            },
            Some(Geometry::Solid(SolidShape::Torus {
                frame,
                major,
                minor,
            })) => Surface::Torus {
                frame: *frame,
                major: *major,
                minor: *minor,
            },
            _ => continue,
        };
        let mut chained = Vec::new();
        let mut complete = true;
        for l in loops {
            let ids: Option<Vec<EdgeId>> = l
                .iter()
                .map(|(link, _)| edge_of.get(&link.object).copied())
                .collect();
            match ids {
                Some(ids) => chained.push(chain(model, &ids)),
                None => complete = false,
            }
        }
        if !complete || chained.is_empty() {
            // One of its edges failed and was reported; so is this face, then.
            entities.failed.insert(object.name.clone());
            continue;
        }
        check_edges_on_surface(
            model,
            &chained,
            &surface,
            &object.name,
            loop_spans,
            object.span,
            diags,
        );
        let reversed = orient_loops(model, &mut chained, &surface);
        let id = crate::ir::FaceId(model.faces.len() as u32);
        model.faces.push(Face {
            name: object.name.as_str().into(),
            carrier: Carrier::own(surface),
            reversed,
            loops: chained.into(),
        });
        source_map.faces.insert(id, Origin { span: object.span });
        entities.faces.insert(object.name.clone(), id);
    }
}

#[allow(clippy::too_many_arguments)]
fn push_edge(
    model: &mut Model,
    source_map: &mut SourceMap,
    entities: &mut Entities,
    edge_of: &mut HashMap<usize, EdgeId>,
    i: usize,
    object: &crate::resolve::ResolvedObject,
    curve: Curve,
    begin: VertexId,
    end: VertexId,
) {
    let id = EdgeId(model.edges.len() as u32);
    model.edges.push(Edge {
        name: object.name.as_str().into(),
        carrier: Carrier::own(curve),
        begin,
        end,
    });
    source_map.edges.insert(id, Origin { span: object.span });
    entities.edges.insert(object.name.clone(), id);
    edge_of.insert(i, id);
}

/// The curve of an explicit edge from its carrier and end points; reports
/// end points off the carrier (E305) and open edges that close on themselves (E400).
fn edge_curve(
    carrier: &LineCarrier,
    a: Point3,
    b: Point3,
    tol: f64,
    name: &str,
    span: Span,
    diags: &mut Diagnostics,
) -> Option<Curve> {
    let same = (a - b).norm() <= tol;
    let off = |what: &str, d: f64, diags: &mut Diagnostics| {
        diags.push(
            Diagnostic::new(
                Code::NotOnCarrier,
                span,
                format!(
                    "the {what} vertex of edge '{name}' lies {} away from its line",
                    crate::resolve_fmt(d)
                ),
            )
            .with_help(format!(
                "move the vertex onto the line (tolerance {})",
                crate::resolve_fmt(tol)
            )),
        );
    };
    match carrier {
        LineCarrier::Straight => {
            if same {
                diags.push(
                    Diagnostic::new(Code::EdgeEndsCoincide, span, format!("straight edge '{name}' begins and ends at the same point"))
                        .with_help("an open edge joins two distinct vertices; only circles and ellipses may close"),
                );
                return None;
            }
            Some(Curve::Segment { a, b })
        }
        LineCarrier::Circle { center, normal } => {
            let ra = a - center;
            let rb = b - center;
            let in_plane_a = ra.dot(normal).abs();
            let in_plane_b = rb.dot(normal).abs();
            if ra.norm() <= tol {
                diags.push(
                    Diagnostic::new(
                        Code::DegenerateCurve,
                        span,
                        format!("edge '{name}' begins at the centre of its circle_arc"),
                    )
                    .with_help(
                        "the arc's radius is the distance from the centre to the begin vertex",
                    ),
                );
                return None;
            }
            if in_plane_a > tol {
                off("begin", in_plane_a, diags);
                return None;
            }
            if in_plane_b > tol || (rb.norm() - ra.norm()).abs() > tol {
                off("end", in_plane_b.max((rb.norm() - ra.norm()).abs()), diags);
                return None;
            }
            let minor = normal.cross(&ra);
            let sweep = if same {
                TAU
            } else {
                angle_from(&ra, &minor, &rb)
            };
            Some(Curve::Ellipse {
                center: *center,
                major: ra,
                minor,
                t0: 0.0,
                t1: sweep,
            })
        }
        LineCarrier::Ellipse {
            center,
            major,
            minor,
        } => {
            let ta = parameter_on(center, major, minor, &a, tol);
            let tb = parameter_on(center, major, minor, &b, tol);
            let (Some(ta), Some(tb)) = (ta, tb) else {
                let which = if ta.is_none() { "begin" } else { "end" };
                let p = if ta.is_none() { a } else { b };
                off(which, ellipse_residual(center, major, minor, &p), diags);
                return None;
            };
            let mut t1 = tb;
            while t1 <= ta + 1e-12 {
                t1 += TAU;
            }
            if same {
                t1 = ta + TAU;
            }
            Some(Curve::Ellipse {
                center: *center,
                major: *major,
                minor: *minor,
                t0: ta,
                t1,
            })
        }
        LineCarrier::Intersection { surfaces } => {
            for (which, p) in [("begin", a), ("end", b)] {
                let d = surfaces[0].distance(&p).max(surfaces[1].distance(&p));
                if d > tol {
                    off(which, d, diags);
                    return None;
                }
            }
            if same {
                diags.push(
                    Diagnostic::new(
                        Code::EdgeEndsCoincide,
                        span,
                        format!("intersection edge '{name}' begins and ends at the same point"),
                    )
                    .with_help(
                        "split a closed intersection curve into two edges at two distinct vertices",
                    ),
                );
                return None;
            }
            Some(Curve::Intersection {
                surfaces: surfaces.clone(),
                a,
                b,
            })
        }
    }
}

/// The angle in (0, 2π] from `ra` to `rb` counter-clockwise in the basis (ra, minor).
fn angle_from(ra: &Vec3, minor: &Vec3, rb: &Vec3) -> f64 {
    let x = rb.dot(ra) / ra.norm_squared();
    let y = rb.dot(minor) / minor.norm_squared();
    let mut t = y.atan2(x);
    if t <= 1e-12 {
        t += TAU;
    }
    t
}

fn parameter_on(center: &Point3, major: &Vec3, minor: &Vec3, p: &Point3, tol: f64) -> Option<f64> {
    let d = p - center;
    // Solve d = major·c + minor·s in the least-squares sense.
    let m = nalgebra::Matrix3x2::from_columns(&[*major, *minor]);
    let cs = (m.transpose() * m).try_inverse()? * m.transpose() * d;
    let t = cs.y.atan2(cs.x);
    let back = center + major * t.cos() + minor * t.sin();
    ((back - p).norm() <= tol).then_some(t)
}

fn ellipse_residual(center: &Point3, major: &Vec3, minor: &Vec3, p: &Point3) -> f64 {
    (0..3600)
        .map(|k| {
            let t = TAU * k as f64 / 3600.0;
            (center + major * t.cos() + minor * t.sin() - p).norm()
        })
        .fold(f64::INFINITY, f64::min)
}

/// Orders the directions of a loop's edges so that each begins where the
/// previous ends; a chain that breaks is left as far as it got (the topology
/// check reports it).
fn chain(model: &Model, ids: &[EdgeId]) -> Vec<OrientedEdge> {
    let mut out: Vec<OrientedEdge> = Vec::with_capacity(ids.len());
    for &id in ids {
        let edge = model.edge(id);
        let forward = match out.last() {
            None => {
                // The first edge's direction is fixed by the second.
                match ids.get(1).map(|&n| model.edge(n)) {
                    Some(next) => edge.end == next.begin || edge.end == next.end,
                    None => true,
                }
            }
            Some(prev) => {
                let prev_edge = model.edge(prev.edge);
                let at = if prev.forward {
                    prev_edge.end
                } else {
                    prev_edge.begin
                };
                edge.begin == at || edge.end != at
            }
        };
        out.push(OrientedEdge { edge: id, forward });
    }
    out
}

fn loop_points(model: &Model, l: &[OrientedEdge]) -> Vec<Point3> {
    let mut points = Vec::new();
    for e in l {
        let mut samples = model.edge_curve(e.edge).samples(8);
        if !e.forward {
            samples.reverse();
        }
        samples.pop();
        points.extend(samples);
    }
    points
}

/// Newell's vector area of a closed polygon.
fn vector_area(points: &[Point3]) -> Vec3 {
    let n = points.len();
    (0..n)
        .map(|i| points[i].coords.cross(&points[(i + 1) % n].coords))
        .sum::<Vec3>()
        * 0.5
}

/// Makes the outer loop counter-clockwise and hole loops clockwise about the
/// face normal; returns whether the face normal is −∇S.
fn orient_loops(model: &Model, loops: &mut [Vec<OrientedEdge>], surface: &Surface) -> bool {
    let Some(outer) = loops.first() else {
        return false;
    };
    let points = loop_points(model, outer);
    let area = vector_area(&points);
    let centroid =
        Point3::from(points.iter().map(|p| p.coords).sum::<Vec3>() / points.len().max(1) as f64);
    let on_surface = surface.project(&centroid).unwrap_or(centroid);
    let gradient = surface.gradient(&on_surface);
    let reversed = area.dot(&gradient) < 0.0;
    // The face normal (±∇S, chosen above) points along the outer loop's vector area.
    let normal = area;
    for (k, l) in loops.iter_mut().enumerate() {
        let a = vector_area(&loop_points(model, l));
        let counter_clockwise = a.dot(&normal) > 0.0;
        // The outer loop runs counter-clockwise, holes clockwise.
        if (k == 0) != counter_clockwise {
            reverse_loop(l);
        }
    }
    reversed
}

fn reverse_loop(l: &mut [OrientedEdge]) {
    l.reverse();
    for e in l.iter_mut() {
        e.forward = !e.forward;
    }
}

fn check_edges_on_surface(
    model: &Model,
    loops: &[Vec<OrientedEdge>],
    surface: &Surface,
    name: &str,
    loop_spans: &[Span],
    span: Span,
    diags: &mut Diagnostics,
) {
    let tol = model.tolerance;
    for (k, l) in loops.iter().enumerate() {
        for e in l {
            let edge = model.edge(e.edge);
            let worst = model
                .edge_curve(e.edge)
                .samples(8)
                .iter()
                .map(|p| surface.distance(p))
                .fold(0.0, f64::max);
            if worst > tol {
                diags.push(
                    Diagnostic::new(
                        Code::NotOnCarrier,
                        loop_spans.get(k).copied().unwrap_or(span),
                        format!(
                            "edge '{}' of face '{name}' leaves the face's surface by up to {}",
                            edge.name,
                            crate::resolve_fmt(worst)
                        ),
                    )
                    .with_help(format!(
                        "the edges of a face must lie on its surface (tolerance {})",
                        crate::resolve_fmt(tol)
                    )),
                );
            }
        }
    }
}

/// `<boundary>` elements: named sets of faces (3D) or edges (2D).
pub(super) fn lower_boundaries(
    doc: &Document,
    model: &mut Model,
    entities: &Entities,
    diags: &mut Diagnostics,
) {
    for b in &doc.boundaries {
        let mut boundary = Boundary {
            name: b.name.text.clone(),
            faces: Vec::new(),
            edges: Vec::new(),
        };
        if let Some((refs, _)) = &b.faces {
            for r in refs {
                match lookup_entities(&entities.faces, &r.text) {
                    Some(ids) => boundary.faces.extend(ids),
                    None => unknown_entity(r, "face", entities, diags),
                }
            }
        }
        if let Some((refs, _)) = &b.edges {
            for r in refs {
                match lookup_entities(&entities.edges, &r.text) {
                    Some(ids) => boundary.edges.extend(ids),
                    None => unknown_entity(r, "edge", entities, diags),
                }
            }
        }
        if b.faces.is_none() && b.edges.is_none() {
            let what = if model.dimension == Dimension::Two {
                "edges"
            } else {
                "faces"
            };
            diags.push(
                Diagnostic::new(
                    Code::MissingAttribute,
                    b.span,
                    format!("boundary '{}' names no {what}", b.name.text),
                )
                .with_help(format!("add {what}=\"…\" listing what it names")),
            );
        }
        boundary.faces.sort();
        boundary.faces.dedup();
        boundary.edges.sort();
        boundary.edges.dedup();
        model.boundaries.push(boundary);
    }
}

/// `name` exactly, or every entity of primitive `name` ("box" → "box.*").
pub(super) fn lookup_entities<T: Copy + Ord>(
    table: &HashMap<String, T>,
    name: &str,
) -> Option<Vec<T>> {
    if let Some(&id) = table.get(name) {
        return Some(vec![id]);
    }
    let prefix = format!("{name}.");
    let mut ids: Vec<T> = table
        .iter()
        .filter(|(k, _)| k.starts_with(&prefix))
        .map(|(_, &v)| v)
        .collect();
    ids.sort();
    ids.dedup();
    (!ids.is_empty()).then_some(ids)
}

/// Reports a face or edge reference that names nothing of that kind: E202
/// when it names another kind of entity, else E200 with a suggestion.
pub(super) fn unknown_entity(
    r: &crate::doc::Ref,
    kind: &str,
    entities: &Entities,
    diags: &mut Diagnostics,
) {
    if entities.failed.contains(r.name()) || entities.failed.contains(&*r.text) {
        return;
    }
    let found_as = if kind != "face" && lookup_entities(&entities.faces, &r.text).is_some() {
        Some("a face")
    } else if kind != "edge" && lookup_entities(&entities.edges, &r.text).is_some() {
        Some("an edge")
    } else if entities.vertices.contains_key(&*r.text) {
        Some("a vertex")
    } else {
        None
    };
    if let Some(what) = found_as {
        diags.push(
            Diagnostic::new(
                Code::WrongKind,
                r.span,
                format!("'{}' is {what}, but a {kind} is expected here", r.text),
            )
            .with_help(format!(
                "name a {kind} (an explicit <{kind}> or a primitive's {kind} such as {})",
                if kind == "face" {
                    "box.xmin"
                } else {
                    "box.xmin_ymin"
                }
            )),
        );
        return;
    }
    let names: Vec<&str> = if kind == "face" {
        entities.faces.keys().map(String::as_str).collect()
    } else {
        entities.edges.keys().map(String::as_str).collect()
    };
    let mut d = Diagnostic::new(
        Code::UndefinedName,
        r.span,
        format!("no {kind} named '{}'", r.text),
    );
    d.help = Some(
        match crate::diag::did_you_mean(&r.text, names.iter().copied()) {
            Some(best) => format!("did you mean '{best}'?"),
            None => format!(
                "name an explicit <{kind}> or a primitive's {kind} such as box.xmin (see docs/format.md)"
            ),
        },
    );
    diags.push(d);
}
