//! The primitive solids in canonical local form, with implicit functions
//! (positive inside), exact measures, and boundary samples for the checks
//! that find crossing boundaries.

use super::shape_eval::ShapeEval;
use super::{Aabb, Frame, Mat3, Point3, Vec3};
use std::f64::consts::PI;

#[derive(Debug, Clone, PartialEq)]
pub enum SolidShape {
    /// The unit ball |q| ≤ 1 in `frame` (sphere, ellipsoid).
    Ball { frame: Frame },
    /// The unit cube [0, 1]³ in `frame` (parallelepiped: the columns of the
    /// frame's linear map are the three edge vectors).
    Box { frame: Frame },
    /// 0 ≤ z ≤ 1 and x² + y² ≤ (r0 + (r1 − r0)·z)² in `frame`: the frame's z
    /// column runs from the bottom centre to the top centre, x and y columns are
    /// unit vectors perpendicular to it (before any scaling).
    Cone { frame: Frame, r0: f64, r1: f64 },
    /// (√(x² + y²) − major)² + z² ≤ minor² in `frame`.
    Torus {
        frame: Frame,
        major: f64,
        minor: f64,
    },
    /// 2D: the unit disk x² + y² ≤ 1, z = 0 of `frame` (circle, ellipse).
    Disk { frame: Frame },
    /// 2D: a simple polygon in the z = 0 plane of `frame`, local coordinates
    /// (triangle and parallelogram: convex and counter-clockwise; polygon,
    /// rectangle, regular polygon: as given, either orientation).
    Polygon { frame: Frame, vertices: Vec<Point3> },
}

impl SolidShape {
    /// Positive inside, zero on the boundary, negative outside; scaled to be
    /// close to a signed distance near the boundary (for tolerance tests).
    pub fn value(&self, p: &Point3) -> f64 {
        ShapeEval::new(self).value(p)
    }

    pub fn is_planar(&self) -> bool {
        matches!(self, SolidShape::Disk { .. } | SolidShape::Polygon { .. })
    }

    pub fn bbox(&self) -> Aabb {
        let mut bbox = Aabb::empty();
        match self {
            SolidShape::Ball { frame } => {
                // x_i ranges over o_i ± |i-th row of L| on the image of the unit ball.
                let half = Vec3::from_fn(|i, _| frame.linear.row(i).norm());
                include_box(&mut bbox, &frame.origin, &half);
            }
            SolidShape::Box { frame } => {
                for corner in 0..8 {
                    let q = Point3::from(Vec3::from_fn(|i, _| ((corner >> i) & 1) as f64));
                    bbox.include(&frame.to_global(&q));
                }
            }
            SolidShape::Cone { frame, r0, r1 } => {
                let top = frame.to_global(&Point3::new(0.0, 0.0, 1.0));
                include_box(
                    &mut bbox,
                    &frame.origin,
                    &(disk_half(&frame.linear) * r0.abs()),
                );
                include_box(&mut bbox, &top, &(disk_half(&frame.linear) * r1.abs()));
            }
            SolidShape::Torus {
                frame,
                major,
                minor,
            } => {
                // Core circle image plus the image of a ball of the minor radius.
                let half = disk_half(&frame.linear) * major.abs()
                    + Vec3::from_fn(|i, _| frame.linear.row(i).norm()) * minor.abs();
                include_box(&mut bbox, &frame.origin, &half);
            }
            SolidShape::Disk { frame } => {
                include_box(&mut bbox, &frame.origin, &disk_half(&frame.linear));
            }
            SolidShape::Polygon { frame, vertices } => {
                for v in vertices {
                    bbox.include(&frame.to_global(&Point3::new(v.x, v.y, 0.0)));
                }
            }
        }
        bbox
    }

