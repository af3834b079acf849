//! Lowering of isolated primitive solids (no other solid's entities within
//! the welding tolerance, `isolation.rs`) on the rayon workers. Such a solid
//! can weld only with itself, so its entity counts are its own: a first pass
//! welds every solid locally for its counts, prefix sums give each solid its
//! ids, and a second pass writes every solid's entities in place into the
//! model's vectors. Ids, order and every value are those of lowering the
//! solids one after another, whatever the number of threads.

use super::brep::Brep;
use super::distinct::unwelded_counts;
use super::reserved::{Part, Tail};
use super::weld::{Chains, FaceSamples, Grid, probe_points, same_edge};
use crate::geom::{Point3, SolidShape};
use crate::ir::{
    Edge, EdgeId, EntityName, Face, FaceId, Model, OrientedEdge, OrientedFace, Origin, Solid,
    SourceMap, Vertex, VertexId,
};
use crate::span::Span;
use rayon::prelude::*;
use std::borrow::Cow;
use std::sync::Arc;

/// A primitive solid to lower, in lowering order.
pub(super) struct SolidJob<'r> {
    pub name: Cow<'r, str>,
    pub shape: &'r SolidShape,
    pub span: Span,
}

/// Solids per task: enough to amortise a task, few enough to balance.
const TASK: usize = 256;

/// Lowers `jobs`, all isolated, after the model's current entities.
pub(super) fn lower_run(
    model: &mut Model,
    source_map: &mut SourceMap,
    samples: &mut FaceSamples,
    grid: Grid,
    jobs: &[SolidJob],
) {
    let counts: Vec<Counts> = jobs
        .par_iter()
        .with_min_len(TASK)
        .map_init(LocalWeld::default, |weld, job| {
            // A regular primitive needs no boundary for its counts.
            if let Some([vertices, edges, faces]) = unwelded_counts(job.shape, grid.tol) {
                return Counts {
                    vertices,
                    edges,
                    faces,
                };
            }
            weld.weld(job.shape, grid);
            weld.counts()
        })
        .collect();
    let first = Counts {
        vertices: model.vertices.len() as u32,
        edges: model.edges.len() as u32,
        faces: model.faces.len() as u32,
    };
    let first_solid = model.solids.len();
    // Each task's first ids, and how many entities it makes.
    let mut starts = Vec::with_capacity(counts.len().div_ceil(TASK));
    let mut sizes = Vec::with_capacity(starts.capacity());
    let mut at = first;
    for chunk in counts.chunks(TASK) {
        let size = chunk.iter().fold(Counts::default(), |a, c| a.plus(c));
        starts.push(at);
        sizes.push(size);
        at = at.plus(&size);
    }
    let total = at.minus(&first);
    let mut vertices = Tail::new(&mut model.vertices, total.vertices as usize);
    let mut edges = Tail::new(&mut model.edges, total.edges as usize);
    let mut faces = Tail::new(&mut model.faces, total.faces as usize);
    let mut solids = Tail::new(&mut model.solids, jobs.len());
    let mut sample_slots = samples.run(first.faces as usize, total.faces as usize);
    let sample_parts: Vec<&mut [Point3]> = sizes
        .iter()
        .map(|size| {
            let (part, rest) = std::mem::take(&mut sample_slots).split_at_mut(size.faces as usize);
            sample_slots = rest;
            part
        })
        .collect();
    let out = vertices
        .parts(sizes.iter().map(|s| s.vertices as usize))
        .into_iter()
        .zip(edges.parts(sizes.iter().map(|s| s.edges as usize)))
        .zip(faces.parts(sizes.iter().map(|s| s.faces as usize)))
        .zip(solids.parts(jobs.chunks(TASK).map(<[_]>::len)))
        .zip(sample_parts)
        .map(|((((vertices, edges), faces), solids), samples)| Out {
            vertices,
            edges,
            faces,
            solids,
            samples,
        });
    let tasks: Vec<_> = (jobs.chunks(TASK).zip(counts.chunks(TASK)).enumerate())
        .zip(starts)
        .zip(out)
        .map(|(((k, jobs), start), out)| (first_solid + k * TASK, jobs, start, out))
        .collect();
    // The source map is filled beside the writing, on a worker too: the
    // main thread only waits.
    let write = || {
        tasks.into_par_iter().for_each_init(
            LocalWeld::default,
            |weld, (solid, (jobs, counts), start, mut out)| {
                let mut at = start;
                for (k, (job, count)) in jobs.iter().zip(counts).enumerate() {
                    // Welded again only when the first pass merged something.
                    weld.unwelded(job.shape);
                    if !weld.unmerged(count) {
                        weld.weld(job.shape, grid);
                    }
                    weld.write(job, solid + k, at, &mut out);
                    at = at.plus(count);
                }
            },
        )
    };
    rayon::join(write, || {
        map_origins(source_map, jobs, &counts, first, first_solid)
    });
    vertices.commit();
    edges.commit();
    faces.commit();
    solids.commit();
}

