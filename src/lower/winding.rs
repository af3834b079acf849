//! Point containment for subdomains given by explicit face lists: the
//! generalised winding number over the faces' loops, each loop fanned into
//! triangles (exact for planar faces, an approximation of curved ones that
//! is good away from them), and an interior sample point for each face.

use crate::geom::{Point3, Vec3};
use crate::ir::{FaceId, Model, OrientedFace};

/// Triangles of a closed shell, oriented with the outward flags.
pub struct ShellTriangles {
    triangles: Vec<[Point3; 3]>,
}

impl ShellTriangles {
    pub fn of(model: &Model, boundary: &[OrientedFace]) -> ShellTriangles {
        let mut triangles = Vec::new();
        for of in boundary {
            for l in &model.face(of.face).loops {
                let points = loop_points(model, l);
                let Some(&apex) = points.first() else {
                    continue;
                };
                for k in 1..points.len().saturating_sub(1) {
                    let (b, c) = (points[k], points[k + 1]);
                    // The loop runs counter-clockwise about the face normal;
                    // an inward face is flipped.
                    triangles.push(if of.outward {
                        [apex, b, c]
                    } else {
                        [apex, c, b]
                    });
                }
            }
        }
        ShellTriangles { triangles }
    }

    /// The winding number of the shell about `p` (1 inside, 0 outside).
    pub fn winding(&self, p: &Point3) -> f64 {
        let total: f64 = self.triangles.iter().map(|t| solid_angle(t, p)).sum();
        total / (4.0 * std::f64::consts::PI)
    }

    pub fn contains(&self, p: &Point3) -> bool {
        self.winding(p) > 0.5
    }
}

/// The signed solid angle of a triangle seen from `p` (Van Oosterom–Strackee).
fn solid_angle(t: &[Point3; 3], p: &Point3) -> f64 {
    let (a, b, c) = (t[0] - p, t[1] - p, t[2] - p);
    let (la, lb, lc) = (a.norm(), b.norm(), c.norm());
    let numerator = a.dot(&b.cross(&c));
    let denominator = la * lb * lc + a.dot(&b) * lc + a.dot(&c) * lb + b.dot(&c) * la;
    2.0 * numerator.atan2(denominator)
}

/// A loop as a closed polygon (first point not repeated), curved edges sampled.
pub fn loop_points(model: &Model, l: &[crate::ir::OrientedEdge]) -> Vec<Point3> {
    let mut points = Vec::new();
    for e in l {
        let curve = model.edge_curve(e.edge);
        let n = match *curve {
            crate::geom::Curve::Segment { .. } => 1,
            _ => 16,
        };
        let mut samples = curve.samples(n);
        if !e.forward {
            samples.reverse();
        }
        samples.pop();
        points.extend(samples);
    }
    points
}

/// A point inside a face: the centroid of an ear of its outer loop (a convex
/// corner whose triangle holds no other loop point), moved onto the surface.
pub fn face_sample(model: &Model, face: FaceId) -> Option<Point3> {
    let f = model.face(face);
    let outer = loop_points(model, f.loops.first()?);
    let others: Vec<Point3> = f
        .loops
        .iter()
        .skip(1)
        .flat_map(|l| loop_points(model, l))
        .collect();
    let n = outer.len();
    if n < 3 {
        return None;
    }
    let centroid = Point3::from(outer.iter().map(|p| p.coords).sum::<Vec3>() / n as f64);
    let normal: Vec3 = (0..n)
        .map(|i| outer[i].coords.cross(&outer[(i + 1) % n].coords))
        .sum();
    for i in 0..n {
        let (a, b, c) = (outer[(i + n - 1) % n], outer[i], outer[(i + 1) % n]);
        if (b - a).cross(&(c - b)).dot(&normal) <= 0.0 {
            continue;
        }
        let inside = |p: &Point3| {
            let s1 = (b - a).cross(&(p - a)).dot(&normal);
            let s2 = (c - b).cross(&(p - b)).dot(&normal);
            let s3 = (a - c).cross(&(p - c)).dot(&normal);
            s1 > 0.0 && s2 > 0.0 && s3 > 0.0
        };
        let blocked = outer
            .iter()
            .chain(&others)
            .any(|p| *p != a && *p != b && *p != c && inside(p));
        if !blocked {
            let guess = Point3::from((a.coords + b.coords + c.coords) / 3.0);
            return Some(model.face_surface(face).project(&guess).unwrap_or(guess));
        }
    }
    Some(
        model
            .face_surface(face)
            .project(&centroid)
            .unwrap_or(centroid),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solid_angles_of_a_closed_cube_sum_to_one_turn() {
        let c = |x: f64, y: f64, z: f64| Point3::new(x, y, z);
        // The six faces of the unit cube, two triangles each, outward.
        let quads = [
            [c(0., 0., 0.), c(0., 1., 0.), c(1., 1., 0.), c(1., 0., 0.)],
            [c(0., 0., 1.), c(1., 0., 1.), c(1., 1., 1.), c(0., 1., 1.)],
            [c(0., 0., 0.), c(1., 0., 0.), c(1., 0., 1.), c(0., 0., 1.)],
            [c(0., 1., 0.), c(0., 1., 1.), c(1., 1., 1.), c(1., 1., 0.)],
            [c(0., 0., 0.), c(0., 0., 1.), c(0., 1., 1.), c(0., 1., 0.)],
            [c(1., 0., 0.), c(1., 1., 0.), c(1., 1., 1.), c(1., 0., 1.)],
        ];
        let shell = ShellTriangles {
            triangles: quads
                .iter()
                .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
                .collect(),
        };
        assert!((shell.winding(&c(0.5, 0.5, 0.5)) - 1.0).abs() < 1e-12);
        assert!((shell.winding(&c(0.1, 0.9, 0.2)) - 1.0).abs() < 1e-12);
        assert!(shell.winding(&c(1.5, 0.5, 0.5)).abs() < 1e-12);
        assert!(!shell.contains(&c(-0.1, 0.5, 0.5)));
    }
}
