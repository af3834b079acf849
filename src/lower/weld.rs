//! Welding: entities of different primitives that coincide within the
//! tolerance become one entity, so solids that share a face share one `Face`
//! and the meshes built on it conform.
//!
//! Candidates are kept in hash maps (foldhash, fixed seed) whose values are
//! chains through per-entity `next` links, so a lookup allocates nothing and
//! candidates are visited in creation order.

use super::booleans::cell_hash;
use crate::geom::{Curve, Point3};
use crate::ir::{
    Carrier, Edge, EdgeId, EntityName, Face, FaceId, Model, OrientedEdge, Vertex, VertexId,
};
use std::collections::HashMap;
use std::hash::{BuildHasher, Hash};

type FastMap<K, V> = HashMap<K, V, foldhash::fast::FixedState>;

/// No entity: the end of a chain.
const NONE: u32 = u32::MAX;

/// Canonical interior points of faces, indexed by face id. Which faces have
/// one is a flag vector beside the points: an `Option<Point3>` per face
/// took a third more (they live through lowering's memory peak).
#[derive(Debug, Default, Clone)]
pub struct FaceSamples {
    points: Vec<Point3>,
    present: Vec<bool>,
}

impl FaceSamples {
    fn with_capacity(faces: usize) -> FaceSamples {
        FaceSamples {
            points: Vec::with_capacity(faces),
            present: Vec::with_capacity(faces),
        }
    }

    pub fn get(&self, face: &FaceId) -> Option<&Point3> {
        let k = face.index();
        (self.present.get(k) == Some(&true)).then(|| &self.points[k])
    }

    /// The points of faces `first..first + n`, all present, for their
    /// lowering to write (in parallel).
    pub fn run(&mut self, first: usize, n: usize) -> &mut [Point3] {
        self.points.resize(first, Point3::origin());
        self.present.resize(first, false);
        self.points.resize(first + n, Point3::origin());
        self.present.resize(first + n, true);
        &mut self.points[first..]
    }

    pub fn insert(&mut self, face: FaceId, point: Point3) {
        let k = face.index();
        if self.points.len() <= k {
            self.points.resize(k + 1, Point3::origin());
            self.present.resize(k + 1, false);
        }
        self.points[k] = point;
        self.present[k] = true;
    }
}

/// Chains of entity ids sharing a key: the map holds (first, last) of each
/// chain, `next` links an id to the following one.
pub(super) struct Chains<K> {
    heads: FastMap<K, (u32, u32)>,
    next: Vec<u32>,
}

impl<K> Default for Chains<K> {
    fn default() -> Self {
        Chains {
            heads: FastMap::default(),
            next: Vec::new(),
        }
    }
}

impl<K: Hash + Eq + Copy> Chains<K> {
    fn with_capacity(capacity: usize) -> Self {
        Chains {
            heads: FastMap::with_capacity_and_hasher(capacity, Default::default()),
            next: Vec::with_capacity(capacity),
        }
    }

    pub(super) fn clear(&mut self) {
        self.heads.clear();
        self.next.clear();
    }

    pub(super) fn push(&mut self, key: K, id: u32) {
        let at = id as usize;
        if self.next.len() <= at {
            self.next.resize(at + 1, NONE);
        }
        match self.heads.get_mut(&key) {
            Some((_, last)) => {
                self.next[*last as usize] = id;
                *last = id;
            }
            None => {
                self.heads.insert(key, (id, id));
            }
        }
    }

    /// The ids under `key`, in the order they were pushed.
    pub(super) fn iter(&self, key: &K) -> impl Iterator<Item = u32> + '_ {
        let mut at = self.heads.get(key).map_or(NONE, |&(first, _)| first);
        std::iter::from_fn(move || {
            if at == NONE {
                return None;
            }
            let id = at;
            at = self.next.get(id as usize).copied().unwrap_or(NONE);
            Some(id)
        })
    }
}

