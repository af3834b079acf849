//! The mesh report of `geomc inspect --mesh`: counts, triangle quality
//! (smallest angles and their histogram, aspect ratios) and, per subdomain,
//! the mesh's volume and area against the exact ones with relative errors,
//! and the range of its triangle areas (2D: its region triangles; 3D: the
//! triangles of its boundary), which `area=` and `--max-area` bound.

use super::exact::{ExactMeasure, subdomain_measures};
use crate::ir::Model;
use crate::mesh::Mesh;
use nalgebra::Vector3;
use serde::Serialize;
use std::fmt::Write;

/// Width of a bin of the smallest-angle histogram, degrees.
const BIN_DEGREES: f64 = 5.0;

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MeshReport {
    /// The chordal tolerance used, as a length.
    pub tolerance: f64,
    pub max_edge: Option<f64>,
    pub min_angle_target: f64,
    pub nodes: usize,
    pub triangles: usize,
    /// Segments of the edges' polylines.
    pub edge_segments: usize,
    /// Points of point sets and segments of poly_lines.
    pub points: usize,
    pub polyline_segments: usize,
    /// The smallest triangle angle, degrees (180 without triangles).
    pub min_angle: f64,
    /// Triangles per 5° bin of their smallest angle: [0, 5), [5, 10), … [55, 60].
    pub min_angle_histogram: [usize; 12],
    /// Longest edge / (2√3 · inradius): 1 for an equilateral triangle.
    pub max_aspect_ratio: f64,
    pub mean_aspect_ratio: f64,
    pub subdomains: Vec<SubdomainReport>,
    /// Paper 002's trimmed surfaces, one per surface (issue 9).
    pub trimmed: Vec<super::trimmed::TrimmedReport>,
}

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SubdomainReport {
    pub name: String,
    pub triangles: usize,
    pub min_angle: f64,
    /// 3D only: the volume the triangles enclose, the exact one, and
    /// |mesh − exact| / exact.
    pub mesh_volume: Option<f64>,
    pub exact_volume: Option<f64>,
    pub volume_error: Option<f64>,
    /// 3D only: the relative volume error a surface within the tolerance of
    /// the exact one can have, tolerance · exact area / exact volume.
    pub volume_bound: Option<f64>,
    /// Boundary area (3D) or region area (2D).
    pub mesh_area: f64,
    pub exact_area: Option<f64>,
    pub area_error: Option<f64>,
    /// The smallest and largest triangle area (0 without triangles).
    pub min_area: f64,
    pub max_area: f64,
}

/// Per-triangle figures gathered in one pass.
#[derive(Default)]
struct Angles {
    count: usize,
    min: f64,
    histogram: [usize; 12],
    max_aspect: f64,
    aspect_sum: f64,
}

impl Angles {
    fn new() -> Angles {
        Angles {
            min: 180.0,
            ..Angles::default()
        }
    }

    fn add(&mut self, [a, b, c]: [Vector3<f64>; 3]) {
        let (ab, bc, ca) = (b - a, c - b, a - c);
        let (lab, lbc, lca) = (ab.norm(), bc.norm(), ca.norm());
        let angle = |u: Vector3<f64>, v: Vector3<f64>| u.angle(&v).to_degrees();
        let smallest = angle(ab, -ca).min(angle(bc, -ab)).min(angle(ca, -bc));
        let twice_area = ab.cross(&(-ca)).norm();
        let inradius = twice_area / (lab + lbc + lca);
        let mut aspect = lab.max(lbc).max(lca) / (2.0 * 3f64.sqrt() * inradius);
        if aspect.is_nan() {
            aspect = f64::INFINITY;
        }
        self.count += 1;
        self.min = self.min.min(smallest);
        let bin = ((smallest / BIN_DEGREES).floor().max(0.0) as usize).min(11);
        self.histogram[bin] += 1;
        self.max_aspect = self.max_aspect.max(aspect);
        self.aspect_sum += aspect;
    }
}