/// The source map of a run, in order (a slot per entity, a value per solid).
fn map_origins(
    source_map: &mut SourceMap,
    jobs: &[SolidJob],
    counts: &[Counts],
    first: Counts,
    first_solid: usize,
) {
    let mut at = first;
    for (k, (job, count)) in jobs.iter().zip(counts).enumerate() {
        let origin = Origin { span: job.span };
        let map = &mut *source_map;
        map.vertices
            .insert_range(at.vertices as usize, count.vertices as usize, origin);
        map.edges
            .insert_range(at.edges as usize, count.edges as usize, origin);
        map.faces
            .insert_range(at.faces as usize, count.faces as usize, origin);
        map.solids.insert_range(first_solid + k, 1, origin);
        at = at.plus(count);
    }
}

/// Entities of one kind each, per solid or summed.
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq)]
struct Counts {
    vertices: u32,
    edges: u32,
    faces: u32,
}

impl Counts {
    fn plus(&self, o: &Counts) -> Counts {
        Counts {
            vertices: self.vertices + o.vertices,
            edges: self.edges + o.edges,
            faces: self.faces + o.faces,
        }
    }

    fn minus(&self, o: &Counts) -> Counts {
        Counts {
            vertices: self.vertices - o.vertices,
            edges: self.edges - o.edges,
            faces: self.faces - o.faces,
        }
    }
}

/// One task's parts of the model's vectors.
struct Out<'t> {
    vertices: Part<'t, Vertex>,
    edges: Part<'t, Edge>,
    faces: Part<'t, Face>,
    solids: Part<'t, Solid>,
    samples: &'t mut [Point3],
}

/// One solid welded on its own, with the welder's rules (`weld.rs`): which of
/// its boundary's entities are distinct. Reused from solid to solid.
#[derive(Default)]
struct LocalWeld {
    brep: Brep,
    /// Per distinct vertex: the brep vertex that made it.
    vertices: Vec<usize>,
    /// Per brep vertex: its distinct vertex.
    vertex_of: Vec<u32>,
    /// Per distinct edge: the brep edge that made it and its ends.
    edges: Vec<(usize, u32, u32)>,
    /// Per brep edge: its distinct edge, and whether that runs the other way.
    edge_of: Vec<(u32, bool)>,
    /// Per distinct face: the brep face that made it and the end of its
    /// sorted edges in `sorted`.
    faces: Vec<(usize, usize)>,
    sorted: Vec<u32>,
    /// Per brep face: its distinct face, and whether it faces outward.
    face_of: Vec<(u32, bool)>,
    /// The candidates of a solid with more than `SCANNED` vertices.
    index: Index,
}

/// Vertices up to which a solid's candidates are scanned, not looked up:
/// every primitive but a large polygon (a scan of a few is cheaper than
/// hashing them).
const SCANNED: usize = 32;

/// Candidates by key, each chain in creation order (local ids), as the
/// welder keeps them.
#[derive(Default)]
struct Index {
    vertices: Chains<u64>,
    edges: Chains<(u32, u32)>,
    faces: Chains<u64>,
}

impl Index {
    fn clear(&mut self) {
        self.vertices.clear();
        self.edges.clear();
        self.faces.clear();
    }
}

