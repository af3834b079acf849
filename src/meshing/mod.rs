//! The surface mesher: model IR → [`Mesh`]. Edges are discretised once and
//! shared ([`edges`]), each face is triangulated against them in a chart of
//! its surface ([`chart`], [`face`]), and the groups (subdomains, fragments,
//! points, poly_lines) are copied over. [`check`] verifies and measures the
//! result.
//!
//! # Guarantees
//! - Every model vertex is one node (node i is vertex i); an edge's nodes are
//!   shared by every face that uses it, so the mesh conforms.
//! - Chordal deviation ≤ tolerance on edges (≤ half of it) and faces;
//!   planar faces have angles ≥ `min_angle_degrees` except where their own
//!   loops meet at smaller angles (or the last round had to forbid boundary
//!   splits); in a face with such an angle, refinement work is bounded
//!   (`face::vertex_budget`) and triangles below tolerance² are left.
//! - Deterministic: the same model and options give the same mesh.
//!
//! # Limitations
//! - Faces without loops (unbounded surfaces) get no triangles; one that
//!   bounds a subdomain is an error.
//! - Spade's refinement can panic on loss of precision (its own `expect`):
//!   every edge and face is meshed under `catch_unwind`, so such a failure
//!   becomes [`MeshError::Internal`] naming the entity instead of a crash.
//! - See the module docs of [`chart`] and [`face`] for per-surface limits.

mod boundary_chain;
mod chart;
mod check;
mod constraints;
mod crack;
mod diagnostic;
mod edges;
pub mod exact;
mod face;
mod guard;
mod polyline_split;
mod quadratic;
mod refine;
mod report;
mod schedule;
mod size;
mod trimmed;
mod trimmed_edges;
mod trimmed_shell;
pub use trimmed::TrimmedReport;

pub use check::{Quality, SubdomainMeasure, quality, sanity_check};
pub use guard::panics_are_caught;
pub use report::{MeshReport, SubdomainReport};
pub use size::SizeField;

use crate::ir::{self, Dimension, Model, Side, SubdomainCells};
use crate::mesh::{
    Mesh, MeshEdge, MeshFace, MeshFragment, MeshPolyline, MeshSubdomain, MeshVertex,
};
use edges::EdgeNodes;
use face::{FaceMesh, FacePoint, Outcome, Settings};
use std::collections::{BTreeMap, BTreeSet};

/// Rounds of "mesh faces, add the boundary points they asked for" before
/// boundary splitting is forbidden.
const MAX_ROUNDS: usize = 8;

/// The chordal tolerance: the largest distance allowed between the model's
/// curves and surfaces and their chords and triangles.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Tolerance {
    Absolute(f64),
    /// A fraction of the model's bounding-box diagonal.
    Relative(f64),
}

impl Default for Tolerance {
    fn default() -> Tolerance {
        Tolerance::Relative(1e-3)
    }
}

#[derive(Debug, Clone, PartialEq)]
pub struct MeshOptions {
    pub tolerance: Tolerance,
    /// Longest edge allowed anywhere; `None` = no limit.
    pub max_edge: Option<f64>,
    /// The smallest triangle angle refinement aims for (planar faces exactly,
    /// curved faces in their chart).
    pub min_angle_degrees: f64,
    /// 2D: the largest triangle area anywhere (a subdomain's `area=` may
    /// lower it there).
    pub max_area: Option<f64>,
    /// A size field h(x, y, z[, d]): no triangle edge longer than h.
    pub size_field: Option<SizeField>,
    /// 1: linear elements; 2: quadratic (mid-edge nodes, on the curve for
    /// boundary edges).
    pub order: u8,
}

