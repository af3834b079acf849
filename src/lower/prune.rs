//! Removing what the boolean trees made interior: faces of solids used by
//! subdomains that bound no subdomain, and the edges and vertices only they used.

use crate::ir::{
    EdgeId, FaceId, Model, OrientedEdge, OrientedFace, SourceMap, SubdomainCells, VertexId,
};

pub(super) fn prune_interior(model: &mut Model, source_map: &mut SourceMap) {
    // Flag vectors, not sets: these run over every entity of the model.
    let mut used_by_subdomains = vec![false; model.solids.len()];
    for id in model.subdomains.iter().flat_map(|s| &s.solids) {
        if let Some(flag) = used_by_subdomains.get_mut(id.index()) {
            *flag = true;
        }
    }
    let mut keep_face = vec![true; model.faces.len()];
    for (k, solid) in model.solids.iter().enumerate() {
        if used_by_subdomains[k] {
            for of in &solid.faces {
                keep_face[of.face.index()] = false;
            }
            // A used 2D region's own face is replaced by its subdomain's face.
        }
    }
    for (k, solid) in model.solids.iter().enumerate() {
        if !used_by_subdomains[k] {
            solid
                .faces
                .iter()
                .for_each(|of| keep_face[of.face.index()] = true);
        }
    }
    for s in &model.subdomains {
        match &s.cells {
            SubdomainCells::Volume { boundary } => boundary
                .iter()
                .for_each(|of| keep_face[of.face.index()] = true),
            SubdomainCells::Region { faces } => {
                faces.iter().for_each(|f| keep_face[f.index()] = true)
            }
        }
    }
    for b in &model.boundaries {
        b.faces.iter().for_each(|f| keep_face[f.index()] = true);
    }
    let mut keep_edge = vec![false; model.edges.len()];
    for (k, face) in model.faces.iter().enumerate() {
        if keep_face[k] {
            face.loops
                .iter()
                .flatten()
                .for_each(|e| keep_edge[e.edge.index()] = true);
        }
    }
    let mut primitive_edges = vec![false; model.edges.len()];
    for e in model.solids.iter().flat_map(|s| &s.edges) {
        if let Some(flag) = primitive_edges.get_mut(e.index()) {
            *flag = true;
        }
    }
    for (k, keep) in keep_edge.iter_mut().enumerate() {
        // Explicit edges and edges of free-standing solids always stay.
        if !primitive_edges[k] {
            *keep = true;
        }
    }
    for (k, solid) in model.solids.iter().enumerate() {
        if !used_by_subdomains[k] {
            solid.edges.iter().for_each(|e| keep_edge[e.index()] = true);
        }
    }
    for b in &model.boundaries {
        b.edges.iter().for_each(|e| keep_edge[e.index()] = true);
    }
    let mut keep_vertex = ends_of_kept(model, &keep_edge);
    let mut primitive_vertices = vec![false; model.vertices.len()];
    for v in model.solids.iter().flat_map(|s| &s.vertices) {
        if let Some(flag) = primitive_vertices.get_mut(v.index()) {
            *flag = true;
        }
    }
    for (k, keep) in keep_vertex.iter_mut().enumerate() {
        if !primitive_vertices[k] {
            *keep = true;
        }
    }
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
