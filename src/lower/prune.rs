//! Removing what the boolean trees made interior: faces of solids used by
//! subdomains that bound no subdomain, and the edges and vertices only they used.

use crate::ir::{
    EdgeId, FaceId, Model, OrientedEdge, OrientedFace, SourceMap, SubdomainCells, VertexId,
};
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};

pub(super) fn prune_interior(model: &mut Model, source_map: &mut SourceMap) {
    // Flag vectors, not sets: these run over every entity of the model, each
    // pass on the workers (a pass writes one value only, so its flags do not
    // depend on the order).
    let used_by_subdomains = Flags::new(model.solids.len(), false);
    (model.subdomains.par_iter())
        .flat_map_iter(|s| &s.solids)
        .for_each(|id| used_by_subdomains.set(id.index(), true));
    let solids = || {
        model
            .solids
            .par_iter()
            .enumerate()
            .with_min_len(ITEMS_PER_TASK)
    };
    let keep_face = Flags::new(model.faces.len(), true);
    // A used 2D region's own face is replaced by its subdomain's face.
    solids()
        .filter(|(k, _)| used_by_subdomains.get(*k))
        .for_each(|(_, solid)| {
            (solid.faces.iter()).for_each(|of| keep_face.set(of.face.index(), false))
        });
    solids()
        .filter(|(k, _)| !used_by_subdomains.get(*k))
        .for_each(|(_, solid)| {
            (solid.faces.iter()).for_each(|of| keep_face.set(of.face.index(), true))
        });
    model.subdomains.par_iter().for_each(|s| match &s.cells {
        SubdomainCells::Volume { boundary } => boundary
            .iter()
            .for_each(|of| keep_face.set(of.face.index(), true)),
        SubdomainCells::Region { faces } => {
            faces.iter().for_each(|f| keep_face.set(f.index(), true))
        }
    });
    for b in &model.boundaries {
        b.faces.iter().for_each(|f| keep_face.set(f.index(), true));
    }
    let keep_edge = Flags::new(model.edges.len(), false);
    (model.faces.par_iter().enumerate())
        .with_min_len(ITEMS_PER_TASK)
        .filter(|(k, _)| keep_face.get(*k))
        .for_each(|(_, face)| {
            (face.loops.iter().flatten()).for_each(|e| keep_edge.set(e.edge.index(), true))
        });
    // Explicit edges and edges of free-standing solids always stay.
    let primitive_edges = Flags::new(model.edges.len(), false);
    solids().for_each(|(_, s)| {
        s.edges
            .iter()
            .for_each(|e| primitive_edges.set(e.index(), true))
    });
    (0..model.edges.len())
        .into_par_iter()
        .with_min_len(ITEMS_PER_TASK)
        .filter(|&k| !primitive_edges.get(k))
        .for_each(|k| keep_edge.set(k, true));
    solids()
        .filter(|(k, _)| !used_by_subdomains.get(*k))
        .for_each(|(_, solid)| {
            solid
                .edges
                .iter()
                .for_each(|e| keep_edge.set(e.index(), true))
        });
    for b in &model.boundaries {
        b.edges.iter().for_each(|e| keep_edge.set(e.index(), true));
    }
    let keep_vertex = Flags::new(model.vertices.len(), false);
    (model.edges.par_iter().enumerate())
        .with_min_len(ITEMS_PER_TASK)
        .filter(|(k, _)| keep_edge.get(*k))
        .for_each(|(_, edge)| {
            keep_vertex.set(edge.begin.index(), true);
            keep_vertex.set(edge.end.index(), true);
        });
    let primitive_vertices = Flags::new(model.vertices.len(), false);
    solids().for_each(|(_, s)| {
        (s.vertices.iter()).for_each(|v| primitive_vertices.set(v.index(), true))
    });
    (0..model.vertices.len())
        .into_par_iter()
        .with_min_len(ITEMS_PER_TASK)
        .filter(|&k| !primitive_vertices.get(k))
        .for_each(|k| keep_vertex.set(k, true));
    drop((used_by_subdomains, primitive_edges, primitive_vertices));
    let (keep_face, keep_edge, keep_vertex) = (
        keep_face.into_vec(),
        keep_edge.into_vec(),
        keep_vertex.into_vec(),
    );
    if keep_face.iter().all(|&k| k)
        && keep_edge.iter().all(|&k| k)
        && keep_vertex.iter().all(|&k| k)
    {
        return;
    }
    // The maps only when something goes: on large files they were megabytes
    // at the end of lowering, where the memory peaks.
    let face_map = compact(&keep_face);
    let edge_map = compact(&keep_edge);
    let vertex_map = compact(&keep_vertex);
    drop((keep_face, keep_edge, keep_vertex));
    apply(model, source_map, &face_map, &edge_map, &vertex_map);
}

/// Entities per task of the flag passes.
const ITEMS_PER_TASK: usize = 4096;

