//! Welding: entities of different primitives that coincide within the
//! tolerance become one entity, so solids that share a face share one `Face`
//! and the meshes built on it conform.

use crate::geom::{Curve, Point3};
use crate::ir::{Edge, EdgeId, Face, FaceId, Model, OrientedEdge, Vertex, VertexId};
use std::collections::HashMap;

pub struct Welder {
    tol: f64,
    cell: f64,
    vertex_grid: HashMap<[i64; 3], Vec<VertexId>>,
    edges_by_ends: HashMap<(VertexId, VertexId), Vec<EdgeId>>,
    faces_by_edges: HashMap<Vec<EdgeId>, Vec<FaceId>>,
    /// Canonical interior point of every face (welded faces: the first's).
    pub face_samples: HashMap<FaceId, Point3>,
}

impl Welder {
    pub fn new(tol: f64) -> Welder {
        Welder {
            tol,
            cell: (tol * 4.0).max(f64::MIN_POSITIVE),
            vertex_grid: HashMap::new(),
            edges_by_ends: HashMap::new(),
            faces_by_edges: HashMap::new(),
            face_samples: HashMap::new(),
        }
    }

    fn key(&self, p: &Point3) -> [i64; 3] {
        [p.x, p.y, p.z].map(|c| (c / self.cell).floor() as i64)
    }

    /// The existing vertex within the tolerance of `position`, or a new one.
    pub fn vertex(
        &mut self,
        model: &mut Model,
        name: String,
        position: Point3,
    ) -> (VertexId, bool) {
        let key = self.key(&position);
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    let k = [key[0] + dx, key[1] + dy, key[2] + dz];
                    if let Some(ids) = self.vertex_grid.get(&k) {
                        for &id in ids {
                            if (model.vertices[id.index()].position - position).norm() <= self.tol {
                                return (id, false);
                            }
                        }
                    }
                }
            }
        }
        let id = VertexId(model.vertices.len() as u32);
        model.vertices.push(Vertex { name, position });
        self.vertex_grid.entry(key).or_default().push(id);
        (id, true)
    }

    /// The existing edge with the same ends and the same curve, or a new one.
    /// Returns the id and whether the existing edge runs the other way.
    pub fn edge(
        &mut self,
        model: &mut Model,
        name: String,
        curve: Curve,
        begin: VertexId,
        end: VertexId,
    ) -> (EdgeId, bool, bool) {
        let key = if begin <= end {
            (begin, end)
        } else {
            (end, begin)
        };
        let probes = probe_points(&curve);
        if let Some(ids) = self.edges_by_ends.get(&key) {
            for &id in ids {
                let existing = &model.edges[id.index()];
                let theirs = probe_points(&existing.curve);
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
                    return (id, false, false);
                }
                if opposite && (existing.begin == end || begin == end) {
                    return (id, true, false);
                }
            }
        }
        let id = EdgeId(model.edges.len() as u32);
        model.edges.push(Edge {
            name,
            curve,
            begin,
            end,
        });
        self.edges_by_ends.entry(key).or_default().push(id);
        (id, false, true)
    }

    /// The existing face with the same edges and the same interior point, or a new one.
    pub fn face(&mut self, model: &mut Model, face: Face, sample: Point3) -> (FaceId, bool) {
        let mut key: Vec<EdgeId> = face
            .loops
            .iter()
            .flatten()
            .map(|e: &OrientedEdge| e.edge)
            .collect();
        key.sort();
        if let Some(ids) = self.faces_by_edges.get(&key) {
            for &id in ids {
                if let Some(theirs) = self.face_samples.get(&id) {
                    if (theirs - sample).norm() <= self.tol {
                        return (id, false);
                    }
                }
            }
        }
        let id = FaceId(model.faces.len() as u32);
        model.faces.push(face);
        self.faces_by_edges.entry(key).or_default().push(id);
        self.face_samples.insert(id, sample);
        (id, true)
    }
}

/// Points at s = 1/4, 1/2, 3/4: two curves with the same ends are the same
/// curve when these agree (in order, or reversed for opposite directions).
fn probe_points(curve: &Curve) -> [Point3; 3] {
    [curve.point(0.25), curve.point(0.5), curve.point(0.75)]
}
