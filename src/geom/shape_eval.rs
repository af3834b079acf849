//! The implicit function of a solid, prepared once (frame inverses, face
//! normals) so that classifying thousands of boundary samples stays cheap.
//! Values are positive inside and, near the boundary, close to the signed
//! distance in global units: each piece is f / |∇f| with f the local defining
//! function, its gradient carried to global coordinates by L⁻ᵀ.

use super::{Frame, Mat3, Point3, SolidShape};
use nalgebra::{Matrix2, Matrix2x3, Vector2};

/// Global → local map q = L⁻¹ (p − o) with L⁻¹ as plain rows: this runs for
/// every boundary sample, and plain arithmetic keeps unoptimised builds fast.
pub(super) struct ToLocal {
    origin: [f64; 3],
    rows: [[f64; 3]; 3],
}

impl ToLocal {
    fn new(frame: &Frame) -> Option<ToLocal> {
        let inv = frame.inverse()?;
        Some(ToLocal {
            origin: [frame.origin.x, frame.origin.y, frame.origin.z],
            rows: [0, 1, 2].map(|i| [inv[(i, 0)], inv[(i, 1)], inv[(i, 2)]]),
        })
    }

    fn apply(&self, p: &Point3) -> [f64; 3] {
        let (x, y, z) = (
            p.x - self.origin[0],
            p.y - self.origin[1],
            p.z - self.origin[2],
        );
        let [a, b, c] = &self.rows;
        [
            a[0] * x + a[1] * y + a[2] * z,
            b[0] * x + b[1] * y + b[2] * z,
            c[0] * x + c[1] * y + c[2] * z,
        ]
    }