/// The candidate tables of one welding scope.
#[derive(Default)]
struct Tables {
    /// Vertices by a hash of their grid cell (16-byte entries instead of 32:
    /// this table is the largest at the memory peak). Vertices of colliding
    /// cells only add candidates, which the distance test discards.
    vertex_grid: Chains<u64>,
    edges_by_ends: Chains<(VertexId, VertexId)>,
    /// Faces by a hash of their sorted edge list (compared exactly on a hit).
    faces_by_edges: Chains<u64>,
}

impl Tables {
    fn with_capacity(expected: &super::Expected) -> Tables {
        Tables {
            vertex_grid: Chains::with_capacity(expected.vertices),
            edges_by_ends: Chains::with_capacity(expected.edges),
            faces_by_edges: Chains::with_capacity(expected.faces),
        }
    }
}

/// Welds the entities of solids that may weld with another solid's. An
/// isolated solid (no other solid's entities within the tolerance) is welded
/// on its own by `isolated::LocalWeld`, with the same rules: its entities
/// can only match each other, so the tables here hold only the solids that
/// can weld across (on large files of separate primitives, none).
pub struct Welder {
    tol: f64,
    cell: f64,
    shared: Tables,
    /// Canonical interior point of every face (welded faces: the first's).
    pub face_samples: FaceSamples,
    scratch: Vec<EdgeId>,
}

impl Welder {
    pub fn new(tol: f64) -> Welder {
        Welder {
            tol,
            cell: (tol * 4.0).max(f64::MIN_POSITIVE),
            shared: Tables::default(),
            face_samples: FaceSamples::default(),
            scratch: Vec::new(),
        }
    }

    /// A welder whose tables are sized for `shared` entities (those of
    /// solids that are not isolated), with `faces` faces expected in all.
    pub(crate) fn with_capacity(tol: f64, shared: &super::Expected, faces: usize) -> Welder {
        Welder {
            shared: Tables::with_capacity(shared),
            face_samples: FaceSamples::with_capacity(faces),
            ..Welder::new(tol)
        }
    }

    /// The welding tolerance and grid cell.
    pub(super) fn grid(&self) -> Grid {
        Grid {
            tol: self.tol,
            cell: self.cell,
        }
    }

    /// The existing vertex within the tolerance of `position`, or a new one
    /// named by `name()`.
    pub fn vertex(
        &mut self,
        model: &mut Model,
        name: impl FnOnce() -> EntityName,
        position: Point3,
    ) -> (VertexId, bool) {
        let grid = self.grid();
        let found = grid.probe_cells(&position).find_map(|cell| {
            (self.shared.vertex_grid.iter(&cell))
                .find(|&id| (model.vertices[id as usize].position - position).norm() <= self.tol)
        });
        if let Some(id) = found {
            return (VertexId(id), false);
        }
        let id = VertexId(model.vertices.len() as u32);
        model.vertices.push(Vertex {
            name: name(),
            position,
        });
        self.shared.vertex_grid.push(grid.cell_of(&position), id.0);
        (id, true)
    }

    /// The existing edge with the same ends and the same curve, or a new one
    /// named by `name()`. Returns the id, whether the existing edge runs the
    /// other way, and whether the edge is new.
    pub fn edge(
        &mut self,
        model: &mut Model,
        name: impl FnOnce() -> EntityName,
        curve: &Curve,
        carrier: impl FnOnce() -> Carrier<Curve>,
        begin: VertexId,
        end: VertexId,
    ) -> (EdgeId, bool, bool) {
        let key = if begin <= end {
            (begin, end)
        } else {
            (end, begin)
        };
        let mut probes = None;
        for id in self.shared.edges_by_ends.iter(&key) {
            let probes = *probes.get_or_insert_with(|| probe_points(curve));
            let existing = &model.edges[id as usize];
            let theirs = probe_points(&existing.curve(&model.solids));
            let ends = (existing.begin, begin, end);
            if let Some(flipped) = same_edge(&probes, &theirs, ends, self.tol) {
                return (EdgeId(id), flipped, false);
            }
        }
        let id = EdgeId(model.edges.len() as u32);
        model.edges.push(Edge {
            name: name(),
            carrier: carrier(),
            begin,
            end,
        });
        self.shared.edges_by_ends.push(key, id.0);
        (id, false, true)
    }

