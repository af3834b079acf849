//! The mesh-quality summary of `geomc inspect --mesh`: the achieved smallest
//! angle, the histogram of every triangle's smallest angle, and per
//! subdomain the triangle count, smallest angle and area range (2D: its
//! region triangles; 3D: the triangles of its boundary).

use crate::mesh::Mesh;
use serde::Serialize;

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MeshReport {
    pub nodes: usize,
    pub triangles: usize,
    /// The smallest angle of any triangle, degrees (180 without triangles).
    pub min_angle: f64,
    /// Triangles per 5° bin of their smallest angle: [0, 5), [5, 10), … [55, 60].
    pub angle_histogram: [usize; 12],
    pub subdomains: Vec<SubdomainQuality>,
}

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SubdomainQuality {
    pub name: String,
    pub triangles: usize,
    pub min_angle: f64,
    pub min_area: f64,
    pub max_area: f64,
}

/// Smallest angle (degrees) and area of a triangle.
fn measure(mesh: &Mesh, t: &[u32; 3]) -> (f64, f64) {
    let p = t.map(|n| nalgebra::Vector3::from(mesh.nodes[n as usize]));
    let mut smallest: f64 = 180.0;
    for i in 0..3 {
        let (u, v) = (p[(i + 1) % 3] - p[i], p[(i + 2) % 3] - p[i]);
        let angle = u.angle(&v).to_degrees();
        smallest = smallest.min(angle);
    }
    let area = 0.5 * (p[1] - p[0]).cross(&(p[2] - p[0])).norm();
    (smallest, area)
}

pub fn mesh_report(mesh: &Mesh) -> MeshReport {
    let mut report = MeshReport {
        nodes: mesh.nodes.len(),
        triangles: 0,
        min_angle: 180.0,
        angle_histogram: [0; 12],
        subdomains: Vec::new(),
    };
    for t in mesh.faces.iter().flat_map(|f| f.triangles.iter()) {
        let (angle, _) = measure(mesh, t);
        report.triangles += 1;
        report.min_angle = report.min_angle.min(angle);
        report.angle_histogram[((angle / 5.0) as usize).min(11)] += 1;
    }
    for sub in &mesh.subdomains {
        let mut q = SubdomainQuality {
            name: sub.name.clone(),
            triangles: 0,
            min_angle: 180.0,
            min_area: f64::INFINITY,
            max_area: 0.0,
        };
        for &(f, _) in &sub.faces {
            for t in mesh
                .faces
                .get(f as usize)
                .into_iter()
                .flat_map(|f| &f.triangles)
            {
                let (angle, area) = measure(mesh, t);
                q.triangles += 1;
                q.min_angle = q.min_angle.min(angle);
                q.min_area = q.min_area.min(area);
                q.max_area = q.max_area.max(area);
            }
        }
        if q.triangles == 0 {
            q.min_area = 0.0;
        }
        report.subdomains.push(q);
    }
    report
}

impl MeshReport {
    pub fn render_text(&self) -> String {
        use std::fmt::Write;
        let mut s = String::new();
        let _ = writeln!(
            s,
            "mesh: {} nodes, {} triangles",
            self.nodes, self.triangles
        );
        let _ = writeln!(s, "  minimum angle: {:.2}°", self.min_angle);
        let _ = writeln!(s, "  smallest-angle histogram:");
        let peak = self
            .angle_histogram
            .iter()
            .copied()
            .max()
            .unwrap_or(0)
            .max(1);
        for (i, &n) in self.angle_histogram.iter().enumerate() {
            if n == 0 {
                continue;
            }
            let bar = "#".repeat((40 * n).div_ceil(peak));
            let _ = writeln!(s, "    {:>2}–{:<2}° {n:>8} {bar}", 5 * i, 5 * i + 5);
        }
        for q in &self.subdomains {
            let _ = writeln!(
                s,
                "  {}: {} triangles, minimum angle {:.2}°, area {:.4e} .. {:.4e}",
                q.name, q.triangles, q.min_angle, q.min_area, q.max_area
            );
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{MeshFace, MeshSubdomain};

    #[test]
    fn a_right_isosceles_pair_reports_45_degrees_and_its_areas() {
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
        let r = mesh_report(&mesh);
        assert_eq!(r.triangles, 2);
        assert!((r.min_angle - 45.0).abs() < 1e-9);
        assert_eq!(r.angle_histogram[9], 2);
        let s = &r.subdomains[0];
        assert_eq!((s.min_area, s.max_area), (0.5, 1.0));
    }
}
