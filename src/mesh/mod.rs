//! The output mesh IR: the model discretised — nodes, edge polylines, face
//! triangulations, and the groups every writer must carry (faces, boundary
//! fragments Γ_{k,k'} with their subdomain pairs, subdomains). Writers read it
//! and never modify it; readers of other formats produce it.
//!
//! Rules: every model vertex is one node; an edge's polyline starts at its
//! begin vertex's node and ends at its end vertex's node; a face's triangles
//! use the nodes of its bounding edges' polylines on its boundary (so faces
//! sharing an edge share nodes: the mesh conforms) and are oriented
//! counter-clockwise about the face normal; a subdomain lists its boundary
//! faces with `outward` as in the model.

pub mod locate;
pub mod volume;

pub use volume::{CellKind, MeshVolume};

/// A named point of the model (a topology vertex).
#[derive(Debug, Clone, PartialEq)]
pub struct MeshVertex {
    pub name: String,
    pub node: u32,
}

/// A discretised edge: its nodes from begin to end (closed edges repeat the first node at the end).
#[derive(Debug, Clone, PartialEq)]
pub struct MeshEdge {
    pub name: String,
    pub nodes: Vec<u32>,
}

/// A triangulated face.
#[derive(Debug, Clone, PartialEq)]
pub struct MeshFace {
    pub name: String,
    pub triangles: Vec<[u32; 3]>,
    /// The edges bounding the face, with their direction in its loops.
    pub boundary: Vec<(u32, bool)>,
}

#[derive(Debug, Clone, PartialEq)]
pub struct MeshSubdomain {
    pub name: String,
    pub material: Option<String>,
    /// 3D: boundary faces, `true` when the face normal points out of the subdomain.
    /// 2D: the region faces, all `true`.
    pub faces: Vec<(u32, bool)>,
}

/// A boundary fragment: faces (3D) or edges (2D) between `subdomain` and `other`
/// (`None` = the exterior).
#[derive(Debug, Clone, PartialEq)]
pub struct MeshFragment {
    pub name: String,
    pub subdomain: u32,
    pub other: Option<u32>,
    pub faces: Vec<u32>,
    pub edges: Vec<u32>,
}

/// Points and poly_lines of the model that are not topology: point and line elements.
#[derive(Debug, Clone, PartialEq)]
pub struct MeshPolyline {
    pub name: String,
    pub nodes: Vec<u32>,
}

#[derive(Debug, Clone, PartialEq, Default)]
pub struct Mesh {
    /// 2 or 3.
    pub dimension: u8,
    pub nodes: Vec<[f64; 3]>,
    pub vertices: Vec<MeshVertex>,
    pub edges: Vec<MeshEdge>,
    pub faces: Vec<MeshFace>,
    pub subdomains: Vec<MeshSubdomain>,
    pub fragments: Vec<MeshFragment>,
    pub point_sets: Vec<MeshPolyline>,
    pub polylines: Vec<MeshPolyline>,
    /// Mid-edge nodes of second-order meshes (`None`: linear elements).
    pub quadratic: Option<QuadraticNodes>,
    /// Volume cells read from a solver format (geomc's own meshes have none).
    pub volumes: Vec<MeshVolume>,
}

/// The extra nodes of 6-node triangles and 3-node lines: one per element
/// edge, shared by the elements meeting there; on a model edge it lies on
/// the curve (at the middle parameter), elsewhere at the chord's middle.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct QuadraticNodes {
    /// Per mesh edge, per segment (nodes[i] to nodes[i + 1]): its mid node.
    pub edges: Vec<Vec<u32>>,
    /// Per mesh face, per triangle: the mid nodes of its sides (0–1, 1–2,
    /// 2–0), the node order of Gmsh's 6-node triangle and VTK's
    /// quadratic triangle.
    pub faces: Vec<Vec<[u32; 3]>>,
    /// Per poly_line, per segment: its mid node.
    pub polylines: Vec<Vec<u32>>,
}
