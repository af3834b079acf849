//! Paper 002's trimmed surfaces in the output mesh: each is meshed on its
//! own (`crate::trimmed`) and becomes a face named after the surface, its
//! boundary chains (trim curves and patch sides) edges named
//! `<surface>.boundary[k]`, so writers carry it like any face.

use super::MeshError;
use super::guard::guarded;
use crate::geom::Point3;
use crate::ir::Model;
use crate::mesh::{Mesh, MeshEdge, MeshFace};
use crate::trimmed::shared::coincide;
use crate::trimmed::{TrimSettings, TrimmedMesh, TrimmedSurface, mesh_trimmed_shared};
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
    let mesh_one = |s: &TrimmedSurface, chains: &[Vec<Point3>]| {
        guarded(
            || format!("face `{}`", s.name),
            || {
                mesh_trimmed_shared(s, settings, chains).map_err(|reason| MeshError::Face {
                    face: s.name.clone(),
                    reason,
                })
            },
        )
    };
    // In parallel, taken in model order: the output does not depend on the
    // thread count.
    let mut meshes = model
        .trimmed
        .par_iter()
        .map(|s| mesh_one(s, &[]))
        .collect::<Result<Vec<_>, MeshError>>()?;
    let edges = closed_edges(mesh, |_, _| true);
    let sources = share(model, &edges, &mut meshes, tolerance, &mesh_one)?;
    // Global node ids: each surface's own nodes in model order, then the
    // shared ones from the chain they were taken from.
    let mut ids: Vec<Vec<u32>> = Vec::with_capacity(meshes.len());
    for m in &meshes {
        let mut own = vec![true; m.nodes.len()];
        for &(n, _, _) in &m.shared {
            own[n as usize] = false;
        }
        let mut v = vec![u32::MAX; m.nodes.len()];
        for (i, p) in m.nodes.iter().enumerate() {
            if own[i] {
                v[i] = mesh.nodes.len() as u32;
                mesh.nodes.push([p.x, p.y, p.z]);
            }
        }
        ids.push(v);
    }
    // A chain may itself hold shared nodes: resolve until nothing changes.
    for _ in 0..=meshes.len() {
        let mut changed = false;
        for j in 0..meshes.len() {
            for &(n, c, i) in &meshes[j].shared {
                let global = match sources[j].get(c) {
                    Some(ChainSource::Edge(e)) => mesh.edges[*e].nodes[i],
                    Some(ChainSource::Chain(s, k)) => ids[*s][meshes[*s].boundary[*k][i] as usize],
                    None => u32::MAX,
                };
                if ids[j][n as usize] != global {
                    ids[j][n as usize] = global;
                    changed = true;
                }
            }
        }
        if !changed {
            break;
        }
    }
    let mut chains = Vec::with_capacity(meshes.len());
    for (j, (s, m)) in model.trimmed.iter().zip(&meshes).enumerate() {
        let id = |i: &u32| ids[j][*i as usize];
        if m.triangles.iter().flatten().any(|i| id(i) == u32::MAX) {
            return Err(MeshError::Internal {
                entity: format!("face `{}`", s.name),
                message: "a shared trim node has no node".into(),
            });
        }
        chains.push(
            m.boundary
                .iter()
                .map(|chain| chain.iter().map(id).collect::<Vec<u32>>())
                .collect::<Vec<_>>(),
        );
    }
    // The IR's trimmed edges and vertices cut out of those chains; a
    // model without them (a surface meshed on its own) keeps whole chains.
    let boundaries = match model.trimmed_start {
        Some(_) => super::trimmed_edges::write(model, mesh, &chains)?,
        None => chains
            .iter()
            .zip(&model.trimmed)
            .map(|(own, s)| {
                own.iter()
                    .enumerate()
                    .map(|(k, nodes)| {
                        mesh.edges.push(MeshEdge {
                            name: format!("{}.boundary[{}]", s.name, k + 1),
                            nodes: nodes.clone(),
                        });
                        ((mesh.edges.len() - 1) as u32, true)
                    })
                    .collect()
            })
            .collect(),
    };
    for (j, (s, m)) in model.trimmed.iter().zip(&meshes).enumerate() {
        let id = |i: &u32| ids[j][*i as usize];
        mesh.faces.push(MeshFace {
            name: s.name.clone(),
            triangles: m.triangles.iter().map(|t| t.map(|i| id(&i))).collect(),
            boundary: boundaries[j].clone(),
        });
    }
    Ok(())
}

/// The closed edges of `mesh` (first node repeated last) that `keep` keeps,
/// as chains a trim loop may take.
fn closed_edges(
    mesh: &Mesh,
    keep: impl Fn(usize, &str) -> bool,
) -> Vec<(ChainSource, Vec<Point3>)> {
    let point = |n: u32| {
        let p = mesh.nodes.get(n as usize).copied().unwrap_or([f64::NAN; 3]);
        Point3::new(p[0], p[1], p[2])
    };
    mesh.edges
        .iter()
        .enumerate()
        .filter(|(i, e)| {
            e.nodes.len() >= 4 && e.nodes.first() == e.nodes.last() && keep(*i, &e.name)
        })
        .map(|(i, e)| {
            (
                ChainSource::Edge(i),
                e.nodes.iter().map(|&n| point(n)).collect(),
            )
        })
        .collect()
}

