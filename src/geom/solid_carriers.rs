//! The surface of each face and the curve of each edge of a 3D primitive's
//! canonical boundary, by local index (the order of `lower/brep.rs`, which
//! takes its carriers from here). The model keeps a (solid, local index) per
//! primitive face and edge and makes the carrier when it is read: on files of
//! many primitives a copy of every surface (120 bytes) and curve (96 bytes)
//! was a fifth of the memory peak.

use super::{Curve, Frame, Point3, SolidShape, Surface, Vec3};
use std::f64::consts::TAU;

impl SolidShape {
    /// The surface of face `local` of the canonical boundary; `None` for a 2D
    /// region or an index past the faces.
    pub fn face_surface(&self, local: usize) -> Option<Surface> {
        match self {
            SolidShape::Box { frame } => (local < 6).then(|| box_face(frame, local / 2, local % 2)),
            SolidShape::Ball { frame } => {
                (local < 2).then_some(Surface::Ellipsoid { frame: *frame })
            }
            SolidShape::Cone { frame, r0, r1 } => {
                let caps = cone_rims(*r0, *r1).count();
                match local.cmp(&caps) {
                    std::cmp::Ordering::Less => {
                        let (z, _, up) = cone_rims(*r0, *r1).nth(local)?;
                        Some(cone_cap(frame, z, up))
                    }
                    std::cmp::Ordering::Equal => Some(Surface::Cone {
                        frame: *frame,
                        r0: *r0,
                        r1: *r1,
                    }),
                    std::cmp::Ordering::Greater => None,
                }
            }
            SolidShape::Torus {
                frame,
                major,
                minor,
            } => (local == 0).then_some(Surface::Torus {
                frame: *frame,
                major: *major,
                minor: *minor,
            }),
            SolidShape::Disk { .. } | SolidShape::Polygon { .. } => None,
        }
    }

    /// The curve of edge `local` of the canonical boundary; `None` for a 2D
    /// region or an index past the edges.
    pub fn edge_curve(&self, local: usize) -> Option<Curve> {
        match self {
            SolidShape::Box { frame } => (local < 12).then(|| {
                let (begin, end) = box_edge_ends(local);
                Curve::Segment {
                    a: box_corner(frame, begin),
                    b: box_corner(frame, end),
                }
            }),
            SolidShape::Ball { frame } => {
                (local == 0).then(|| ellipse(frame, Vec3::zeros(), Vec3::x(), Vec3::y()))
            }
            SolidShape::Cone { frame, r0, r1 } => {
                let (z, r, _) = cone_rims(*r0, *r1).nth(local)?;
                Some(cone_rim(frame, z, r))
            }
            SolidShape::Torus {
                frame,
                major,
                minor,
            } => match local {
                0 => Some(torus_parallel(frame, *major, *minor)),
                1 => Some(torus_meridian(frame, *major, *minor)),
                _ => None,
            },
            SolidShape::Disk { .. } | SolidShape::Polygon { .. } => None,
        }
    }

    /// Whether edge `local`'s curve ([`SolidShape::edge_curve`]) is closed,
    /// without making it: a box's edges are segments, every other
    /// primitive's are whole ellipses (t from 0 to 2π). `None` where
    /// `edge_curve` is.
    pub fn edge_is_closed(&self, local: usize) -> Option<bool> {
        match self {
            SolidShape::Box { .. } => (local < 12).then_some(false),
            SolidShape::Ball { .. } => (local == 0).then_some(true),
            SolidShape::Cone { r0, r1, .. } => {
                (local < cone_rims(*r0, *r1).count()).then_some(true)
            }
            SolidShape::Torus { .. } => (local < 2).then_some(true),
            SolidShape::Disk { .. } | SolidShape::Polygon { .. } => None,
        }
    }
}