/// The candidates' ids in creation order: all `count` of them, or a chain's.
fn scanned_or_chained<I: Iterator<Item = u32>>(
    chained: bool,
    count: usize,
    chain: impl FnOnce() -> I,
) -> impl Iterator<Item = u32> {
    let (all, chain) = if chained {
        (None, Some(chain()))
    } else {
        (Some(0..count as u32), None)
    };
    all.into_iter().flatten().chain(chain.into_iter().flatten())
}

/// The key of a face's sorted edge list (lists are compared exactly on a hit).
fn edge_list_hash(edges: &[u32]) -> u64 {
    use std::hash::BuildHasher;
    foldhash::fast::FixedState::default().hash_one(edges)
}

impl LocalWeld {
    fn counts(&self) -> Counts {
        Counts {
            vertices: self.vertices.len() as u32,
            edges: self.edges.len() as u32,
            faces: self.faces.len() as u32,
        }
    }

    /// A brep edge's use, as a distinct edge (local ids).
    fn orient(&self, (local, forward): (usize, bool)) -> (u32, bool) {
        let (edge, flipped) = self.edge_of[local];
        (edge, forward != flipped)
    }

    /// Makes the boundary of `shape` whose weld is known to merge nothing
    /// (its counts are its boundary's): every entity is distinct.
    fn unwelded(&mut self, shape: &SolidShape) {
        self.brep.rebuild(shape);
        let brep = &self.brep;
        self.vertices.clear();
        self.vertices.extend(0..brep.vertices.len());
        self.vertex_of.clear();
        self.vertex_of.extend(0..brep.vertices.len() as u32);
        self.edges.clear();
        (self.edges).extend(
            brep.edges
                .iter()
                .enumerate()
                .map(|(k, e)| (k, e.begin as u32, e.end as u32)),
        );
        self.edge_of.clear();
        self.edge_of
            .extend((0..brep.edges.len() as u32).map(|k| (k, false)));
        self.faces.clear();
        self.faces.extend((0..brep.faces.len()).map(|k| (k, 0)));
        self.face_of.clear();
        self.face_of
            .extend((0..brep.faces.len() as u32).map(|k| (k, true)));
    }

    /// Whether the boundary's entities are `counts` in number.
    fn unmerged(&self, counts: &Counts) -> bool {
        let brep = &self.brep;
        [brep.vertices.len(), brep.edges.len(), brep.faces.len()]
            == [counts.vertices, counts.edges, counts.faces].map(|c| c as usize)
    }

