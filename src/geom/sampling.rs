//! Boundary samples of the primitive solids in their local coordinates,
//! emitted row by row so that consecutive samples are usually neighbours on
//! the surface (the crossing search in `intersect` relies on that).

use super::{Point3, SolidShape};
use std::f64::consts::{PI, TAU};

/// Local points covering every face of `shape`, edges and corners included:
/// about `density` steps along each parametric direction of each face.
pub(super) fn local_boundary_samples(shape: &SolidShape, density: usize) -> Vec<Point3> {
    let n = density.clamp(2, 4096);
    let mut out = Vec::new();
    match shape {
        SolidShape::Ball { .. } => {
            // Latitude rows with single points at the poles.
            for i in 0..=n {
                let theta = PI * i as f64 / n as f64;
                if i == 0 || i == n {
                    out.push(Point3::new(0.0, 0.0, theta.cos()));
                    continue;
                }
                for phi in angles(2 * n) {
                    let r = theta.sin();
                    out.push(Point3::new(r * phi.cos(), r * phi.sin(), theta.cos()));
                }
            }
        }
        SolidShape::Box { .. } => {
            for axis in 0..3 {
                for side in [0.0, 1.0] {
                    for i in 0..=n {
                        for j in 0..=n {
                            let mut q = [0.0; 3];
                            q[axis] = side;
                            q[(axis + 1) % 3] = i as f64 / n as f64;
                            q[(axis + 2) % 3] = j as f64 / n as f64;
                            out.push(Point3::from(q));
                        }
                    }
                }
            }
        }
        SolidShape::Cone { r0, r1, .. } => {
            for i in 0..=n {
                let z = i as f64 / n as f64;
                let r = r0 + (r1 - r0) * z;
                for phi in angles(2 * n) {
                    out.push(Point3::new(r * phi.cos(), r * phi.sin(), z));
                }
            }
            for (z, r) in [(0.0, *r0), (1.0, *r1)] {
                if r != 0.0 {
                    disk(&mut out, n, r, z);
                }
            }
        }
        SolidShape::Torus { major, minor, .. } => {
            for phi in angles(2 * n) {
                for theta in angles(n) {
                    let r = major + minor * theta.cos();
                    out.push(Point3::new(
                        r * phi.cos(),
                        r * phi.sin(),
                        minor * theta.sin(),
                    ));
                }
            }
        }
        SolidShape::Disk { .. } => {
            for phi in angles(4 * n) {
                out.push(Point3::new(phi.cos(), phi.sin(), 0.0));
            }
        }
        SolidShape::Polygon { vertices, .. } => {
            let m = vertices.len();
            for k in 0..m {
                let (v, w) = (vertices[k], vertices[(k + 1) % m]);
                for i in 0..n {
                    let f = i as f64 / n as f64;
                    out.push(Point3::new(
                        v.x + (w.x - v.x) * f,
                        v.y + (w.y - v.y) * f,
                        0.0,
                    ));
                }
            }
        }
    }
    out
}

/// `count` angles evenly spaced over a full turn, starting at 0.
fn angles(count: usize) -> impl Iterator<Item = f64> {
    (0..count).map(move |j| TAU * j as f64 / count as f64)
}

/// A flat cap at height `z`: the centre and `n` rings out to radius `r`.
fn disk(out: &mut Vec<Point3>, n: usize, r: f64, z: f64) {
    out.push(Point3::new(0.0, 0.0, z));
    for k in 1..=n {
        let rk = r * k as f64 / n as f64;
        for phi in angles(2 * n) {
            out.push(Point3::new(rk * phi.cos(), rk * phi.sin(), z));
        }
    }
}