/// Corner `n` of a parallelepiped: local (n & 1, n >> 1 & 1, n >> 2 & 1).
pub(crate) fn box_corner(frame: &Frame, n: usize) -> Point3 {
    frame.to_global(&Point3::new(
        (n & 1) as f64,
        ((n >> 1) & 1) as f64,
        ((n >> 2) & 1) as f64,
    ))
}

/// The corners at the ends of parallelepiped edge `4 * axis + 2 * s + t`:
/// it runs along `axis` from 0 to 1, `s` the side of the lower of the other
/// two axes and `t` of the higher.
pub(crate) fn box_edge_ends(local: usize) -> (usize, usize) {
    let corner = |i: usize, j: usize, k: usize| i + 2 * j + 4 * k;
    let (axis, s, t) = (local / 4, (local / 2) % 2, local % 2);
    let (p, q) = ((axis + 1) % 3, (axis + 2) % 3);
    let (lo, hi) = (p.min(q), p.max(q));
    let mut at = [0usize; 3];
    at[lo] = s;
    at[hi] = t;
    let begin = corner(at[0], at[1], at[2]);
    at[axis] = 1;
    (begin, corner(at[0], at[1], at[2]))
}

/// The centre of parallelepiped face `side` (0: min, 1: max) across `axis`.
pub(crate) fn box_face_center(frame: &Frame, axis: usize, side: usize) -> Point3 {
    let mut center = Point3::new(0.5, 0.5, 0.5);
    center[axis] = side as f64;
    frame.to_global(&center)
}

/// The plane of parallelepiped face `side` across `axis`, through its centre.
pub(crate) fn box_face(frame: &Frame, axis: usize, side: usize) -> Surface {
    let mut local_normal = Vec3::zeros();
    local_normal[axis] = if side == 0 { -1.0 } else { 1.0 };
    Surface::Plane {
        origin: box_face_center(frame, axis, side),
        normal: frame.normal_to_global(&local_normal),
    }
}

/// A cone's rims that exist (radius not at or below zero), bottom first: (local z,
/// radius, the cap's outward direction along the axis).
pub(crate) fn cone_rims(r0: f64, r1: f64) -> impl Iterator<Item = (f64, f64, f64)> {
    [(0.0, r0, -1.0), (1.0, r1, 1.0)]
        .into_iter()
        .filter(|&(_, r, _)| r > 0.0 || r.is_nan())
}

/// The plane of a cone's cap at local height `z`, normal `up` along the axis.
pub(crate) fn cone_cap(frame: &Frame, z: f64, up: f64) -> Surface {
    Surface::Plane {
        origin: frame.to_global(&Point3::new(0.0, 0.0, z)),
        normal: frame.normal_to_global(&Vec3::new(0.0, 0.0, up)),
    }
}

/// A cone's rim circle at local height `z`, radius `r`.
pub(crate) fn cone_rim(frame: &Frame, z: f64, r: f64) -> Curve {
    ellipse(frame, Vec3::new(0.0, 0.0, z), Vec3::x() * r, Vec3::y() * r)
}

/// A torus's outer parallel, through its seam vertex.
pub(crate) fn torus_parallel(frame: &Frame, major: f64, minor: f64) -> Curve {
    let outer = major + minor;
    ellipse(frame, Vec3::zeros(), Vec3::x() * outer, Vec3::y() * outer)
}

/// A torus's meridian at local +x, through its seam vertex.
pub(crate) fn torus_meridian(frame: &Frame, major: f64, minor: f64) -> Curve {
    ellipse(
        frame,
        Vec3::new(major, 0.0, 0.0),
        Vec3::x() * minor,
        Vec3::z() * minor,
    )
}

/// The closed ellipse center + a·cos t + b·sin t (local) in global coordinates.
pub(crate) fn ellipse(frame: &Frame, center: Vec3, a: Vec3, b: Vec3) -> Curve {
    Curve::Ellipse {
        center: frame.to_global(&Point3::from(center)),
        major: frame.vector_to_global(&a),
        minor: frame.vector_to_global(&b),
        t0: 0.0,
        t1: TAU,
    }
}
