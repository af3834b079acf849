//! Quality of a trimmed-surface mesh: the distribution of per-triangle
//! minimum angles (paper 002's figure 5) and the largest distance from a
//! triangle's centroid to the surface.

use super::TrimmedSurface;
use super::triangulate::{TrimmedMesh, min_angle, nearest_parameter};
use crate::geom::Point3;

#[derive(Debug, Clone, PartialEq)]
pub struct TrimmedQuality {
    pub min_angle: f64,
    /// Triangles per 5° bin of their smallest angle.
    pub histogram: [usize; 12],
    pub max_centroid_distance: f64,
    /// Sum of the triangles' areas.
    pub area: f64,
}

/// The distance from `p` to the surface, searched from parameter `start`.
pub fn centroid_distance(s: &TrimmedSurface, p: Point3, start: [f64; 2]) -> f64 {
    let uv = nearest_parameter(s, p, start);
    let d = (s.point(uv[0], uv[1]) - p).norm();
    let d0 = (s.point(start[0], start[1]) - p).norm();
    if d.is_finite() { d.min(d0) } else { d0 }
}

impl TrimmedMesh {
    pub fn quality(&self, s: &TrimmedSurface) -> TrimmedQuality {
        let mut q = TrimmedQuality {
            min_angle: 180.0,
            histogram: [0; 12],
            max_centroid_distance: 0.0,
            area: 0.0,
        };
        for t in &self.triangles {
            let p = t.map(|i| self.nodes[i as usize]);
            let m = min_angle(&p);
            q.min_angle = q.min_angle.min(m);
            q.histogram[((m / 5.0).floor().max(0.0) as usize).min(11)] += 1;
            q.area += 0.5 * (p[1] - p[0]).cross(&(p[2] - p[0])).norm();
            let c = Point3::from((p[0].coords + p[1].coords + p[2].coords) / 3.0);
            let uv = t.map(|i| self.uv[i as usize]);
            let start = [
                (uv[0][0] + uv[1][0] + uv[2][0]) / 3.0,
                (uv[0][1] + uv[1][1] + uv[2][1]) / 3.0,
            ];
            // Across a welded seam or at a pole the corners' parameters are
            // not near one another and their mean may be no start: each
            // corner is tried too (every result is a surface point, so the
            // smallest is the best bound).
            let d = uv
                .iter()
                .map(|&corner| centroid_distance(s, c, corner))
                .fold(centroid_distance(s, c, start), f64::min);
            q.max_centroid_distance = q.max_centroid_distance.max(d);
        }
        q
    }
}

/// ∫ R · (R_u × R_v) du dv / 3 over the material part of the rectangle (a
/// 96 × 96 midpoint rule masked by W ≥ 0): the surface's share of the
/// volume a closed shell encloses, its normal R_u × R_v. The topology IR
/// fixes a shell's outward side by the sign of that volume; loops fanned
/// from a point cancel out on a tube (both rims' fans are flat disks).
pub fn volume_share(s: &TrimmedSurface) -> f64 {
    let [u0, u1, v0, v1] = s.rect;
    let n = 96;
    let (du, dv) = ((u1 - u0) / n as f64, (v1 - v0) / n as f64);
    let mut total = 0.0;
    for i in 0..n {
        for j in 0..n {
            let (u, v) = (u0 + (i as f64 + 0.5) * du, v0 + (j as f64 + 0.5) * dv);
            if s.material(u, v) < 0.0 {
                continue;
            }
            let (ru, rv) = s.tangents(u, v);
            let term = s.point(u, v).coords.dot(&ru.cross(&rv));
            if term.is_finite() {
                total += term;
            }
        }
    }
    total * du * dv / 3.0
}
