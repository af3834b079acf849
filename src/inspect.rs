//! Stable text and JSON summaries of a model, shared by `geomc inspect` and
//! the snapshot tests: counts, subdomains with their faces, fragments with
//! their subdomain pairs, the bounding box, parameters, incidence matrices.

use crate::geom::Aabb;
use crate::ir::{
    Dimension, Fragment, IncidenceMatrices, Model, Side, SubdomainCells, derive_fragments,
};
use serde::Serialize;
use std::fmt::Write;

#[derive(Debug, Clone, Serialize)]
pub struct SubdomainSummary {
    pub name: String,
    pub material: Option<String>,
    /// Boundary faces (3D, with `-` before inward-oriented ones) or region faces (2D).
    pub faces: Vec<String>,
}

#[derive(Debug, Clone, Serialize)]
pub struct FragmentSummary {
    pub name: String,
    pub subdomain: String,
    pub other: String,
    pub faces: Vec<String>,
    pub edges: Vec<String>,
}

#[derive(Debug, Clone, Serialize)]
pub struct Report {
    pub dimension: u8,
    pub vertices: usize,
    pub edges: usize,
    pub faces: usize,
    pub subdomains: Vec<SubdomainSummary>,
    pub fragments: Vec<FragmentSummary>,
    pub bbox_min: Option<[f64; 3]>,
    pub bbox_max: Option<[f64; 3]>,
    pub parameters: Vec<(String, f64)>,
    pub point_sets: usize,
    pub polylines: usize,
    /// Paper 003's curves (standalone lines and edge curves): "name: what".
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub curves: Vec<String>,
}

impl Report {
    pub fn of(model: &Model) -> Report {
        let bbox: Aabb = model.bbox();
        let fragments = derive_fragments(model);
        Report {
            dimension: if model.dimension == Dimension::Two {
                2
            } else {
                3
            },
            vertices: model.vertices.len(),
            edges: model.edges.len(),
            faces: model.faces.len(),
            subdomains: model
                .subdomains
                .iter()
                .map(|s| SubdomainSummary {
                    name: s.name.clone(),
                    material: s.material.clone(),
                    faces: match &s.cells {
                        SubdomainCells::Volume { boundary } => boundary
                            .iter()
                            .map(|of| {
                                let face = model.face(of.face);
                                // Trimmed faces: oriented on the mesh, marked.
                                // (never a primitive's: their carriers are their own).
                                if matches!(
                                    face.carrier.owned(),
                                    Some(crate::geom::Surface::Parametric(_))
                                ) {
                                    return format!("{} (trimmed)", face.name);
                                }
                                format!("{}{}", if of.outward { "" } else { "-" }, face.name)
                            })
                            // Trimmed faces without topology (a 2D model).
                            .chain(
                                s.trimmed
                                    .iter()
                                    .filter(|&&k| model.trimmed_face(k).is_none())
                                    .filter_map(|&k| {
                                        model
                                            .trimmed
                                            .get(k)
                                            .map(|t| format!("{} (trimmed)", t.name))
                                    }),
                            )
                            .collect(),
                        SubdomainCells::Region { faces } => faces
                            .iter()
                            .map(|f| model.face(*f).name.to_string())
                            .collect(),
                    },
                })
                .collect(),
            fragments: fragments
                .iter()
                .map(|f| fragment_summary(model, f))
                .collect(),
            bbox_min: (!bbox.is_empty()).then(|| [bbox.min.x, bbox.min.y, bbox.min.z].map(round)),
            bbox_max: (!bbox.is_empty()).then(|| [bbox.max.x, bbox.max.y, bbox.max.z].map(round)),
            parameters: model.parameters.clone(),
            point_sets: model.point_sets.len(),
            polylines: model.polylines.len(),
            curves: point_curves(model),
        }
    }