impl MeshReport {
    /// Measures `mesh`, meshed from `model` with the given options.
    pub fn of(
        model: &Model,
        mesh: &Mesh,
        tolerance: f64,
        max_edge: Option<f64>,
        min_angle_target: f64,
    ) -> MeshReport {
        let point = |i: u32| {
            mesh.nodes
                .get(i as usize)
                .map_or(Vector3::zeros(), |p| Vector3::from(*p))
        };
        let mut all = Angles::new();
        for face in &mesh.faces {
            for t in &face.triangles {
                all.add(t.map(point));
            }
        }
        let exact = subdomain_measures(model);
        let three_d = mesh.dimension == 3;
        let subdomains = mesh
            .subdomains
            .iter()
            .enumerate()
            .map(|(k, sub)| {
                let mut angles = Angles::new();
                let (mut volume, mut area) = (0.0, 0.0);
                let (mut min_area, mut max_area) = (f64::INFINITY, 0.0f64);
                for &(f, outward) in &sub.faces {
                    let Some(face) = mesh.faces.get(f as usize) else {
                        continue;
                    };
                    let sign = if outward { 1.0 } else { -1.0 };
                    for t in &face.triangles {
                        let [a, b, c] = t.map(point);
                        angles.add([a, b, c]);
                        let triangle = 0.5 * (b - a).cross(&(c - a)).norm();
                        area += triangle;
                        min_area = min_area.min(triangle);
                        max_area = max_area.max(triangle);
                        volume += sign * a.dot(&b.cross(&c)) / 6.0;
                    }
                }
                let exact: Option<ExactMeasure> = exact.get(k).copied().flatten();
                let relative = |mesh: f64, exact: f64| (mesh - exact).abs() / exact.abs();
                SubdomainReport {
                    name: sub.name.clone(),
                    triangles: angles.count,
                    min_angle: angles.min,
                    mesh_volume: three_d.then_some(volume),
                    exact_volume: exact.filter(|_| three_d).map(|e| e.volume),
                    volume_error: exact
                        .filter(|_| three_d)
                        .map(|e| relative(volume, e.volume)),
                    volume_bound: exact
                        .filter(|_| three_d)
                        .map(|e| tolerance * e.area / e.volume.abs()),
                    mesh_area: area,
                    exact_area: exact.map(|e| e.area),
                    area_error: exact.map(|e| relative(area, e.area)),
                    min_area: if angles.count > 0 { min_area } else { 0.0 },
                    max_area,
                }
            })
            .collect();
        let segments = |nodes: &[u32]| nodes.len().saturating_sub(1);
        MeshReport {
            tolerance,
            max_edge,
            min_angle_target,
            nodes: mesh.nodes.len(),
            triangles: all.count,
            edge_segments: mesh.edges.iter().map(|e| segments(&e.nodes)).sum(),
            points: mesh.point_sets.iter().map(|p| p.nodes.len()).sum(),
            polyline_segments: mesh.polylines.iter().map(|p| segments(&p.nodes)).sum(),
            min_angle: all.min,
            min_angle_histogram: all.histogram,
            max_aspect_ratio: all.max_aspect,
            mean_aspect_ratio: if all.count > 0 {
                all.aspect_sum / all.count as f64
            } else {
                0.0
            },
            subdomains,
            trimmed: super::trimmed::reports(model, mesh, tolerance, max_edge, min_angle_target),
        }
    }