    /// Welds the boundary of `shape`. The welder looks up candidates in
    /// hashed chains; here the few entities of one solid are scanned in the
    /// same order (cells in the welder's order, then creation order), so
    /// each lookup finds what the welder's would. A solid with more than
    /// `SCANNED` vertices (a polygon of thousands) looks its candidates up
    /// in chains as the welder does: scanning them all is quadratic.
    fn weld(&mut self, shape: &SolidShape, grid: Grid) {
        self.brep.rebuild(shape);
        let brep = &self.brep;
        let chained = brep.vertices.len() > SCANNED;
        let mut index = std::mem::take(&mut self.index);
        index.clear();
        self.vertices.clear();
        self.vertex_of.clear();
        for (k, v) in brep.vertices.iter().enumerate() {
            let vertices = &self.vertices;
            let near = |&src: &usize| (brep.vertices[src].position - v.position).norm() <= grid.tol;
            // The welder finds only vertices within the tolerance; when there
            // is one (a degenerate solid), the first in its order.
            let found = if chained {
                grid.probe_cells(&v.position).find_map(|cell| {
                    (index.vertices.iter(&cell)).find(|&id| near(&vertices[id as usize]))
                })
            } else {
                vertices
                    .iter()
                    .any(near)
                    .then(|| {
                        grid.probe_cells(&v.position).find_map(|cell| {
                            (0..vertices.len() as u32).find(|&id| {
                                let src = &vertices[id as usize];
                                grid.cell_of(&brep.vertices[*src].position) == cell && near(src)
                            })
                        })
                    })
                    .flatten()
            };
            let id = found.unwrap_or_else(|| {
                self.vertices.push(k);
                let id = (self.vertices.len() - 1) as u32;
                if chained {
                    index.vertices.push(grid.cell_of(&v.position), id);
                }
                id
            });
            self.vertex_of.push(id);
        }
        self.edges.clear();
        self.edge_of.clear();
        for (k, e) in brep.edges.iter().enumerate() {
            let (begin, end) = (self.vertex_of[e.begin], self.vertex_of[e.end]);
            let key = (begin.min(end), begin.max(end));
            let mut probes = None;
            let edges = &self.edges;
            let candidates = scanned_or_chained(chained, edges.len(), || index.edges.iter(&key));
            let found = candidates.into_iter().find_map(|id| {
                let (src, b, en) = edges[id as usize];
                if (b.min(en), b.max(en)) != key {
                    return None;
                }
                let probes = *probes.get_or_insert_with(|| probe_points(&e.curve));
                let theirs = probe_points(&brep.edges[src].curve);
                same_edge(&probes, &theirs, (b, begin, end), grid.tol).map(|f| (id, f))
            });
            let found = found.unwrap_or_else(|| {
                self.edges.push((k, begin, end));
                let id = (self.edges.len() - 1) as u32;
                if chained {
                    index.edges.push(key, id);
                }
                (id, false)
            });
            self.edge_of.push(found);
        }
        self.faces.clear();
        self.sorted.clear();
        self.face_of.clear();
        for (k, f) in brep.faces.iter().enumerate() {
            let start = self.sorted.len();
            for lp in brep.loops(f) {
                for &item in lp {
                    self.sorted.push(self.edge_of[item.0].0);
                }
            }
            self.sorted[start..].sort_unstable();
            let mine = &self.sorted[start..];
            let key = if chained { edge_list_hash(mine) } else { 0 };
            let faces = &self.faces;
            let candidates = scanned_or_chained(chained, faces.len(), || index.faces.iter(&key));
            // Face `id`'s sorted edges end where the face before it ends.
            let found = candidates.into_iter().find(|&id| {
                let (src, end) = faces[id as usize];
                let from = id
                    .checked_sub(1)
                    .map_or(0, |before| faces[before as usize].1);
                &self.sorted[from..end] == mine
                    && (brep.faces[src].sample - f.sample).norm() <= grid.tol
            });
            let found = match found {
                None => {
                    self.faces.push((k, self.sorted.len()));
                    let id = (self.faces.len() - 1) as u32;
                    if chained {
                        index.faces.push(key, id);
                    }
                    (id, true)
                }
                Some(id) => {
                    let id = id as usize;
                    self.sorted.truncate(start);
                    // A welded face keeps the first's orientation; this one's
                    // outward side agrees when its loop runs the same way.
                    let first = brep.loops(f).next().and_then(|l| l.first()).copied();
                    let existing = &brep.faces[self.faces[id].0];
                    let outward = first.is_none_or(|probe| {
                        let probe = self.orient(probe);
                        (brep.loops(existing).flatten())
                            .map(|&item| self.orient(item))
                            .find(|e| e.0 == probe.0)
                            .is_none_or(|e| e.1 == probe.1)
                    });
                    (id as u32, outward)
                }
            };
            self.face_of.push(found);
        }
        self.index = index;
    }