    pub fn render_text(&self, model: &Model, matrices: bool) -> String {
        let mut s = String::new();
        let _ = writeln!(s, "dimension: {}", self.dimension);
        let _ = writeln!(
            s,
            "vertices: {}  edges: {}  faces: {}  subdomains: {}  fragments: {}",
            self.vertices,
            self.edges,
            self.faces,
            self.subdomains.len(),
            self.fragments.len()
        );
        if self.point_sets + self.polylines > 0 {
            let _ = writeln!(
                s,
                "point sets: {}  poly_lines: {}",
                self.point_sets, self.polylines
            );
        }
        if !self.curves.is_empty() {
            let _ = writeln!(s, "curves:");
            for c in &self.curves {
                let _ = writeln!(s, "  {c}");
            }
        }
        if let (Some(min), Some(max)) = (self.bbox_min, self.bbox_max) {
            let _ = writeln!(s, "bounding box: ({}) .. ({})", join(&min), join(&max));
        }
        if !self.parameters.is_empty() {
            let _ = writeln!(s, "parameters:");
            for (name, value) in &self.parameters {
                let _ = writeln!(s, "  {name} = {}", crate::resolve_fmt(*value));
            }
        }
        if !self.subdomains.is_empty() {
            let _ = writeln!(s, "subdomains:");
            for sub in &self.subdomains {
                let material = sub
                    .material
                    .as_ref()
                    .map_or(String::new(), |m| format!(" [{m}]"));
                let _ = writeln!(
                    s,
                    "  {}{material}: {} face{}: {}",
                    sub.name,
                    sub.faces.len(),
                    plural(sub.faces.len()),
                    sub.faces.join(" ")
                );
            }
        }
        if !self.fragments.is_empty() {
            let _ = writeln!(s, "fragments:");
            for f in &self.fragments {
                let items = if f.faces.is_empty() {
                    &f.edges
                } else {
                    &f.faces
                };
                let _ = writeln!(
                    s,
                    "  {} ({} | {}): {}",
                    f.name,
                    f.subdomain,
                    f.other,
                    items.join(" ")
                );
            }
        }
        if matrices {
            let m = IncidenceMatrices::of(model);
            let vertices: Vec<String> = model.vertices.iter().map(|v| v.name.to_string()).collect();
            let edges: Vec<String> = model.edges.iter().map(|e| e.name.to_string()).collect();
            let faces: Vec<String> = model.faces.iter().map(|f| f.name.to_string()).collect();
            let subdomains: Vec<String> = model.subdomains.iter().map(|d| d.name.clone()).collect();
            for (title, matrix, rows, cols) in [
                ("M_VE (vertex × edge)", &m.ve, &vertices, &edges),
                ("M_EF (edge × face)", &m.ef, &edges, &faces),
                ("M_FD (face × subdomain)", &m.fd, &faces, &subdomains),
                ("V–F (vertex × face)", &m.vf, &vertices, &faces),
                ("E–D (edge × subdomain)", &m.ed, &edges, &subdomains),
            ] {
                let _ = writeln!(s, "\n{title}:");
                s.push_str(&matrix.render(rows, cols));
            }
        }
        s
    }

    pub fn render_json(&self, model: &Model, matrices: bool) -> String {
        let mut value = serde_json::to_value(self).unwrap_or_default();
        if matrices
            && let (Some(obj), Ok(m)) = (
                value.as_object_mut(),
                serde_json::to_value(IncidenceMatrices::of(model)),
            )
        {
            obj.insert("matrices".into(), m);
        }
        serde_json::to_string_pretty(&value).unwrap_or_default()
    }
}

fn fragment_summary(model: &Model, f: &Fragment) -> FragmentSummary {
    FragmentSummary {
        name: f.name.clone(),
        subdomain: model.subdomain(f.subdomain).name.clone(),
        other: match f.other {
            Side::Exterior => "exterior".into(),
            Side::Subdomain(id) => model.subdomain(id).name.clone(),
        },
        faces: f
            .faces
            .iter()
            .map(|id| model.face(*id).name.to_string())
            .collect(),
        edges: f
            .edges
            .iter()
            .map(|id| model.edge(*id).name.to_string())
            .collect(),
    }
}

fn round(v: f64) -> f64 {
    let r = (v * 1e9).round() / 1e9;
    if r == 0.0 { 0.0 } else { r }
}

fn join(v: &[f64; 3]) -> String {
    v.iter()
        .map(|x| crate::resolve_fmt(*x))
        .collect::<Vec<_>>()
        .join(", ")
}

fn plural(n: usize) -> &'static str {
    if n == 1 { "" } else { "s" }
}

/// Each point-calculus curve of the model with its kind (and a conic's type
/// by its discriminant): standalone lines first, then edges, in model order.
fn point_curves(model: &Model) -> Vec<String> {
    use crate::geom::Curve;
    use std::fmt::Display;
    let lines = model
        .polylines
        .iter()
        .map(|l| (&l.name as &dyn Display, &l.curve, "line"));
    let edges = model
        .edges
        .iter()
        // Point-calculus curves are never a primitive's: their carriers are their own.
        .map(|e| (&e.name as &dyn Display, e.carrier.owned(), "edge"));
    let mut out = Vec::new();
    for (name, curve, role) in lines.map(|(n, c, r)| (n, c.as_ref(), r)).chain(edges) {
        if let Some(Curve::PointCalculus(c)) = curve {
            out.push(format!("{name} ({role}): {}", c.describe()));
        }
    }
    out
}
