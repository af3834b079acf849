//! Paper 002's trimmed surfaces in the output mesh: each is meshed on its
//! own (`crate::trimmed`) and becomes a face named after the surface, its
//! boundary chains (trim curves and patch sides) edges named
//! `<surface>.boundary[k]`, so writers carry it like any face.

use super::MeshError;
use super::guard::guarded;
use crate::ir::Model;
use crate::mesh::{Mesh, MeshEdge, MeshFace};
use crate::trimmed::{TrimSettings, mesh_trimmed};
use rayon::prelude::*;

pub(super) fn append(
    model: &Model,
    mesh: &mut Mesh,
    tolerance: f64,
    min_angle: f64,
    max_edge: f64,
) -> Result<(), MeshError> {
    let settings = TrimSettings {
        tolerance,
        min_angle,
        max_edge,
    };
    // In parallel, taken in model order: the output does not depend on the
    // thread count.
    let meshes = model
        .trimmed
        .par_iter()
        .map(|s| {
            guarded(
                || format!("face `{}`", s.name),
                || {
                    mesh_trimmed(s, settings).map_err(|reason| MeshError::Face {
                        face: s.name.clone(),
                        reason,
                    })
                },
            )
        })
        .collect::<Result<Vec<_>, MeshError>>()?;
    for (s, m) in model.trimmed.iter().zip(meshes) {
        let base = mesh.nodes.len() as u32;
        mesh.nodes.extend(m.nodes.iter().map(|p| [p.x, p.y, p.z]));
        let mut boundary = Vec::with_capacity(m.boundary.len());
        for (k, chain) in m.boundary.iter().enumerate() {
            boundary.push((mesh.edges.len() as u32, true));
            mesh.edges.push(MeshEdge {
                name: format!("{}.boundary[{}]", s.name, k + 1),
                nodes: chain.iter().map(|&i| base + i).collect(),
            });
        }
        mesh.faces.push(MeshFace {
            name: s.name.clone(),
            triangles: m.triangles.iter().map(|t| t.map(|i| base + i)).collect(),
            boundary,
        });
    }
    Ok(())
}

/// `inspect --mesh` figures of one trimmed surface.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct TrimmedReport {
    pub name: String,
    pub triangles: usize,
    pub min_angle: f64,
    /// Triangles per 5° bin of their smallest angle: [0, 5), … [55, 60].
    pub min_angle_histogram: [usize; 12],
    /// The largest distance from a triangle's centroid to the surface.
    pub max_centroid_distance: f64,
    pub area: f64,
}

/// Re-meshes each trimmed surface as `append` did (the result is the same)
/// to measure it with its parameters at hand.
pub(super) fn reports(
    model: &Model,
    tolerance: f64,
    max_edge: Option<f64>,
    min_angle: f64,
) -> Vec<TrimmedReport> {
    let settings = TrimSettings {
        tolerance,
        min_angle,
        max_edge: max_edge.unwrap_or(f64::INFINITY),
    };
    model
        .trimmed
        .par_iter()
        .filter_map(|s| {
            let m = mesh_trimmed(s, settings).ok()?;
            let q = m.quality(s);
            Some(TrimmedReport {
                name: s.name.clone(),
                triangles: m.triangles.len(),
                min_angle: q.min_angle,
                min_angle_histogram: q.histogram,
                max_centroid_distance: q.max_centroid_distance,
                area: q.area,
            })
        })
        .collect()
}
