//! `geomc inspect MESHFILE`: counts, groups with their watertightness,
//! bounding box, triangle quality and the surface checks, as stable text or
//! JSON.

use crate::formats::read::Loaded;
use crate::formats::read::clean::EdgeCounts;
use crate::mesh::Mesh;
use serde::Serialize;

#[derive(Debug, Clone, Serialize)]
pub struct GroupReport {
    pub name: String,
    pub kind: &'static str,
    pub triangles: usize,
    pub lines: usize,
    pub points: usize,
    /// Triangle groups only.
    pub watertight: Option<bool>,
    pub open_edges: Option<usize>,
    pub non_manifold_edges: Option<usize>,
}

#[derive(Debug, Clone, Serialize)]
pub struct Quality {
    pub min_angle_degrees: f64,
    pub max_angle_degrees: f64,
    /// Triangles with an angle under 10°.
    pub slivers: usize,
}

#[derive(Debug, Clone, Serialize)]
pub struct MeshReport {
    pub format: String,
    pub encoding: Option<&'static str>,
    pub nodes: usize,
    pub triangles: usize,
    pub lines: usize,
    pub points: usize,
    pub bounding_box: Option<[[f64; 3]; 2]>,
    pub edges: usize,
    pub open_edges: usize,
    pub non_manifold_edges: usize,
    pub inconsistent_edges: usize,
    pub degenerate_triangles: usize,
    pub watertight: bool,
    pub quality: Option<Quality>,
    pub subdomains: Vec<String>,
    pub groups: Vec<GroupReport>,
    pub warnings: Vec<String>,
}

impl MeshReport {
    pub fn of(loaded: &Loaded, format: &str) -> MeshReport {
        let mesh = &loaded.mesh;
        let whole = &loaded.report.whole;
        let mut groups = Vec::new();
        for (i, f) in mesh.faces.iter().enumerate() {
            let c = loaded.report.faces.get(i).cloned().unwrap_or_default();
            groups.push(GroupReport {
                name: f.name.clone(),
                kind: "triangles",
                triangles: f.triangles.len(),
                lines: 0,
                points: 0,
                watertight: Some(c.watertight()),
                open_edges: Some(c.open),
                non_manifold_edges: Some(c.non_manifold),
            });
        }
        for p in &mesh.polylines {
            groups.push(GroupReport {
                name: p.name.clone(),
                kind: "lines",
                triangles: 0,
                lines: p.nodes.len().saturating_sub(1),
                points: 0,
                watertight: None,
                open_edges: None,
                non_manifold_edges: None,
            });
        }
        for p in &mesh.point_sets {
            groups.push(GroupReport {
                name: p.name.clone(),
                kind: "points",
                triangles: 0,
                lines: 0,
                points: p.nodes.len(),
                watertight: None,
                open_edges: None,
                non_manifold_edges: None,
            });
        }
        MeshReport {
            format: format.to_string(),
            encoding: loaded.binary.map(|b| if b { "binary" } else { "ascii" }),
            nodes: mesh.nodes.len(),
            triangles: mesh.faces.iter().map(|f| f.triangles.len()).sum(),
            lines: mesh
                .polylines
                .iter()
                .map(|p| p.nodes.len().saturating_sub(1))
                .sum(),
            points: mesh.point_sets.iter().map(|p| p.nodes.len()).sum(),
            bounding_box: bounding_box(mesh),
            edges: whole.edges,
            open_edges: whole.open,
            non_manifold_edges: whole.non_manifold,
            inconsistent_edges: whole.inconsistent,
            degenerate_triangles: whole.degenerate,
            watertight: whole.watertight(),
            quality: quality(mesh),
            subdomains: mesh.subdomains.iter().map(|s| s.name.clone()).collect(),
            groups,
            warnings: loaded
                .warnings
                .iter()
                .map(|d| format!("{}: {}", d.code.as_str(), d.message))
                .collect(),
        }
    }

