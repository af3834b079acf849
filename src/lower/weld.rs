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
/// chain, `next` links an id to the following one. Ids are at least `base`
/// (`next` is indexed from there, so tables restarted per solid stay small).
/// A table restarted per solid keeps its few entries in a list instead,
/// scanned in push order: the same ids in the same order, without hashing
/// into a map for every lookup of every entity of every isolated solid.
struct Chains<K> {
    heads: FastMap<K, (u32, u32)>,
    next: Vec<u32>,
    base: u32,
    /// (key, id) in push order, once the table has been restarted.
    listed: Option<Vec<(K, u32)>>,
}

impl<K> Default for Chains<K> {
    fn default() -> Self {
        Chains {
            heads: FastMap::default(),
            next: Vec::new(),
            base: 0,
            listed: None,
        }
    }
}

impl<K: Hash + Eq + Copy> Chains<K> {
    fn with_capacity(capacity: usize) -> Self {
        Chains {
            heads: FastMap::with_capacity_and_hasher(capacity, Default::default()),
            next: Vec::with_capacity(capacity),
            base: 0,
            listed: None,
        }
    }

    /// Empties the table, which from now on lists its entries; later ids
    /// are at least `base`.
    fn restart(&mut self, base: usize) {
        self.heads.clear();
        self.next.clear();
        self.base = base as u32;
        self.listed.get_or_insert_with(Vec::new).clear();
    }

    fn push(&mut self, key: K, id: u32) {
        if let Some(listed) = &mut self.listed {
            listed.push((key, id));
            return;
        }
        let at = (id - self.base) as usize;
        if self.next.len() <= at {
            self.next.resize(at + 1, NONE);
        }
        match self.heads.get_mut(&key) {
            Some((_, last)) => {
                self.next[(*last - self.base) as usize] = id;
                *last = id;
            }
            None => {
                self.heads.insert(key, (id, id));
            }
        }
    }

