//! The model IR: geometry and the topology graph of a resolved domain, in
//! global coordinates. Plain data with public fields and typed indices; it holds
//! no spans and no paths (the [`SourceMap`] side table maps entities back to the
//! XML that made them).
//!
//! Rules of the IR:
//! - every edge's curve runs from its `begin` vertex to its `end` vertex;
//! - a face's loops are closed chains of oriented edges, counter-clockwise
//!   seen from the side its normal points to (the surface gradient, negated when
//!   `reversed`); the first loop is the outer one in planar faces;
//! - a 3D subdomain lists the faces of its boundary with `outward = true` where
//!   the face normal points out of the subdomain;
//! - entities are welded: two solids that share a face share one `Face`.

mod carrier;
mod fragments;
mod incidence;
mod loops;
mod name;
mod source_map;
mod teardown;

pub use carrier::Carrier;
pub use fragments::{Fragment, Side, derive_fragments};
pub use incidence::{Incidence, IncidenceMatrices};
pub use loops::Loops;
pub use name::{EntityName, LOCAL_NAMES, LocalName};
pub use source_map::{DenseId, IdMap, Origin, SourceMap};

use crate::geom::{Aabb, Curve, Point3, SolidShape, Surface};

macro_rules! id_type {
    ($($name:ident),*) => {$(
        #[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize)]
        pub struct $name(pub u32);
        impl $name {
            pub fn index(self) -> usize { self.0 as usize }
        }
    )*};
}
id_type!(VertexId, EdgeId, FaceId, SubdomainId, SolidId);