    pub fn render_text(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(
            s,
            "mesh: tolerance {}  max edge {}  min angle target {}°",
            sig(self.tolerance),
            self.max_edge.map_or("none".to_string(), sig),
            sig(self.min_angle_target)
        );
        let _ = writeln!(
            s,
            "nodes: {}  triangles: {}  edge segments: {}",
            self.nodes, self.triangles, self.edge_segments
        );
        if self.points + self.polyline_segments > 0 {
            let _ = writeln!(
                s,
                "points: {}  poly_line segments: {}",
                self.points, self.polyline_segments
            );
        }
        if self.triangles > 0 {
            let _ = writeln!(
                s,
                "quality: min angle {}°  aspect ratio max {} mean {}",
                fixed(self.min_angle, 2),
                fixed(self.max_aspect_ratio, 3),
                fixed(self.mean_aspect_ratio, 3)
            );
            let _ = writeln!(s, "smallest angle per triangle (degrees):");
            let most = self.min_angle_histogram.iter().copied().max().unwrap_or(0);
            for (i, &n) in self.min_angle_histogram.iter().enumerate() {
                let lo = i as f64 * BIN_DEGREES;
                let close = if i == 11 { ']' } else { ')' };
                let bar = "#".repeat((40 * n).div_ceil(most.max(1)));
                let _ = writeln!(s, "  [{lo:>2}, {:>2}{close} {n:>9} {bar}", lo + BIN_DEGREES);
            }
        }
        for t in &self.trimmed {
            let _ = writeln!(
                s,
                "trimmed surface {}: {} triangles, min angle {}°, area {}, max centroid-to-surface distance {}",
                t.name,
                t.triangles,
                fixed(t.min_angle, 2),
                sig(t.area),
                sci(t.max_centroid_distance)
            );
            let _ = writeln!(
                s,
                "  smallest angle per triangle: {:?} (5° bins)",
                t.min_angle_histogram
            );
        }
        if !self.subdomains.is_empty() {
            let _ = writeln!(s, "subdomains (mesh | exact | relative error):");
        }
        for sub in &self.subdomains {
            let _ = writeln!(
                s,
                "  {}: {} triangles, min angle {}°, triangle area {} .. {}",
                sub.name,
                sub.triangles,
                fixed(sub.min_angle, 2),
                sci(sub.min_area),
                sci(sub.max_area)
            );
            if let Some(volume) = sub.mesh_volume {
                let bound = sub
                    .volume_bound
                    .map_or(String::new(), |b| format!(" (bound {})", sci(b)));
                let _ = writeln!(
                    s,
                    "    volume {} | {} | {}{bound}",
                    sig(volume),
                    sub.exact_volume.map_or("-".to_string(), sig),
                    sub.volume_error.map_or("-".to_string(), sci),
                );
            }
            let _ = writeln!(
                s,
                "    area   {} | {} | {}",
                sig(sub.mesh_area),
                sub.exact_area.map_or("-".to_string(), sig),
                sub.area_error.map_or("-".to_string(), sci),
            );
        }
        s
    }

    pub fn render_json(&self) -> String {
        serde_json::to_string_pretty(self).unwrap_or_default()
    }
}

/// Ten significant digits, trailing zeros dropped.
fn sig(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let digits = (9 - x.abs().log10().floor() as i32).clamp(0, 17) as usize;
    let text = format!("{x:.digits$}");
    if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        text
    }
}

fn fixed(x: f64, digits: usize) -> String {
    format!("{x:.digits$}")
}

fn sci(x: f64) -> String {
    format!("{x:.2e}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_print_compactly() {
        assert_eq!(sig(4.0), "4");
        assert_eq!(sig(4.18879020478639), "4.188790205");
        assert_eq!(sig(0.001), "0.001");
        assert_eq!(sci(0.000123), "1.23e-4");
    }

    #[test]
    fn an_equilateral_triangle_has_aspect_one_and_sixty_degrees() {
        let mut a = Angles::new();
        a.add([
            Vector3::new(0.0, 0.0, 0.0),
            Vector3::new(1.0, 0.0, 0.0),
            Vector3::new(0.5, 3f64.sqrt() / 2.0, 0.0),
        ]);
        assert!((a.min - 60.0).abs() < 1e-9);
        assert!((a.max_aspect - 1.0).abs() < 1e-12);
        assert_eq!(a.histogram[11], 1);
    }

    #[test]
    fn a_right_isosceles_pair_reports_45_degrees_and_its_areas() {
        use crate::mesh::{MeshFace, MeshSubdomain};
        let mesh = Mesh {
            dimension: 2,
            nodes: vec![[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 2., 0.]],
            faces: vec![MeshFace {
                name: "f".into(),
                triangles: vec![[0, 1, 2], [0, 2, 3]],
                boundary: Vec::new(),
            }],
            subdomains: vec![MeshSubdomain {
                name: "s".into(),
                material: None,
                faces: vec![(0, true)],
            }],
            ..Mesh::default()
        };
        let r = MeshReport::of(
            &Model::empty(crate::ir::Dimension::Two),
            &mesh,
            0.01,
            None,
            25.0,
        );
        assert_eq!(r.triangles, 2);
        assert!((r.min_angle - 45.0).abs() < 1e-9);
        assert_eq!(r.min_angle_histogram[9], 2);
        let s = &r.subdomains[0];
        assert_eq!((s.min_area, s.max_area), (0.5, 1.0));
    }
}