impl Default for MeshOptions {
    fn default() -> MeshOptions {
        MeshOptions {
            tolerance: Tolerance::default(),
            max_edge: None,
            min_angle_degrees: 25.0,
            max_area: None,
            size_field: None,
            order: 1,
        }
    }
}

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MeshError {
    #[error("invalid mesh options: {0}")]
    Options(String),
    #[error("cannot discretise edge `{edge}`: {reason}")]
    Edge { edge: String, reason: String },
    #[error("cannot mesh face `{face}`: {reason}")]
    Face { face: String, reason: String },
    /// A panic inside the mesher (a bug), caught and attributed to the edge
    /// or face being meshed.
    #[error("internal meshing failure on {entity}: {message}")]
    Internal { entity: String, message: String },
}

impl Tolerance {
    /// The tolerance as a length for `model`.
    pub fn absolute(self, model: &Model) -> f64 {
        match self {
            Tolerance::Absolute(t) => t,
            Tolerance::Relative(r) => r * model.bbox().diagonal(),
        }
    }
}

/// Meshes every edge and face of `model` and copies its groups.
pub fn mesh_model(model: &Model, options: &MeshOptions) -> Result<Mesh, MeshError> {
    let tolerance = options.tolerance.absolute(model);
    if !(tolerance.is_finite() && tolerance > 0.0) {
        return Err(MeshError::Options(format!(
            "the tolerance must be positive and finite (got {tolerance})"
        )));
    }
    // Trimmed surfaces' faces are meshed by `trimmed::append`, not by charts.
    let full = model;
    let stripped;
    let model = match model.trimmed_start {
        Some(_) => {
            stripped = model.without_trimmed_entities();
            &stripped
        }
        None => model,
    };
    let max_edge = options.max_edge.unwrap_or(f64::INFINITY);
    if max_edge.is_nan() || max_edge <= 0.0 {
        return Err(MeshError::Options(format!(
            "max_edge must be positive (got {max_edge})"
        )));
    }
    // Spade's refinement may not terminate above about 30°.
    let min_angle = options.min_angle_degrees;
    // Zero is refused as the CLI refuses it: with no angle limit at all,
    // spade's refinement of a thin triangle never ended (a fuzz finding).
    if !(min_angle > 0.0 && min_angle <= 33.0) {
        return Err(MeshError::Options(format!(
            "min_angle_degrees must lie in (0, 33] (got {min_angle})"
        )));
    }

    let max_area = options.max_area.unwrap_or(f64::INFINITY);
    if max_area.is_nan() || max_area <= 0.0 {
        return Err(MeshError::Options("max_area must be positive".into()));
    }
    if !(1..=2).contains(&options.order) {
        return Err(MeshError::Options(format!(
            "the element order must be 1 or 2 (got {})",
            options.order
        )));
    }

    // Half the tolerance on edges leaves room for the triangles beside them.
    // Under an area limit, edges start at the side of an equilateral triangle
    // of that area, so refinement rarely has to send splits back (each round
    // re-meshes the faces).
    let face_areas = face_area_limits(model, max_area);
    let mut edge_area = vec![f64::INFINITY; model.edges.len()];
    for (face, &area) in model.faces.iter().zip(&face_areas) {
        for oe in face.loops.iter().flatten() {
            if let Some(slot) = edge_area.get_mut(oe.edge.index()) {
                *slot = slot.min(area);
            }
        }
    }
    let mut edge_nodes = model
        .edges
        .iter()
        .zip(&edge_area)
        .map(|(e, &area)| {
            let side = (4.0 * area / 3f64.sqrt()).sqrt();
            guard::guarded(
                || format!("edge `{}`", e.name),
                || edges::discretise(model, e, 0.5 * tolerance, max_edge.min(side)),
            )
        })
        .collect::<Result<Vec<EdgeNodes>, MeshError>>()?;
    let sizing = size::Sizing::new(model, options.size_field.as_ref(), max_edge, &edge_nodes)?;
    for (nodes, edge) in edge_nodes.iter_mut().zip(&model.edges) {
        nodes.refine_to_size(&edge.curve(&model.solids), &sizing);
    }
    let lines = model
        .polylines
        .iter()
        .map(|l| {
            guard::guarded(
                || format!("poly_line `{}`", l.name),
                || edges::polyline_points(l, tolerance, max_edge),
            )
        })
        .collect::<Result<Vec<_>, MeshError>>()?;
    let constraints = constraints::assign(model, &mut edge_nodes, &lines)?;
    let settings = Settings {
        tolerance,
        sizing: &sizing,
        min_angle,
        keep_boundary: false,
        max_area,
    };
    let face_meshes = mesh_faces(model, &mut edge_nodes, settings, &face_areas, &constraints)?;
    guard::guarded(
        || "the assembly of the mesh".to_string(),
        || {
            let mut mesh = assemble(model, &edge_nodes, face_meshes, &lines);
            // The face meshes are gone: the writers can have their pages.
            // A small mesh freed too little to pay for a collection (a
            // forced one was 3% of meshing a 10,000-sided polygon).
            let triangles: usize = mesh.faces.iter().map(|f| f.triangles.len()).sum();
            if triangles >= LARGE_FACE_TRIANGLES {
                crate::allocator::release_freed_memory();
            }
            refuse_collapsed(&mesh, tolerance)?;
            let first_trimmed = mesh.faces.len();
            trimmed::append(full, &mut mesh, tolerance, min_angle, max_edge)?;
            trimmed_shell::join(model, full, &mut mesh, first_trimmed)?;
            let origins = crack::open(model, &mut mesh);
            if options.order == 2 {
                quadratic::elevate(model, &edge_nodes, &origins, &mut mesh);
            }
            Ok(mesh)
        },
    )
}