    /// |L⁻ᵀ u|: the global length of a gradient whose local form is `u`.
    fn covector_norm(&self, u: [f64; 3]) -> f64 {
        let r = &self.rows;
        let g = [0, 1, 2].map(|j| r[0][j] * u[0] + r[1][j] * u[1] + r[2][j] * u[2]);
        (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt()
    }

    fn row_norm(&self, i: usize) -> f64 {
        let r = self.rows[i];
        (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt()
    }
}

pub(super) enum ShapeEval {
    /// Similarity-frame ball: exact r − |p − c|.
    Sphere {
        center: Point3,
        radius: f64,
    },
    Ellipsoid {
        local: ToLocal,
    },
    /// `row_norms[i]` = |i-th row of L⁻¹|: local slab width → global distance.
    Box {
        local: ToLocal,
        row_norms: [f64; 3],
    },
    Cone {
        local: ToLocal,
        row_z: f64,
        r0: f64,
        r1: f64,
    },
    Torus {
        local: ToLocal,
        major: f64,
        minor: f64,
    },
    Disk {
        plane: InPlane,
    },
    /// Edge lines as (point, inward normal scaled so that n·(q − v) is a
    /// global in-plane distance).
    Polygon {
        plane: InPlane,
        edges: Vec<(Vector2<f64>, Vector2<f64>)>,
    },
    /// A non-convex simple polygon: even–odd inside test in local
    /// coordinates, distance to the nearest edge in global coordinates.
    Nonconvex {
        plane: InPlane,
        local: Vec<Vector2<f64>>,
        global: Vec<Point3>,
        linear: Mat3,
    },
    /// A degenerate shape with no interior: everything is outside.
    Empty,
}

/// The z = 0 plane of a 2D shape's frame: in-plane local coordinates by
/// orthogonal projection (so the normal offset and the z column are ignored).
pub(super) struct InPlane {
    origin: Point3,
    /// (AᵀA)⁻¹Aᵀ with A = [x column, y column].
    to_local: Matrix2x3<f64>,
    /// (AᵀA)⁻¹: the metric that turns local covectors into global lengths.
    metric_inv: Matrix2<f64>,
}

impl InPlane {
    fn new(origin: Point3, linear: &Mat3) -> Option<InPlane> {
        let a = linear.fixed_columns::<2>(0).into_owned();
        let metric_inv = (a.transpose() * a).try_inverse()?;
        let to_local = metric_inv * a.transpose();
        to_local.iter().all(|v| v.is_finite()).then_some(InPlane {
            origin,
            to_local,
            metric_inv,
        })
    }

    fn local(&self, p: &Point3) -> Vector2<f64> {
        self.to_local * (p - self.origin)
    }

    /// Global length of the in-plane gradient whose local form is `u`.
    fn covector_norm(&self, u: &Vector2<f64>) -> f64 {
        u.dot(&(self.metric_inv * u)).sqrt()
    }
}

impl ShapeEval {
    pub(super) fn new(shape: &SolidShape) -> ShapeEval {
        Self::build(shape).unwrap_or(ShapeEval::Empty)
    }

    fn build(shape: &SolidShape) -> Option<ShapeEval> {
        Some(match shape {
            SolidShape::Ball { frame } => match frame.similarity_scale() {
                Some(radius) => ShapeEval::Sphere {
                    center: frame.origin,
                    radius,
                },
                None => ShapeEval::Ellipsoid {
                    local: ToLocal::new(frame)?,
                },
            },
            SolidShape::Box { frame } => {
                let local = ToLocal::new(frame)?;
                let row_norms = [0, 1, 2].map(|i| local.row_norm(i));
                ShapeEval::Box { local, row_norms }
            }
            SolidShape::Cone { frame, r0, r1 } => {
                let local = ToLocal::new(frame)?;
                let row_z = local.row_norm(2);
                ShapeEval::Cone {
                    local,
                    row_z,
                    r0: *r0,
                    r1: *r1,
                }
            }
            SolidShape::Torus {
                frame,
                major,
                minor,
            } => ShapeEval::Torus {
                local: ToLocal::new(frame)?,
                major: *major,
                minor: *minor,
            },
            SolidShape::Disk { frame } => ShapeEval::Disk {
                plane: InPlane::new(frame.origin, &frame.linear)?,
            },
            SolidShape::Polygon { frame, vertices } => {
                let plane = InPlane::new(frame.origin, &frame.linear)?;
                if !super::polygon::is_convex(vertices) {
                    let local = vertices.iter().map(|v| Vector2::new(v.x, v.y)).collect();
                    let global = vertices
                        .iter()
                        .map(|v| frame.to_global(&Point3::new(v.x, v.y, 0.0)))
                        .collect();
                    return Some(ShapeEval::Nonconvex {
                        plane,
                        local,
                        global,
                        linear: frame.linear,
                    });
                }
                let edges = polygon_edges(&plane, vertices);
                if edges.len() < 3 {
                    return None;
                }
                ShapeEval::Polygon { plane, edges }
            }
        })
    }

    pub(super) fn value(&self, p: &Point3) -> f64 {
        match self {
            ShapeEval::Sphere { center, radius } => {
                let (dx, dy, dz) = (p.x - center.x, p.y - center.y, p.z - center.z);
                radius - (dx * dx + dy * dy + dz * dz).sqrt()
            }
            ShapeEval::Ellipsoid { local } => {
                let [x, y, z] = local.apply(p);
                let len = (x * x + y * y + z * z).sqrt();
                let u = if len > 0.0 {
                    [x / len, y / len, z / len]
                } else {
                    [1.0, 0.0, 0.0]
                };
                (1.0 - len) / local.covector_norm(u)
            }
            ShapeEval::Box { local, row_norms } => {
                let q = local.apply(p);
                let mut value = f64::INFINITY;
                for i in 0..3 {
                    value = value.min(q[i].min(1.0 - q[i]) / row_norms[i]);
                }
                value
            }
            ShapeEval::Cone {
                local,
                row_z,
                r0,
                r1,
            } => {
                let [x, y, z] = local.apply(p);
                let rho = x.hypot(y);
                let (cx, cy) = if rho > 0.0 {
                    (x / rho, y / rho)
                } else {
                    (1.0, 0.0)
                };
                let f = r0 + (r1 - r0) * z - rho;
                let lateral = f / local.covector_norm([-cx, -cy, r1 - r0]);
                lateral.min(z / row_z).min((1.0 - z) / row_z)
            }
            ShapeEval::Torus {
                local,
                major,
                minor,
            } => {
                let [x, y, z] = local.apply(p);
                let rho = x.hypot(y);
                let (cx, cy) = if rho > 0.0 {
                    (x / rho, y / rho)
                } else {
                    (1.0, 0.0)
                };
                let (dr, dz) = (rho - major, z);
                let d = dr.hypot(dz);
                let u = if d > 0.0 {
                    [cx * dr / d, cy * dr / d, dz / d]
                } else {
                    [cx, cy, 0.0]
                };
                (minor - d) / local.covector_norm(u)
            }
            ShapeEval::Disk { plane } => {
                let q = plane.local(p);
                let rho = q.norm();
                let u = if rho > 0.0 { q / rho } else { Vector2::x() };
                (1.0 - rho) / plane.covector_norm(&u)
            }
            ShapeEval::Polygon { plane, edges } => {
                let q = plane.local(p);
                edges
                    .iter()
                    .map(|(v, n)| n.dot(&(q - v)))
                    .fold(f64::INFINITY, f64::min)
            }
            ShapeEval::Nonconvex {
                plane,
                local,
                global,
                linear,
            } => {
                let q = plane.local(p);
                // The foot of p in the polygon's plane, in global coordinates.
                let foot = plane.origin + linear.fixed_columns::<2>(0) * q;
                let n = global.len();
                let distance = (0..n)
                    .map(|i| {
                        super::polygon::segment_distance(&foot, &global[i], &global[(i + 1) % n])
                    })
                    .fold(f64::INFINITY, f64::min);
                if super::polygon::contains(local, [q.x, q.y]) {
                    distance
                } else {
                    -distance
                }
            }
            ShapeEval::Empty => f64::NEG_INFINITY,
        }
    }
}

/// Edge lines of a convex polygon with inward normals scaled to global
/// in-plane distance; clockwise input is reversed, zero-length edges skipped.
fn polygon_edges(plane: &InPlane, vertices: &[Point3]) -> Vec<(Vector2<f64>, Vector2<f64>)> {
    let vs: Vec<Vector2<f64>> = vertices.iter().map(|v| Vector2::new(v.x, v.y)).collect();
    let n = vs.len();
    let twice_area: f64 = (0..n).map(|i| vs[i].perp(&vs[(i + 1) % n])).sum();
    if twice_area.is_nan() || twice_area == 0.0 {
        return Vec::new();
    }
    let orientation = twice_area.signum();
    (0..n)
        .filter_map(|i| {
            let (v, w) = (vs[i], vs[(i + 1) % n]);
            let d = w - v;
            let normal = Vector2::new(-d.y, d.x) * orientation;
            let len = plane.covector_norm(&normal);
            (len > 0.0 && len.is_finite()).then(|| (v, normal / len))
        })
        .collect()
}