    /// The existing face with the same edges and the same interior point, or a new one.
    pub fn face(&mut self, model: &mut Model, face: Face, sample: Point3) -> (FaceId, bool) {
        sorted_edges(&face, &mut self.scratch);

        let key = foldhash::fast::FixedState::default().hash_one(&self.scratch);
        let mut theirs = Vec::new();
        for id in self.shared.faces_by_edges.iter(&key) {
            sorted_edges(&model.faces[id as usize], &mut theirs);
            if theirs != self.scratch {
                continue;
            }
            if let Some(p) = self.face_samples.get(&FaceId(id))
                && (p - sample).norm() <= self.tol
            {
                return (FaceId(id), false);
            }
        }
        let id = FaceId(model.faces.len() as u32);
        model.faces.push(face);
        self.shared.faces_by_edges.push(key, id.0);
        self.face_samples.insert(id, sample);
        (id, true)
    }
}

/// The edges of a face's loops, sorted (the welding key).
fn sorted_edges(face: &Face, out: &mut Vec<EdgeId>) {
    out.clear();
    out.extend(face.loops.edges().iter().map(|e: &OrientedEdge| e.edge));
    out.sort_unstable();
}

/// Points at s = 1/4, 1/2, 3/4: two curves with the same ends are the same
/// curve when these agree (in order, or reversed for opposite directions).
pub(super) fn probe_points(curve: &Curve) -> [Point3; 3] {
    [curve.point(0.25), curve.point(0.5), curve.point(0.75)]
}

/// Whether a new edge from `begin` to `end` with probe points `probes` is an
/// existing edge (starting at `existing_begin`, probe points `theirs`), and
/// if so whether that edge runs the other way.
pub(super) fn same_edge<V: PartialEq>(
    probes: &[Point3; 3],
    theirs: &[Point3; 3],
    (existing_begin, begin, end): (V, V, V),
    tol: f64,
) -> Option<bool> {
    let same = probes
        .iter()
        .zip(theirs)
        .all(|(a, b)| (a - b).norm() <= tol);
    let mut reversed_probes = *probes;
    reversed_probes.reverse();
    let opposite = reversed_probes
        .iter()
        .zip(theirs)
        .all(|(a, b)| (a - b).norm() <= tol);
    if same && (existing_begin == begin || begin == end) {
        return Some(false);
    }
    if opposite && (existing_begin == end || begin == end) {
        return Some(true);
    }
    None
}

/// The vertex grid: cells of four tolerances, keyed by a hash of their
/// integer coordinates.
#[derive(Debug, Clone, Copy)]
pub(super) struct Grid {
    pub tol: f64,
    cell: f64,
}

impl Grid {
    fn key(&self, p: &Point3) -> [i64; 3] {
        [p.x, p.y, p.z].map(|c| super::floor_index::floor_index(c / self.cell))
    }

    /// The hashed cell of `p`.
    pub fn cell_of(&self, p: &Point3) -> u64 {
        cell_hash(self.key(p))
    }

    /// The hashed cells that can hold a vertex within the tolerance of
    /// `position`: only those the tolerance ball reaches, visited in the same
    /// order as the full 3×3×3 neighbourhood, so the first match is the same.
    pub fn probe_cells(&self, position: &Point3) -> impl Iterator<Item = u64> {
        let key = self.key(position);
        let lo = self.key(&(position - crate::geom::Vec3::repeat(self.tol)));
        let hi = self.key(&(position + crate::geom::Vec3::repeat(self.tol)));
        let range = move |k: usize| {
            lo[k].max(key[k].saturating_sub(1))..=hi[k].min(key[k].saturating_add(1))
        };
        range(0).flat_map(move |x| {
            range(1).flat_map(move |y| range(2).map(move |z| cell_hash([x, y, z])))
        })
    }
}