/// A face far thinner than the tolerance (a 0.002° sliver) can leave
/// triangles whose corners are collinear in the assembled nodes (boundary
/// nodes are recomputed on their curves): refused, by `sanity_check`'s
/// measure, rather than written for a solver to divide by their zero area.
fn refuse_collapsed(mesh: &Mesh, tolerance: f64) -> Result<(), MeshError> {
    for face in &mesh.faces {
        for t in &face.triangles {
            let [a, b, c] = t.map(|i| {
                nalgebra::Vector3::from(mesh.nodes.get(i as usize).copied().unwrap_or_default())
            });
            if let Some(width) = check::no_area_width(&a, &b, &c) {
                return Err(MeshError::Face {
                    face: face.name.clone(),
                    reason: format!(
                        "it is too thin to mesh: a triangle across it collapses to no area (width {width:e}, under the tolerance {tolerance:e}); widen it or remove it"
                    ),
                });
            }
        }
    }
    Ok(())
}

/// Each face's area limit: the smallest of `max_area` and the `area=` of
/// the 2D subdomains it belongs to.
fn face_area_limits(model: &Model, max_area: f64) -> Vec<f64> {
    let mut limits = vec![max_area; model.faces.len()];
    for sub in &model.subdomains {
        if let (SubdomainCells::Region { faces }, Some(area)) = (&sub.cells, sub.max_area) {
            for f in faces {
                if let Some(limit) = limits.get_mut(f.index()) {
                    *limit = limit.min(area);
                }
            }
        }
    }
    limits
}