/// Meshes one surface given the chains it may share.
type MeshOne<'a> =
    dyn Fn(&TrimmedSurface, &[Vec<Point3>]) -> Result<TrimmedMesh, MeshError> + Sync + 'a;

/// Where a chain offered to a trimmed surface comes from.
#[derive(Debug, Clone, Copy, PartialEq)]
enum ChainSource {
    /// A closed model edge of the mesh (index in `mesh.edges`).
    Edge(usize),
    /// Boundary chain k of trimmed surface s.
    Chain(usize, usize),
}

/// Re-meshes each trimmed surface with a closed trim loop that coincides
/// with a closed model edge or another surface's chain on that chain's
/// nodes. The chain that is no trim loop (a patch side, a model edge), or
/// else the surface first in the model, keeps its nodes. Returns per
/// surface the sources of the chains it was given.
fn share(
    model: &Model,
    edges: &[(ChainSource, Vec<Point3>)],
    meshes: &mut [TrimmedMesh],
    tolerance: f64,
    mesh_one: &MeshOne<'_>,
) -> Result<Vec<Vec<ChainSource>>, MeshError> {
    let chain_points = |m: &TrimmedMesh, k: usize| -> Vec<Point3> {
        m.boundary[k].iter().map(|&n| m.nodes[n as usize]).collect()
    };
    let distance = 2.0 * tolerance;
    let n = meshes.len();
    // Which surfaces take a chain, and whose chains they wait for.
    let mut partners: Vec<Vec<usize>> = vec![Vec::new(); n];
    let mut pending = vec![false; n];
    for j in 0..n {
        for k in (0..meshes[j].boundary.len()).filter(|&k| meshes[j].trim_loop[k]) {
            let pts = chain_points(&meshes[j], k);
            let pts = &pts[..pts.len() - 1];
            if edges.iter().any(|(_, c)| coincide(pts, c, distance)) {
                pending[j] = true;
            }
            for i in (0..n).filter(|&i| i != j) {
                for k2 in 0..meshes[i].boundary.len() {
                    let owner = !meshes[i].trim_loop[k2] || i < j;
                    if owner && coincide(pts, &chain_points(&meshes[i], k2), distance) {
                        pending[j] = true;
                        partners[j].push(i);
                    }
                }
            }
        }
    }
    let mut sources: Vec<Vec<ChainSource>> = vec![Vec::new(); n];
    while let Some(j) = (0..n)
        .find(|&j| pending[j] && partners[j].iter().all(|&i| !pending[i]))
        .or_else(|| (0..n).find(|&j| pending[j]))
    {
        pending[j] = false;
        let mut offered = edges.to_vec();
        for (i, m) in meshes.iter().enumerate() {
            if i != j && !pending[i] {
                for k in 0..m.boundary.len() {
                    offered.push((ChainSource::Chain(i, k), chain_points(m, k)));
                }
            }
        }
        let chains: Vec<Vec<Point3>> = offered.iter().map(|(_, c)| c.clone()).collect();
        meshes[j] = mesh_one(&model.trimmed[j], &chains)?;
        sources[j] = offered.into_iter().map(|(s, _)| s).collect();
    }
    Ok(sources)
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

/// Re-meshes each trimmed surface as `append` did, shared chains included
/// (the result is the same), to measure it with its parameters at hand.
pub(super) fn reports(
    model: &Model,
    mesh: &Mesh,
    tolerance: f64,
    max_edge: Option<f64>,
    min_angle: f64,
) -> Vec<TrimmedReport> {
    let settings = TrimSettings {
        tolerance,
        min_angle,
        max_edge: max_edge.unwrap_or(f64::INFINITY),
    };
    let mesh_one = |s: &TrimmedSurface, chains: &[Vec<Point3>]| {
        mesh_trimmed_shared(s, settings, chains).map_err(|reason| MeshError::Face {
            face: s.name.clone(),
            reason,
        })
    };
    let Ok(mut meshes) = model
        .trimmed
        .par_iter()
        .map(|s| mesh_one(s, &[]))
        .collect::<Result<Vec<_>, MeshError>>()
    else {
        return Vec::new();
    };
    // The model's own closed edges, not the trimmed chains appended after them.
    let trimmed_chain = |name: &str| {
        model.trimmed.iter().any(|s| {
            name.strip_prefix(s.name.as_str())
                .is_some_and(|r| r.starts_with(".boundary["))
        })
    };
    // With the topology IR, the trimmed edges are those from its start on.
    let first_trimmed_edge = model.trimmed_start.map_or(usize::MAX, |s| s[1]);
    let edges = closed_edges(mesh, |i, name| {
        i < first_trimmed_edge && !trimmed_chain(name)
    });
    if share(model, &edges, &mut meshes, tolerance, &mesh_one).is_err() {
        return Vec::new();
    }
    model
        .trimmed
        .iter()
        .zip(&meshes)
        .map(|(s, m)| {
            let q = m.quality(s);
            TrimmedReport {
                name: s.name.clone(),
                triangles: m.triangles.len(),
                min_angle: q.min_angle,
                min_angle_histogram: q.histogram,
                max_centroid_distance: q.max_centroid_distance,
                area: q.area,
            }
        })
        .collect()
}