    /// The ids under `key`, in the order they were pushed.
    fn iter(&self, key: &K) -> impl Iterator<Item = u32> + '_ {
        let key = *key;
        let listed = (self.listed.iter().flatten())
            .filter(move |(k, _)| *k == key)
            .map(|&(_, id)| id);
        let mut at = match self.listed {
            Some(_) => NONE,
            None => self.heads.get(&key).map_or(NONE, |&(first, _)| first),
        };
        let chained = std::iter::from_fn(move || {
            if at == NONE {
                return None;
            }
            let id = at;
            at = self
                .next
                .get((id - self.base) as usize)
                .copied()
                .unwrap_or(NONE);
            Some(id)
        });
        listed.chain(chained)
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

pub struct Welder {
    tol: f64,
    cell: f64,
    /// Entities of solids that may weld with another solid's.
    shared: Tables,
    /// Entities of the current solid when it is isolated (no other solid's
    /// entities within the tolerance): restarted per solid, so the large
    /// tables hold only the solids that can weld across (on large files of
    /// separate primitives, none) and lookups stay in cache. The result is
    /// the same as with one table set: an isolated solid's entities can only
    /// match each other.
    local: Tables,
    /// Per solid, in lowering order: whether it is isolated.
    isolated: Vec<bool>,
    /// The next solid's index in `isolated`.
    solid: usize,
    /// Whether the current solid uses `local`.
    in_local: bool,
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
            local: Tables::default(),
            isolated: Vec::new(),
            solid: 0,
            in_local: false,
            face_samples: FaceSamples::default(),
            scratch: Vec::new(),
        }
    }

    /// A welder whose shared tables are sized for `shared` entities (those
    /// of solids that are not isolated), with `faces` faces expected in all.
    /// `isolated`: per solid in lowering order, whether it is isolated.
    pub(crate) fn with_capacity(
        tol: f64,
        shared: &super::Expected,
        faces: usize,
        isolated: Vec<bool>,
    ) -> Welder {
        Welder {
            shared: Tables::with_capacity(shared),
            face_samples: FaceSamples::with_capacity(faces),
            isolated,
            ..Welder::new(tol)
        }
    }

    /// Called before each solid's entities are welded, in lowering order.
    pub fn begin_solid(&mut self, model: &Model) {
        self.in_local = self.isolated.get(self.solid).copied().unwrap_or(false);
        self.solid += 1;
        if self.in_local {
            self.local.vertex_grid.restart(model.vertices.len());
            self.local.edges_by_ends.restart(model.edges.len());
            self.local.faces_by_edges.restart(model.faces.len());
        }
    }

    fn tables(&mut self) -> &mut Tables {
        if self.in_local {
            &mut self.local
        } else {
            &mut self.shared
        }
    }

    fn key(&self, p: &Point3) -> [i64; 3] {
        [p.x, p.y, p.z].map(|c| (c / self.cell).floor() as i64)
    }

    /// The existing vertex within the tolerance of `position`, or a new one
    /// named by `name()`.
    pub fn vertex(
        &mut self,
        model: &mut Model,
        name: impl FnOnce() -> EntityName,
        position: Point3,
    ) -> (VertexId, bool) {
        let key = self.key(&position);
        // Only cells that the tolerance ball around `position` reaches can
        // hold a match; they are visited in the same order as the full 3×3×3
        // neighbourhood, so the first match is the same.
        let lo = self.key(&(position - crate::geom::Vec3::repeat(self.tol)));
        let hi = self.key(&(position + crate::geom::Vec3::repeat(self.tol)));
        let range =
            |k: usize| lo[k].max(key[k].saturating_sub(1))..=hi[k].min(key[k].saturating_add(1));
        let tables = if self.in_local {
            &self.local
        } else {
            &self.shared
        };
        for x in range(0) {
            for y in range(1) {
                for z in range(2) {
                    for id in tables.vertex_grid.iter(&cell_hash([x, y, z])) {
                        if (model.vertices[id as usize].position - position).norm() <= self.tol {
                            return (VertexId(id), false);
                        }
                    }
                }
            }
        }
        let id = VertexId(model.vertices.len() as u32);
        model.vertices.push(Vertex {
            name: name(),
            position,
        });
        self.tables().vertex_grid.push(cell_hash(key), id.0);
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
        let tables = if self.in_local {
            &self.local
        } else {
            &self.shared
        };
        for id in tables.edges_by_ends.iter(&key) {
            let probes = *probes.get_or_insert_with(|| probe_points(curve));
            let existing = &model.edges[id as usize];
            let theirs = probe_points(&existing.curve(&model.solids));
            let same = probes
                .iter()
                .zip(&theirs)
                .all(|(a, b)| (a - b).norm() <= self.tol);
            let mut reversed_probes = probes;
            reversed_probes.reverse();
            let opposite = reversed_probes
                .iter()
                .zip(&theirs)
                .all(|(a, b)| (a - b).norm() <= self.tol);
            if same && (existing.begin == begin || begin == end) {
                return (EdgeId(id), false, false);
            }
            if opposite && (existing.begin == end || begin == end) {
                return (EdgeId(id), true, false);
            }
        }
        let id = EdgeId(model.edges.len() as u32);
        model.edges.push(Edge {
            name: name(),
            carrier: carrier(),
            begin,
            end,
        });
        self.tables().edges_by_ends.push(key, id.0);
        (id, false, true)
    }

    /// The existing face with the same edges and the same interior point, or a new one.
    pub fn face(&mut self, model: &mut Model, face: Face, sample: Point3) -> (FaceId, bool) {
        sorted_edges(&face, &mut self.scratch);

        let key = foldhash::fast::FixedState::default().hash_one(&self.scratch);
        let mut theirs = Vec::new();
        let tables = if self.in_local {
            &self.local
        } else {
            &self.shared
        };
        for id in tables.faces_by_edges.iter(&key) {
            sorted_edges(&model.faces[id as usize], &mut theirs);
            if theirs != self.scratch {
                continue;
            }
            if let Some(p) = self.face_samples.get(&FaceId(id)) {
                if (p - sample).norm() <= self.tol {
                    return (FaceId(id), false);
                }
            }
        }
        let id = FaceId(model.faces.len() as u32);
        model.faces.push(face);
        self.tables().faces_by_edges.push(key, id.0);
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
fn probe_points(curve: &Curve) -> [Point3; 3] {
    [curve.point(0.25), curve.point(0.5), curve.point(0.75)]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_listed_table_gives_the_ids_of_the_hashed_chains_in_push_order() {
        let entries = [(7u64, 10u32), (3, 11), (7, 12), (9, 13), (7, 14), (3, 15)];
        let mut hashed = Chains::with_capacity(8);
        let mut listed = Chains::default();
        listed.restart(10);
        for (key, id) in entries {
            hashed.push(key, id);
            listed.push(key, id);
        }
        assert!(hashed.listed.is_none() && listed.listed.is_some());
        for (key, ids) in [
            (7, vec![10, 12, 14]),
            (3, vec![11, 15]),
            (9, vec![13]),
            (5, vec![]),
        ] {
            assert_eq!(hashed.iter(&key).collect::<Vec<_>>(), ids);
            assert_eq!(listed.iter(&key).collect::<Vec<_>>(), ids);
        }
        // Restarted, it is empty again.
        listed.restart(16);
        assert_eq!(listed.iter(&7).count(), 0);
    }
}