/// Meshes the faces in rounds until no face asks for new boundary points.
fn mesh_faces(
    model: &Model,
    edge_nodes: &mut [EdgeNodes],
    base: Settings,
    face_areas: &[f64],
    constraints: &constraints::Constraints,
) -> Result<Vec<Option<FaceMesh>>, MeshError> {
    // The faces using each edge, found when a split first needs them (a
    // map of lists built up front was 2% of meshing a 10,000-sided
    // polygon, which never splits an edge).
    let mut faces_of_edge: Option<BTreeMap<usize, Vec<usize>>> = None;
    let faces_using = |faces_of_edge: &mut Option<BTreeMap<usize, Vec<usize>>>, edge: usize| {
        let map = faces_of_edge.get_or_insert_with(|| {
            let mut map: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
            for (f, face) in model.faces.iter().enumerate() {
                for oe in face.loops.iter().flatten() {
                    map.entry(oe.edge.index()).or_default().push(f);
                }
            }
            map
        });
        map.get(&edge).cloned().unwrap_or_default()
    };
    // A face without loops (an unbounded surface) gets no triangles, which
    // would leave a hole in any subdomain it bounds.
    for sub in &model.subdomains {
        let faces: Vec<ir::FaceId> = match &sub.cells {
            SubdomainCells::Volume { boundary } => boundary.iter().map(|of| of.face).collect(),
            SubdomainCells::Region { faces } => faces.clone(),
        };
        for f in faces {
            let face = model.faces.get(f.index()).ok_or_else(|| MeshError::Face {
                face: format!("#{}", f.0),
                reason: format!("subdomain `{}` names a face that does not exist", sub.name),
            })?;
            if face.loops.is_empty() {
                return Err(MeshError::Face {
                    face: face.name.to_string(),
                    reason: format!("it bounds subdomain `{}` but has no loops", sub.name),
                });
            }
        }
    }
    let mut meshes: Vec<Option<FaceMesh>> = vec![None; model.faces.len()];
    let mut todo: BTreeSet<usize> = (0..model.faces.len())
        .filter(|&f| !model.faces[f].loops.is_empty())
        .collect();
    for round in 0..=MAX_ROUNDS {
        // A face meshed again drops its last mesh first: a sphere's second
        // hemisphere, re-meshed for the equator nodes its twin added, held
        // its old mesh beside the new triangulation (a fifth of the peak).
        for &f in &todo {
            meshes[f] = None;
        }
        let mut splits: BTreeMap<usize, Vec<f64>> = BTreeMap::new();
        // Faces mesh independently against the shared edge nodes: in
        // parallel, with results taken in face order (deterministic, and the
        // first error in face order wins as it would sequentially).
        let edges_now: &[EdgeNodes] = edge_nodes;
        let weighted: Vec<(usize, u64)> = todo
            .iter()
            .map(|&f| (f, face_weight(model, f, edges_now)))
            .collect();
        let outcomes: Vec<(usize, Result<Outcome, MeshError>)> =
            schedule::run_bounded(&weighted, memory_budget(&weighted), |f| {
                let face = &model.faces[f];
                let settings = Settings {
                    keep_boundary: round == MAX_ROUNDS,
                    max_area: face_areas.get(f).copied().unwrap_or(base.max_area),
                    ..base
                };
                let face_constraints = constraints.get(&f).map_or(&[][..], |c| c.as_slice());
                let outcome = guard::guarded(
                    || format!("face `{}`", face.name),
                    || face::mesh_face(model, face, edges_now, &settings, face_constraints),
                );
                // A large face's triangulation is gone: its pages serve the
                // next face. Small faces free too little to pay for a
                // collection (one per face cost the seven balls 40% more CPU).
                if let Ok(Outcome::Meshed(m)) = &outcome
                    && m.triangles.len() >= LARGE_FACE_TRIANGLES
                {
                    crate::allocator::release_freed_memory();
                }
                outcome
            });
        // Faces whose mesh already has an edge's new nodes (kept splits on
        // straight edges): they need no new round for that edge.
        let mut has_them: BTreeMap<usize, BTreeSet<usize>> = BTreeMap::new();
        let mut split_by: BTreeMap<usize, BTreeSet<usize>> = BTreeMap::new();
        let mut resend = Vec::new();
        for (f, outcome) in outcomes {
            match outcome? {
                Outcome::Meshed(mesh) => {
                    for &(edge, s) in &mesh.added {
                        splits.entry(edge).or_default().push(s);
                        has_them.entry(edge).or_default().insert(f);
                    }
                    meshes[f] = Some(mesh);
                }
                Outcome::Split(points) => {
                    // Meshed again in any case: it has no mesh now.
                    resend.push(f);
                    for (edge, s) in points {
                        splits.entry(edge).or_default().push(s);
                        split_by.entry(edge).or_default().insert(f);
                    }
                }
            }
        }
        todo.clear();
        todo.extend(resend);
        for (edge, params) in splits {
            let (Some(nodes), Some(model_edge)) = (edge_nodes.get_mut(edge), model.edges.get(edge))
            else {
                continue;
            };
            let mut changed = false;
            let curve = model_edge.curve(&model.solids);
            for s in params {
                changed |= nodes.insert(&curve, s);
            }
            if changed {
                // One face split the edge and kept its mesh: only the
                // others need the new nodes.
                let keeper = match (has_them.get(&edge), split_by.get(&edge)) {
                    (Some(faces), None) if faces.len() == 1 => faces.first().copied(),
                    _ => None,
                };
                todo.extend(
                    faces_using(&mut faces_of_edge, edge)
                        .into_iter()
                        .filter(|&g| Some(g) != keeper),
                );
            }
        }
        if todo.is_empty() {
            break;
        }
    }
    Ok(meshes)
}