#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum Dimension {
    Two,
    Three,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Vertex {
    pub name: EntityName,
    pub position: Point3,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Edge {
    pub name: EntityName,
    /// Its curve; read it with [`Edge::curve`].
    pub carrier: Carrier<Curve>,
    pub begin: VertexId,
    pub end: VertexId,
}

impl Edge {
    pub fn is_closed(&self) -> bool {
        self.begin == self.end
    }

    /// The edge's curve (`solids`: the model's, which primitives' edges need).
    pub fn curve<'a>(&'a self, solids: &[Solid]) -> std::borrow::Cow<'a, Curve> {
        self.carrier.curve(solids)
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct OrientedEdge {
    pub edge: EdgeId,
    /// True when the loop runs along the edge from `begin` to `end`.
    pub forward: bool,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Face {
    pub name: EntityName,
    /// Its surface; read it with [`Face::surface`].
    pub carrier: Carrier<Surface>,
    /// The face normal is −∇S when true.
    pub reversed: bool,
    pub loops: Loops,
}

impl Face {
    /// The face's surface (`solids`: the model's, which primitives' faces need).
    pub fn surface<'a>(&'a self, solids: &[Solid]) -> std::borrow::Cow<'a, Surface> {
        self.carrier.surface(solids)
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct OrientedFace {
    pub face: FaceId,
    /// True when the face normal points out of the subdomain.
    pub outward: bool,
}

#[derive(Debug, Clone, PartialEq)]
pub enum SubdomainCells {
    /// A 3D subdomain: the faces of its boundary (one or more closed shells).
    Volume { boundary: Vec<OrientedFace> },
    /// A 2D subdomain: the planar faces it consists of.
    Region { faces: Vec<FaceId> },
}

impl Default for SubdomainCells {
    fn default() -> SubdomainCells {
        SubdomainCells::Region { faces: Vec::new() }
    }
}

#[derive(Debug, Clone, PartialEq, Default)]
pub struct Subdomain {
    pub name: String,
    pub material: Option<String>,
    pub cells: SubdomainCells,
    /// The leaf solids of its boolean tree, when it was built from solids
    /// (used to classify points); empty for explicit face lists. A boxed
    /// slice (sized once) keeps a `Subdomain` no larger than the
    /// `doc::SubdomainDef` it is built in place of (`lower/booleans.rs`).
    pub solids: Box<[SolidId]>,
    /// 2D: the largest triangle area its mesh may have (`area=`).
    pub max_area: Option<f64>,
    /// 3D, given by faces: the trimmed surfaces (indices in
    /// [`Model::trimmed`]) among its boundary faces. Their trim chains are
    /// made at meshing, so their outward sides and the shell's closure are
    /// settled on the mesh (`meshing/trimmed_shell.rs`).
    pub trimmed: Vec<usize>,
}

/// A lowered primitive solid: its shape and the entities of its canonical
/// boundary representation. The lists are boxed slices, sized once, and the
/// name is the one its entities' names share: on files of many primitives a
/// `String` and four vectors per solid were a sixth of the model.
#[derive(Debug, Clone, PartialEq)]
pub struct Solid {
    /// Shared with its entities' [`EntityName`]s ("{name}.{local}").
    pub name: std::sync::Arc<Box<str>>,
    pub shape: SolidShape,
    /// Faces with `outward` relative to this solid (3D).
    pub faces: Box<[OrientedFace]>,
    /// Boundary edges with `forward` when the region lies on their left, seen
    /// from the region face's normal side (2D regions).
    pub boundary_edges: Box<[OrientedEdge]>,
    pub edges: Box<[EdgeId]>,
    pub vertices: Box<[VertexId]>,
}

/// A set of points (paper 000's `point` with several values), global coordinates.
#[derive(Debug, Clone, PartialEq)]
pub struct PointSet {
    pub name: String,
    pub points: Vec<Point3>,
}

#[derive(Debug, Clone, PartialEq, Default)]
pub struct Polyline {
    pub name: String,
    pub points: Vec<Point3>,
    /// The exact curve when the line is one (paper 003's curves): meshing
    /// samples it to the chordal tolerance instead of using `points`, which
    /// then hold a coarse sample for bounding boxes.
    pub curve: Option<Curve>,
    /// A crack: a 2D mesh is opened along it (two sides, shared tips).
    pub crack: bool,
}

/// A user-named set of faces (3D) or edges (2D) where boundary conditions go.
#[derive(Debug, Clone, PartialEq)]
pub struct Boundary {
    pub name: String,
    pub faces: Vec<FaceId>,
    pub edges: Vec<EdgeId>,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Model {
    pub dimension: Dimension,
    pub vertices: Vec<Vertex>,
    pub edges: Vec<Edge>,
    pub faces: Vec<Face>,
    pub subdomains: Vec<Subdomain>,
    pub solids: Vec<Solid>,
    pub boundaries: Vec<Boundary>,
    pub point_sets: Vec<PointSet>,
    pub polylines: Vec<Polyline>,
    /// Parameter values in force, in definition order.
    pub parameters: Vec<(String, f64)>,
    /// The absolute geometric tolerance used by the checks (1e-6 of the
    /// bounding-box diagonal, at least 1e-12).
    pub tolerance: f64,
    /// Paper 002's trimmed parametric surfaces, each meshed as a face of its own.
    pub trimmed: Vec<crate::trimmed::TrimmedSurface>,
    /// The counts of vertices, edges and faces before the trimmed surfaces'
    /// own entities (`lower/trimmed_topology.rs` appends them last: chain
    /// ends, chains, one face per surface in `trimmed` order), if any.
    pub trimmed_start: Option<[usize; 3]>,
}

impl Model {
    pub fn empty(dimension: Dimension) -> Model {
        Model {
            dimension,
            vertices: Vec::new(),
            edges: Vec::new(),
            faces: Vec::new(),
            subdomains: Vec::new(),
            solids: Vec::new(),
            boundaries: Vec::new(),
            point_sets: Vec::new(),
            polylines: Vec::new(),
            parameters: Vec::new(),
            tolerance: 1e-12,
            trimmed: Vec::new(),
            trimmed_start: None,
        }
    }

    /// The face of trimmed surface `k`, when the topology was built.
    pub fn trimmed_face(&self, k: usize) -> Option<FaceId> {
        self.trimmed_start
            .map(|[_, _, f]| FaceId((f + k) as u32))
            .filter(|f| f.index() < self.faces.len())
    }

    /// The model without the trimmed surfaces' own vertices, edges and faces
    /// (the surfaces stay in `trimmed`): what the chart mesher works on, the
    /// trimmed faces being meshed by `crate::trimmed` and appended after.
    pub fn without_trimmed_entities(&self) -> Model {
        let Some([v, e, f]) = self.trimmed_start else {
            return self.clone();
        };
        let mut out = self.clone();
        out.vertices.truncate(v);
        out.edges.truncate(e);
        out.faces.truncate(f);
        for s in &mut out.subdomains {
            if let SubdomainCells::Volume { boundary } = &mut s.cells {
                boundary.retain(|of| of.face.index() < f);
            }
        }
        for b in &mut out.boundaries {
            b.faces.retain(|id| id.index() < f);
            b.edges.retain(|id| id.index() < e);
        }
        out.trimmed_start = None;
        out
    }

    pub fn vertex(&self, id: VertexId) -> &Vertex {
        &self.vertices[id.index()]
    }

    pub fn edge(&self, id: EdgeId) -> &Edge {
        &self.edges[id.index()]
    }

    pub fn face(&self, id: FaceId) -> &Face {
        &self.faces[id.index()]
    }

    /// The surface of face `id`.
    pub fn face_surface(&self, id: FaceId) -> std::borrow::Cow<'_, Surface> {
        self.faces[id.index()].surface(&self.solids)
    }

    /// The curve of edge `id`.
    pub fn edge_curve(&self, id: EdgeId) -> std::borrow::Cow<'_, Curve> {
        self.edges[id.index()].curve(&self.solids)
    }

    /// The curve of edge `id` for changing (from then on the edge's own).
    pub fn edge_curve_mut(&mut self, id: EdgeId) -> &mut Curve {
        self.edges[id.index()].carrier.curve_mut(&self.solids)
    }

    pub fn subdomain(&self, id: SubdomainId) -> &Subdomain {
        &self.subdomains[id.index()]
    }

    /// The bounding box of every vertex, point, polyline, solid and patch face.
    pub fn bbox(&self) -> Aabb {
        let mut bbox = Aabb::empty();
        for v in &self.vertices {
            bbox.include(&v.position);
        }
        for p in self.point_sets.iter().flat_map(|s| &s.points) {
            bbox.include(p);
        }
        for p in self.polylines.iter().flat_map(|s| &s.points) {
            bbox.include(p);
        }
        for solid in &self.solids {
            bbox = bbox.union(&solid.shape.bbox());
        }
        // A patch face bulges beyond its vertices: include its nine points.
        for face in &self.faces {
            // Patches are never a primitive's: their carriers are their own.
            if let Some(crate::geom::Surface::Patch9(patch)) = face.carrier.owned() {
                patch.rows.iter().flatten().for_each(|p| bbox.include(p));
            }
        }
        for s in &self.trimmed {
            s.samples(8).iter().for_each(|p| bbox.include(p));
        }
        bbox
    }
}