    /// Writes the welded solid as solid `solid` with its entities from `at`.
    fn write(&self, job: &SolidJob, solid: usize, at: Counts, out: &mut Out) {
        let brep = &self.brep;
        let id = crate::ir::SolidId(solid as u32);
        let base: Arc<Box<str>> = Arc::new(job.name.as_ref().into());
        let by_solid = !job.shape.is_planar();
        let vertex = |local: u32| VertexId(at.vertices + local);
        let orient = |item: (usize, bool)| {
            let (edge, forward) = self.orient(item);
            OrientedEdge {
                edge: EdgeId(at.edges + edge),
                forward,
            }
        };
        for &src in &self.vertices {
            let v = &brep.vertices[src];
            out.vertices.push(Vertex {
                name: EntityName::local(&base, v.name),
                position: v.position,
            });
        }
        for &(src, begin, end) in &self.edges {
            let e = &brep.edges[src];
            out.edges.push(Edge {
                name: EntityName::local(&base, e.name),
                carrier: super::brep::carrier(by_solid, id, src, &e.curve),
                begin: vertex(begin),
                end: vertex(end),
            });
        }
        let (samples, rest) = std::mem::take(&mut out.samples).split_at_mut(self.faces.len());
        out.samples = rest;
        for (&(src, _), sample) in self.faces.iter().zip(samples) {
            out.faces
                .push(brep.model_face(src, &base, (id, by_solid), orient));
            *sample = brep.faces[src].sample;
        }
        out.solids.push(Solid {
            name: base,
            shape: job.shape.clone(),
            faces: (self.face_of.iter())
                .map(|&(face, outward)| OrientedFace {
                    face: FaceId(at.faces + face),
                    outward,
                })
                .collect(),
            boundary_edges: brep.boundary.iter().copied().map(orient).collect(),
            edges: (self.edge_of.iter())
                .map(|&(e, _)| EdgeId(at.edges + e))
                .collect(),
            vertices: self.vertex_of.iter().map(|&v| vertex(v)).collect(),
        });
    }
}