/// A face's share of meshing memory, up to a constant: its interior grows
/// as the square of its boundary's node count.
/// Triangles from which a face's freed triangulation (tens of megabytes)
/// is handed back to the system before the next face is meshed.
const LARGE_FACE_TRIANGLES: usize = 1 << 16;

fn face_weight(model: &Model, f: usize, edges: &[EdgeNodes]) -> u64 {
    let boundary: u64 = model.faces[f]
        .loops
        .iter()
        .flatten()
        .map(|oe| {
            edges
                .get(oe.edge.index())
                .map_or(0, |e| e.points.len() as u64)
        })
        .sum();
    boundary.saturating_mul(boundary)
}

/// The face weight that may be meshed at once: the largest face beside half
/// its weight of others, or a quarter of all faces where there are many of
/// about the same size (so a model of equal faces still meshes in parallel).
fn memory_budget(weighted: &[(usize, u64)]) -> u64 {
    let largest = weighted.iter().map(|w| w.1).max().unwrap_or(0);
    let total: u64 = weighted.iter().map(|w| w.1).fold(0, u64::saturating_add);
    largest.saturating_add(largest / 2).max(total / 4)
}

/// Numbers the nodes (vertices, then edge interiors, then face interiors,
/// then points and poly_lines) and fills the mesh IR.
fn assemble(
    model: &Model,
    edge_nodes: &[EdgeNodes],
    face_meshes: Vec<Option<FaceMesh>>,
    lines: &[Vec<crate::geom::Point3>],
) -> Mesh {
    // The node table is sized once (doubling would briefly hold three times
    // it), and each face mesh is dropped as soon as it is copied: the
    // assembled mesh and all the face meshes are never held side by side.
    let interior: usize = face_meshes
        .iter()
        .flatten()
        .map(|m| m.positions.len() - m.on_edges.len())
        .sum();
    let on_edges: usize = edge_nodes
        .iter()
        .map(|e| e.points.len().saturating_sub(2))
        .sum();
    let loose: usize = model
        .point_sets
        .iter()
        .map(|s| s.points.len())
        .sum::<usize>()
        + lines.iter().map(Vec::len).sum::<usize>();
    let mut nodes: Vec<[f64; 3]> =
        Vec::with_capacity(model.vertices.len() + on_edges + interior + loose);
    nodes.extend(
        model
            .vertices
            .iter()
            .map(|v| [v.position.x, v.position.y, v.position.z]),
    );
    let push = |nodes: &mut Vec<[f64; 3]>, p: &crate::geom::Point3| {
        nodes.push([p.x, p.y, p.z]);
        (nodes.len() - 1) as u32
    };
    // The edges' node ids are read back from `edges` (a copy per edge was
    // 10,000 allocations on a 10,000-sided polygon).
    let mut edges: Vec<MeshEdge> = Vec::with_capacity(model.edges.len());
    for (edge, disc) in model.edges.iter().zip(edge_nodes) {
        let n = disc.points.len();
        let mut ids = Vec::with_capacity(n);
        for (j, p) in disc.points.iter().enumerate() {
            ids.push(match j {
                0 => edge.begin.0,
                j if j + 1 == n => edge.end.0,
                _ => push(&mut nodes, p),
            });
        }
        edges.push(MeshEdge {
            name: edge.name.to_string(),
            nodes: ids,
        });
    }
    let mut faces = Vec::with_capacity(model.faces.len());
    let mut constrained: BTreeMap<usize, Vec<u32>> = BTreeMap::new();
    for (face, mesh) in model.faces.iter().zip(face_meshes) {
        let mut triangles = Vec::new();
        if let Some(mesh) = mesh {
            let mut ids: Vec<Option<u32>> = vec![None; mesh.positions.len()];
            for (i, key) in &mesh.on_edges {
                let id = match key {
                    FacePoint::Vertex(v) => *v,
                    FacePoint::Edge { edge, s } => edges
                        .get(*edge)
                        .map(|e| &e.nodes)
                        .zip(edge_nodes.get(*edge))
                        .and_then(|(ids, disc)| ids.get(disc.index_of(*s)))
                        .copied()
                        .unwrap_or(0),
                };
                if let Some(slot) = ids.get_mut(*i as usize) {
                    *slot = Some(id);
                }
            }
            // Interior nodes are numbered in the order the triangles first
            // use them. The face's triangles become the mesh's in place:
            // the face meshes and the assembled triangles are never both held.
            triangles = mesh.triangles;
            for t in &mut triangles {
                for slot in t.iter_mut() {
                    let i = *slot as usize;
                    let id = match ids[i] {
                        Some(id) => id,
                        None => push(&mut nodes, &mesh.positions[i]),
                    };
                    ids[i] = Some(id);
                    *slot = id;
                }
            }
            for (index, chain) in &mesh.polylines {
                let nodes = chain.iter().filter_map(|&i| ids.get(i).copied().flatten());
                constrained.insert(*index, nodes.collect());
            }
        }
        faces.push(MeshFace {
            name: face.name.to_string(),
            triangles,
            boundary: face
                .loops
                .iter()
                .flatten()
                .map(|oe| (oe.edge.0, oe.forward))
                .collect(),
        });
    }
    let subdomains = model
        .subdomains
        .iter()
        .map(|s| MeshSubdomain {
            name: s.name.clone(),
            material: s.material.clone(),
            faces: match &s.cells {
                SubdomainCells::Volume { boundary } => {
                    boundary.iter().map(|of| (of.face.0, of.outward)).collect()
                }
                SubdomainCells::Region { faces } => faces.iter().map(|f| (f.0, true)).collect(),
            },
        })
        .collect();
    let fragments = ir::derive_fragments(model)
        .into_iter()
        .map(|f| MeshFragment {
            name: f.name,
            subdomain: f.subdomain.0,
            other: match f.other {
                Side::Exterior => None,
                Side::Subdomain(k) => Some(k.0),
            },
            faces: f.faces.iter().map(|id| id.0).collect(),
            edges: f.edges.iter().map(|id| id.0).collect(),
        })
        .collect();
    let mut point_sets = Vec::new();
    for set in &model.point_sets {
        let ids = set.points.iter().map(|p| push(&mut nodes, p)).collect();
        point_sets.push(MeshPolyline {
            name: set.name.clone(),
            nodes: ids,
        });
    }
    let mut polylines = Vec::new();
    for (index, (line, points)) in model.polylines.iter().zip(lines).enumerate() {
        let ids = match constrained.remove(&index) {
            Some(chain) => chain,
            None => points.iter().map(|p| push(&mut nodes, p)).collect(),
        };
        polylines.push(MeshPolyline {
            name: line.name.clone(),
            nodes: ids,
        });
    }
    Mesh {
        dimension: match model.dimension {
            Dimension::Two => 2,
            Dimension::Three => 3,
        },
        nodes,
        vertices: model
            .vertices
            .iter()
            .enumerate()
            .map(|(i, v)| MeshVertex {
                name: v.name.to_string(),
                node: i as u32,
            })
            .collect(),
        edges,
        faces,
        subdomains,
        fragments,
        point_sets,
        polylines,
        ..Mesh::default()
    }
}
