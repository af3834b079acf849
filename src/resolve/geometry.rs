//! Resolved geometry of named objects, in global coordinates.

use crate::geom::point_calculus::{Patch9, PcCurve};
use crate::geom::{Frame, Point3, SolidShape, Surface, Vec3};
use crate::span::Span;

/// The carrier of an explicit `<line>`; the curve itself is fixed only by an
/// edge's end vertices.
#[derive(Debug, Clone, PartialEq)]
pub enum LineCarrier {
    Straight,
    /// Circle about `center` in the plane with unit `normal`.
    Circle {
        center: Point3,
        normal: Vec3,
    },
    /// center + major·cos t + minor·sin t.
    Ellipse {
        center: Point3,
        major: Vec3,
        minor: Vec3,
    },
    Intersection {
        surfaces: Box<[Surface; 2]>,
    },
}

/// A reference to another object, resolved to its index in [`super::Resolved::objects`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Link {
    pub object: usize,
    pub span: Span,
}

#[derive(Debug, Clone, PartialEq)]
pub enum Geometry {
    /// A named set of points; `partial[k]` when value k left out a coordinate
    /// (paper 000's 2D and 1D points: lines and planes, taken as points with 0s).
    Points {
        points: Vec<Point3>,
        partial: Vec<bool>,
    },
    Polyline {
        points: Vec<Point3>,
        crack: bool,
    },
    /// A bounded solid (3D) or region (2D).
    Solid(SolidShape),
    /// A surface that bounds nothing by itself (plane primitive, explicit surface).
    Surface(Surface),
    Line(LineCarrier),
    Vertex(Point3),
    Edge {
        line: Option<Link>,
        begin: Link,
        end: Link,
    },
    Face {
        surface: Link,
        loops: Vec<Vec<(Link, Option<String>)>>,
        /// The span of each loop's edge list, for messages (lowering does not
        /// read the document's objects, so the driver can drop them).
        loop_spans: Vec<Span>,
    },
    /// A curve of paper 003 (segment, conic_arc, desargues_arc).
    PointCurve(PcCurve),
    /// Paper 003's 9-point patch.
    Patch(Box<Patch9>),
    /// Paper 002's parametric surface with its trim.
    Trimmed(Box<crate::trimmed::TrimmedSurface>),
    /// Members of a replicate: `name[1]` … `name[n]`.
    Group(Vec<Geometry>),
}

impl Geometry {
    pub fn kind(&self) -> &'static str {
        match self {
            Geometry::Points { .. } => "point",
            Geometry::Polyline { .. } => "poly_line",
            Geometry::Solid(s) if s.is_planar() => "2D region",
            Geometry::Solid(_) => "solid",
            Geometry::Surface(_) => "surface",
            Geometry::Line(_) => "line",
            Geometry::Vertex(_) => "vertex",
            Geometry::Edge { .. } => "edge",
            Geometry::Face { .. } => "face",
            Geometry::PointCurve(c) => c.element(),
            Geometry::Patch(_) => "patch9",
            Geometry::Trimmed(_) => "trimmed surface",
            Geometry::Group(_) => "replicated group",
        }
    }

    /// Applies an affine map (rigid, or with positive scaling) to every
    /// coordinate; `None` for kinds that cannot be transformed.
    pub fn transformed(&self, map: &Frame) -> Option<Geometry> {
        Some(match self {
            Geometry::Points { points, partial } => Geometry::Points {
                points: points.iter().map(|p| map.to_global(p)).collect(),
                partial: partial.clone(),
            },
            Geometry::Polyline { points, crack } => Geometry::Polyline {
                points: points.iter().map(|p| map.to_global(p)).collect(),
                crack: *crack,
            },
            Geometry::Solid(shape) => Geometry::Solid(transform_shape(shape, map)),
            Geometry::Surface(Surface::Plane { origin, normal }) => {
                Geometry::Surface(Surface::Plane {
                    origin: map.to_global(origin),
                    normal: map.normal_to_global(normal),
                })
            }
            Geometry::Surface(Surface::Ellipsoid { frame }) => {
                Geometry::Surface(Surface::Ellipsoid {
                    frame: map.compose(frame),
                })
            }
            Geometry::Surface(Surface::Cone { frame, r0, r1 }) => {
                Geometry::Surface(Surface::Cone {
                    frame: map.compose(frame),
                    r0: *r0,
                    r1: *r1,
                })
            }
            Geometry::Surface(Surface::Torus {
                frame,
                major,
                minor,
            }) => Geometry::Surface(Surface::Torus {
                frame: map.compose(frame),
                major: *major,
                minor: *minor,
            }),
            // Point equations are affine combinations: map the defining points.
            Geometry::PointCurve(c) => Geometry::PointCurve(c.mapped(|p| map.to_global(p))),
            Geometry::Patch(patch) => Geometry::Patch(Box::new(patch.mapped(|p| map.to_global(p)))),
            Geometry::Group(members) => Geometry::Group(
                members
                    .iter()
                    .map(|m| m.transformed(map))
                    .collect::<Option<Vec<_>>>()?,
            ),
            _ => return None,
        })
    }
}

fn transform_shape(shape: &SolidShape, map: &Frame) -> SolidShape {
    match shape {
        SolidShape::Ball { frame } => SolidShape::Ball {
            frame: map.compose(frame),
        },
        SolidShape::Box { frame } => SolidShape::Box {
            frame: map.compose(frame),
        },
        SolidShape::Cone { frame, r0, r1 } => SolidShape::Cone {
            frame: map.compose(frame),
            r0: *r0,
            r1: *r1,
        },
        SolidShape::Torus {
            frame,
            major,
            minor,
        } => SolidShape::Torus {
            frame: map.compose(frame),
            major: *major,
            minor: *minor,
        },
        SolidShape::Disk { frame } => SolidShape::Disk {
            frame: map.compose(frame),
        },
        SolidShape::Polygon { frame, vertices } => SolidShape::Polygon {
            frame: map.compose(frame),
            vertices: vertices.clone(),
        },
    }
}