    /// The exact volume (3D) or area (2D).
    pub fn measure(&self) -> f64 {
        match self {
            SolidShape::Ball { frame } => 4.0 / 3.0 * PI * frame.determinant().abs(),
            SolidShape::Box { frame } => frame.determinant().abs(),
            // Local frustum of height 1; the determinant carries the height
            // (z column) and any scaling of the cross-section.
            SolidShape::Cone { frame, r0, r1 } => {
                PI * (r0 * r0 + r0 * r1 + r1 * r1) / 3.0 * frame.determinant().abs()
            }
            SolidShape::Torus {
                frame,
                major,
                minor,
            } => 2.0 * PI * PI * major.abs() * minor * minor * frame.determinant().abs(),
            SolidShape::Disk { frame } => PI * plane_area_factor(&frame.linear),
            SolidShape::Polygon { frame, vertices } => {
                let n = vertices.len();
                let twice: f64 = (0..n)
                    .map(|i| {
                        let (v, w) = (vertices[i], vertices[(i + 1) % n]);
                        v.x * w.y - w.x * v.y
                    })
                    .sum();
                twice.abs() / 2.0 * plane_area_factor(&frame.linear)
            }
        }
    }

    /// A point strictly inside.
    pub fn interior_point(&self) -> Point3 {
        match self {
            SolidShape::Ball { frame } | SolidShape::Disk { frame } => frame.origin,
            SolidShape::Box { frame } => frame.to_global(&Point3::new(0.5, 0.5, 0.5)),
            SolidShape::Cone { frame, .. } => frame.to_global(&Point3::new(0.0, 0.0, 0.5)),
            SolidShape::Torus { frame, major, .. } => {
                frame.to_global(&Point3::new(*major, 0.0, 0.0))
            }
            SolidShape::Polygon { frame, vertices } if !super::polygon::is_convex(vertices) => {
                frame.to_global(&super::polygon::interior_point(vertices))
            }
            SolidShape::Polygon { frame, vertices } => {
                // The vertex centroid of a convex polygon is inside it.
                let n = vertices.len().max(1) as f64;
                let sum = vertices.iter().fold(Vec3::zeros(), |acc, v| acc + v.coords);
                frame.to_global(&Point3::new(sum.x / n, sum.y / n, 0.0))
            }
        }
    }

    /// Points spread over the whole boundary (including its edges and corners)
    /// with spacing about `1/density` of the solid's size in each parametric
    /// direction; for 2D shapes, points along the boundary curve.
    pub fn boundary_samples(&self, density: usize) -> Vec<Point3> {
        let mut points = super::sampling::local_boundary_samples(self, density);
        // Plain arithmetic: this runs for thousands of points per check.
        let frame = self.frame();
        let (o, l) = (frame.origin, frame.linear);
        let m = [0, 1, 2, 3, 4, 5, 6, 7, 8].map(|k| l[(k / 3, k % 3)]);
        let (ox, oy, oz) = (o.x, o.y, o.z);
        for p in &mut points {
            let (x, y, z) = (p.x, p.y, p.z);
            p.x = ox + m[0] * x + m[1] * y + m[2] * z;
            p.y = oy + m[3] * x + m[4] * y + m[5] * z;
            p.z = oz + m[6] * x + m[7] * y + m[8] * z;
        }
        points
    }

    /// The frame every variant is defined in.
    pub fn frame(&self) -> &Frame {
        match self {
            SolidShape::Ball { frame }
            | SolidShape::Box { frame }
            | SolidShape::Cone { frame, .. }
            | SolidShape::Torus { frame, .. }
            | SolidShape::Disk { frame }
            | SolidShape::Polygon { frame, .. } => frame,
        }
    }
}

/// Half extents per global axis of the image of the unit disk in the local
/// xy plane: √(L_i0² + L_i1²).
fn disk_half(linear: &Mat3) -> Vec3 {
    Vec3::from_fn(|i, _| linear[(i, 0)].hypot(linear[(i, 1)]))
}

fn include_box(bbox: &mut Aabb, center: &Point3, half: &Vec3) {
    bbox.include(&(center - half));
    bbox.include(&(center + half));
}

/// Area of the image of the local unit square in the z = 0 plane: |x col × y col|.
fn plane_area_factor(linear: &Mat3) -> f64 {
    linear.column(0).cross(&linear.column(1)).norm()
}