/// Flags written by the workers; an index out of range is ignored on
/// writing and reads false.
struct Flags(Vec<AtomicBool>);

impl Flags {
    fn new(len: usize, value: bool) -> Flags {
        Flags((0..len).map(|_| AtomicBool::new(value)).collect())
    }

    fn set(&self, index: usize, value: bool) {
        if let Some(flag) = self.0.get(index) {
            flag.store(value, Ordering::Relaxed);
        }
    }

    fn get(&self, index: usize) -> bool {
        self.0.get(index).is_some_and(|f| f.load(Ordering::Relaxed))
    }

    fn into_vec(self) -> Vec<bool> {
        self.0.into_iter().map(AtomicBool::into_inner).collect()
    }
}

/// Which vertices end an edge that `keep_edge` keeps.
pub(super) fn ends_of_kept(model: &Model, keep_edge: &[bool]) -> Vec<bool> {
    let mut ends = vec![false; model.vertices.len()];
    for (edge, &keep) in model.edges.iter().zip(keep_edge) {
        if keep {
            ends[edge.begin.index()] = true;
            ends[edge.end.index()] = true;
        }
    }
    ends
}

/// Drops the edges and vertices whose flag is false (faces stay), renumbering
/// what refers to the rest: what `region_arcs` replaced by kernel arcs.
pub(super) fn drop_entities(
    model: &mut Model,
    source_map: &mut SourceMap,
    keep_edge: &[bool],
    keep_vertex: &[bool],
) {
    if keep_edge.iter().all(|&k| k) && keep_vertex.iter().all(|&k| k) {
        return;
    }
    let faces = compact(&vec![true; model.faces.len()]);
    let (edges, vertices) = (compact(keep_edge), compact(keep_vertex));
    apply(model, source_map, &faces, &edges, &vertices);
}

fn compact(keep: &[bool]) -> Vec<Option<u32>> {
    let mut next = 0u32;
    keep.iter()
        .map(|&k| {
            k.then(|| {
                next += 1;
                next - 1
            })
        })
        .collect()
}

fn retain_indexed<T>(items: &mut Vec<T>, map: &[Option<u32>]) {
    let mut k = 0;
    items.retain(|_| {
        let keep = map.get(k).copied().flatten().is_some();
        k += 1;
        keep
    });
}

fn apply(
    model: &mut Model,
    source_map: &mut SourceMap,
    faces: &[Option<u32>],
    edges: &[Option<u32>],
    vertices: &[Option<u32>],
) {
    let f = |id: FaceId| faces.get(id.index()).copied().flatten().map(FaceId);
    let e = |id: EdgeId| edges.get(id.index()).copied().flatten().map(EdgeId);
    let v = |id: VertexId| vertices.get(id.index()).copied().flatten().map(VertexId);
    retain_indexed(&mut model.faces, faces);
    retain_indexed(&mut model.edges, edges);
    retain_indexed(&mut model.vertices, vertices);
    for edge in &mut model.edges {
        edge.begin = v(edge.begin).unwrap_or(edge.begin);
        edge.end = v(edge.end).unwrap_or(edge.end);
    }
    for face in &mut model.faces {
        for oe in face.loops.edges_mut() {
            oe.edge = e(oe.edge).unwrap_or(oe.edge);
        }
    }
    for s in &mut model.subdomains {
        match &mut s.cells {
            SubdomainCells::Volume { boundary } => {
                boundary.retain(|of| f(of.face).is_some());
                boundary
                    .iter_mut()
                    .for_each(|of| of.face = f(of.face).unwrap_or(of.face));
            }
            SubdomainCells::Region { faces: list } => {
                list.retain(|&x| f(x).is_some());
                list.iter_mut().for_each(|x| *x = f(*x).unwrap_or(*x));
            }
        }
    }
    for solid in &mut model.solids {
        solid.faces = kept(&solid.faces, |of| {
            f(of.face).map(|face| OrientedFace { face, ..of })
        });
        solid.boundary_edges = kept(&solid.boundary_edges, |oe| {
            e(oe.edge).map(|edge| OrientedEdge { edge, ..oe })
        });
        solid.edges = kept(&solid.edges, e);
        solid.vertices = kept(&solid.vertices, v);
    }
    for b in &mut model.boundaries {
        b.faces.retain(|&x| f(x).is_some());
        b.faces.iter_mut().for_each(|x| *x = f(*x).unwrap_or(*x));
        b.edges.retain(|&x| e(x).is_some());
        b.edges.iter_mut().for_each(|x| *x = e(*x).unwrap_or(*x));
    }
    source_map.faces = source_map.faces.remap(f);
    source_map.edges = source_map.edges.remap(e);
    source_map.vertices = source_map.vertices.remap(v);
}

/// The items `map` keeps, mapped (a solid's lists are boxed slices).
fn kept<T: Copy>(items: &[T], map: impl Fn(T) -> Option<T>) -> Box<[T]> {
    items.iter().filter_map(|&x| map(x)).collect()
}