/// The (vertices, edges, faces) of welding `shape`'s boundary on its own
/// with tolerance `tol`, as the isolated runs weld it.
#[cfg(test)]
pub(super) fn weld_counts(shape: &SolidShape, tol: f64) -> [u32; 3] {
    let mut weld = LocalWeld::default();
    weld.weld(shape, super::weld::Welder::new(tol).grid());
    let c = weld.counts();
    [c.vertices, c.edges, c.faces]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::{Frame, Mat3, Vec3};
    use crate::ir::Dimension;
    use crate::test_threads::on_threads;

    fn frame(x: f64, linear: Mat3) -> Frame {
        Frame {
            origin: Point3::new(x, 0.5, -0.25),
            linear,
        }
    }

    /// Regular and degenerate primitives (whose boundaries weld with
    /// themselves), turned and mirrored, 10 apart.
    fn shapes() -> Vec<SolidShape> {
        let turned = Mat3::new(0.0, -2.0, 0.1, 1.5, 0.0, 0.0, 0.2, 0.0, 0.7);
        let mirrored = Mat3::from_diagonal(&Vec3::new(-1.0, 0.5, 2.0));
        let flat = Mat3::from_diagonal(&Vec3::new(1.0, 1.0, 0.0));
        let point = Mat3::zeros();
        let mut shapes = Vec::new();
        for (group, linear) in [turned, mirrored, flat, point].into_iter().enumerate() {
            let x = 150.0 * group as f64;
            let f = |k: f64| frame(x + 10.0 * k, linear);
            shapes.push(SolidShape::Box { frame: f(0.0) });
            shapes.push(SolidShape::Ball { frame: f(1.0) });
            for (k, (r0, r1)) in [(0.4, 0.2), (0.0, 0.3), (0.25, 0.25)].iter().enumerate() {
                let (r0, r1) = (*r0, *r1);
                shapes.push(SolidShape::Cone {
                    frame: f(2.0 + k as f64),
                    r0,
                    r1,
                });
            }
            for minor in [0.15, 0.0] {
                shapes.push(SolidShape::Torus {
                    frame: f(6.0 + 10.0 * minor),
                    major: 0.5,
                    minor,
                });
            }
            shapes.push(SolidShape::Disk { frame: f(9.0) });
            let square = [(0.0, 0.0), (1.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)];
            shapes.push(SolidShape::Polygon {
                frame: f(10.0),
                vertices: square
                    .iter()
                    .map(|&(x, y)| Point3::new(x, y, 0.0))
                    .collect(),
            });
            shapes.push(SolidShape::Polygon {
                frame: f(11.0),
                vertices: large_polygon(),
            });
        }
        shapes
    }

    /// A polygon whose welding looks its candidates up (more than `SCANNED`
    /// vertices), with a repeated vertex and a stretch out and back along
    /// one line, so that even its regular frame welds vertices and edges.
    fn large_polygon() -> Vec<Point3> {
        let n = 3 * SCANNED;
        let mut vertices: Vec<Point3> = (0..n)
            .map(|k| {
                let t = std::f64::consts::TAU * k as f64 / n as f64;
                Point3::new(0.4 * t.cos(), 0.4 * t.sin(), 0.0)
            })
            .collect();
        vertices.insert(5, vertices[5]);
        let spike = [Point3::new(0.9, 0.0, 0.0), vertices[0]];
        vertices.splice(1..1, spike);
        vertices
    }

    /// The model, source map and face samples of lowering `shapes` with
    /// `isolated` per solid, on `threads` threads.
    fn lowered(shapes: &[SolidShape], isolated: &[bool], threads: usize) -> (Model, String) {
        let names: Vec<String> = (0..shapes.len()).map(|k| format!("s{k}")).collect();
        let jobs: Vec<SolidJob> = (shapes.iter().zip(&names).enumerate())
            .map(|(k, (shape, name))| SolidJob {
                name: Cow::Borrowed(name),
                shape,
                span: Span::new(k, k + 1),
            })
            .collect();
        let mut model = Model::empty(Dimension::Three);
        let mut map = SourceMap::default();
        let mut welder = super::super::weld::Welder::new(1e-6);
        on_threads(threads, || {
            super::super::lower_solids(&mut model, &mut map, &mut welder, &jobs, isolated)
        });
        let samples = format!("{map:?} {:?}", welder.face_samples);
        (model, samples)
    }

    #[test]
    fn isolated_solids_lower_as_the_welder_lowers_them_on_any_thread_count() {
        // More solids than a task holds, so runs span tasks.
        let shapes: Vec<SolidShape> = (0..16)
            .flat_map(|copy| {
                let shift = Vec3::new(0.0, 1000.0 * copy as f64, 0.0);
                shapes().into_iter().map(move |mut s| {
                    match &mut s {
                        SolidShape::Box { frame }
                        | SolidShape::Ball { frame }
                        | SolidShape::Cone { frame, .. }
                        | SolidShape::Torus { frame, .. }
                        | SolidShape::Disk { frame }
                        | SolidShape::Polygon { frame, .. } => frame.origin += shift,
                    }
                    s
                })
            })
            .collect();
        assert!(shapes.len() > 2 * TASK);
        let serial = lowered(&shapes, &vec![false; shapes.len()], 1);
        // The degenerate solids merged entities: a zero box is one vertex.
        let boxes = serial
            .0
            .solids
            .iter()
            .filter(|s| matches!(s.shape, SolidShape::Box { .. }));
        let vertex_counts: Vec<usize> = boxes
            .take(4)
            .map(|s| {
                let mut v = s.vertices.to_vec();
                v.sort_unstable();
                v.dedup();
                v.len()
            })
            .collect();
        assert_eq!(vertex_counts, [8, 8, 4, 1]);
        // The large polygon welded its repeats: 3 · SCANNED + 1 distinct
        // vertices (the spike's tip), and the spike's way out and back is
        // one edge (the repeated vertex's zero-length edge stays one of its own).
        let large = (serial.0.solids.iter())
            .find(|s| matches!(&s.shape, SolidShape::Polygon { vertices, .. } if vertices.len() > SCANNED))
            .expect("the large polygon");
        let distinct = |ids: Vec<u32>| {
            ids.into_iter()
                .collect::<std::collections::BTreeSet<_>>()
                .len()
        };
        assert_eq!(
            distinct(large.vertices.iter().map(|v| v.0).collect()),
            3 * SCANNED + 1
        );
        assert_eq!(large.edges.len(), large_polygon().len());
        assert_eq!(
            distinct(large.edges.iter().map(|e| e.0).collect()),
            large_polygon().len() - 1
        );
        let alternating: Vec<bool> = (0..shapes.len()).map(|k| k % 7 != 3).collect();
        for threads in [1, 2, 3] {
            for isolated in [vec![true; shapes.len()], alternating.clone()] {
                let parallel = lowered(&shapes, &isolated, threads);
                assert!(parallel.0 == serial.0, "{threads} threads");
                assert_eq!(parallel.1, serial.1, "{threads} threads");
            }
        }
    }
}