    pub fn render_text(&self) -> String {
        let mut out = String::new();
        let enc = self.encoding.map_or(String::new(), |e| format!(" ({e})"));
        out.push_str(&format!("format: {}{enc}\n", self.format));
        out.push_str(&format!(
            "counts: {} nodes, {} triangles, {} line segments, {} points\n",
            self.nodes, self.triangles, self.lines, self.points
        ));
        if let Some([lo, hi]) = self.bounding_box {
            out.push_str(&format!(
                "bounding box: [{}, {}, {}] .. [{}, {}, {}]\n",
                num(lo[0]),
                num(lo[1]),
                num(lo[2]),
                num(hi[0]),
                num(hi[1]),
                num(hi[2])
            ));
        }
        out.push_str(&format!(
            "surface: {} edges, {} open, {} non-manifold, {} inconsistently oriented, {} degenerate triangles: {}\n",
            self.edges,
            self.open_edges,
            self.non_manifold_edges,
            self.inconsistent_edges,
            self.degenerate_triangles,
            if self.watertight { "watertight" } else { "not watertight" }
        ));
        if let Some(q) = &self.quality {
            out.push_str(&format!(
                "quality: smallest angle {:.2}°, largest angle {:.2}°, {} triangles with an angle under 10°\n",
                q.min_angle_degrees, q.max_angle_degrees, q.slivers
            ));
        }
        if !self.subdomains.is_empty() {
            out.push_str(&format!("subdomains: {}\n", self.subdomains.join(", ")));
        }
        out.push_str(&format!("groups ({}):\n", self.groups.len()));
        for g in &self.groups {
            let what = match g.kind {
                "triangles" => format!(
                    "{} triangles, {}",
                    g.triangles,
                    if g.watertight == Some(true) {
                        "watertight".to_string()
                    } else {
                        format!(
                            "open ({} open, {} non-manifold edges)",
                            g.open_edges.unwrap_or(0),
                            g.non_manifold_edges.unwrap_or(0)
                        )
                    }
                ),
                "lines" => format!("{} line segments", g.lines),
                _ => format!("{} points", g.points),
            };
            out.push_str(&format!("  {}: {what}\n", g.name));
        }
        for w in &self.warnings {
            out.push_str(&format!("warning[{w}\n").replacen(": ", "]: ", 1));
        }
        out
    }

    pub fn render_json(&self) -> String {
        serde_json::to_string_pretty(self).unwrap_or_default()
    }
}

fn num(v: f64) -> String {
    crate::formats::fmt_num(v)
}

fn bounding_box(mesh: &Mesh) -> Option<[[f64; 3]; 2]> {
    let first = *mesh.nodes.first()?;
    let (mut lo, mut hi) = (first, first);
    for p in &mesh.nodes {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    Some([lo, hi])
}

fn quality(mesh: &Mesh) -> Option<Quality> {
    let mut min = f64::INFINITY;
    let mut max: f64 = 0.0;
    let mut slivers = 0;
    for t in mesh.faces.iter().flat_map(|f| &f.triangles) {
        let p = t.map(|n| mesh.nodes[n as usize]);
        let mut angles = [0.0; 3];
        for (k, a) in angles.iter_mut().enumerate() {
            let (o, u, v) = (p[k], p[(k + 1) % 3], p[(k + 2) % 3]);
            let du = [u[0] - o[0], u[1] - o[1], u[2] - o[2]];
            let dv = [v[0] - o[0], v[1] - o[1], v[2] - o[2]];
            let dot = du[0] * dv[0] + du[1] * dv[1] + du[2] * dv[2];
            let nu = (du[0] * du[0] + du[1] * du[1] + du[2] * du[2]).sqrt();
            let nv = (dv[0] * dv[0] + dv[1] * dv[1] + dv[2] * dv[2]).sqrt();
            *a = if nu > 0.0 && nv > 0.0 {
                (dot / (nu * nv)).clamp(-1.0, 1.0).acos().to_degrees()
            } else {
                0.0
            };
        }
        let lo = angles.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = angles.iter().copied().fold(0.0, f64::max);
        min = min.min(lo);
        max = max.max(hi);
        if lo < 10.0 {
            slivers += 1;
        }
    }
    min.is_finite().then_some(Quality {
        min_angle_degrees: min,
        max_angle_degrees: max,
        slivers,
    })
}

/// The per-group counts `inspect` shows, for tests.
pub fn group_counts(loaded: &Loaded) -> Vec<(String, EdgeCounts)> {
    loaded
        .mesh
        .faces
        .iter()
        .zip(&loaded.report.faces)
        .map(|(f, c)| (f.name.clone(), c.clone()))
        .collect()
}
