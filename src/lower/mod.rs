//! Lowering: resolved objects → the model IR. Primitive solids become their
//! canonical boundary representations (welded where they coincide), explicit
//! topology becomes vertices, edges and faces, subdomains become oriented
//! shells (3D) or region faces (2D), and boundaries become named face sets.

mod booleans;
mod brep;
mod contour_straight;
mod distinct;
mod edge_parts;
mod explicit;
mod floor_index;
mod isolated;
mod isolation;
mod leaves;
mod object_solids;
mod point_calculus;
mod prune;
mod region_arcs;
mod region_collinear;
mod region_corner_touch;
mod region_crossing;
mod region_inside_cusp;
pub mod region_interfaces;
mod region_pairs;
mod region_stretches;
mod region_touch;
mod region_touch_inside;
mod reserved;
pub mod rfunction_region;
#[cfg(test)]
mod subdomain_threads_tests;
mod tolerance;
pub mod trimmed_topology;
mod weld;
mod winding;

use crate::diag::Diagnostics;
use crate::doc::Document;
use crate::geom::SolidShape;
use crate::ir::{
    Dimension, EntityName, Face, Model, OrientedEdge, OrientedFace, Origin, PointSet, Polyline,
    Solid, SolidId, SourceMap,
};
use crate::resolve::{Geometry, Resolved};
use crate::span::Span;
use foldhash::HashMap;
use std::borrow::Cow;

/// The model and its side table of source positions.
#[derive(Debug, Clone)]
pub struct Lowered {
    pub model: Model,
    pub source_map: SourceMap,
}

/// Names of lowered entities, for `faces=` and `edges=` lists.
#[derive(Debug, Default)]
pub(crate) struct Entities {
    /// "box.xmin", explicit face names → face.
    pub faces: HashMap<String, crate::ir::FaceId>,
    pub edges: HashMap<String, crate::ir::EdgeId>,
    pub vertices: HashMap<String, crate::ir::VertexId>,
    /// The solids each object lowered to.
    pub solids: object_solids::ObjectSolids,
    /// Objects that failed to resolve (already reported): references to them
    /// are not reported again.
    pub failed: foldhash::HashSet<String>,
}

impl Entities {
    /// Adds the documented names of every lowered solid's entities
    /// ("box.xmin" → its welded face). Explicit entities keep their names: an
    /// explicit entity of the same name wins, and among solids the first does.
    fn add_solid_entities(&mut self, model: &Model) {
        fn add<T: Copy>(
            table: &mut HashMap<String, T>,
            solid: &str,
            names: impl Iterator<Item = crate::ir::LocalName>,
            ids: impl Iterator<Item = T>,
        ) {
            for (local, id) in names.zip(ids) {
                table.entry(format!("{solid}.{local}")).or_insert(id);
            }
        }
        let explicit = (
            std::mem::take(&mut self.vertices),
            std::mem::take(&mut self.edges),
            std::mem::take(&mut self.faces),
        );
        for solid in &model.solids {
            let brep = brep::of(&solid.shape);
            let name: &str = &solid.name;
            add(
                &mut self.vertices,
                name,
                brep.vertices.iter().map(|v| v.name),
                solid.vertices.iter().copied(),
            );
            add(
                &mut self.edges,
                name,
                brep.edges.iter().map(|e| e.name),
                solid.edges.iter().copied(),
            );
            add(
                &mut self.faces,
                name,
                brep.faces.iter().map(|f| f.name),
                solid.faces.iter().map(|f| f.face),
            );
        }
        self.vertices.extend(explicit.0);
        self.edges.extend(explicit.1);
        self.faces.extend(explicit.2);
    }
}

/// Reads the document's subdomains and boundaries; every object comes from
/// `resolved` (the driver drops the document's objects before lowering). The
/// subdomain definitions are taken out of `doc` and dropped once lowered.
/// `resolved` is dropped once the subdomains' solid trees are built, before
/// the checks of their relations (the memory peak on files of many solids),
/// unless `keep_resolved` (the driver's implicit lowering reads it after):
/// then it is returned. `release` (the driver's `Options::release_memory`)
/// is called where much has just been freed: the isolation's shapes, the
/// welder's tables, the subdomain definitions and the resolved objects.
pub fn lower(
    doc: &mut Document,
    resolved: Resolved,
    keep_resolved: bool,
    diags: &mut Diagnostics,
    release: Option<fn()>,
) -> (Lowered, Option<Resolved>) {
    let resolved_objects = resolved;
    let resolved = &resolved_objects;
    let dimension = if resolved.dimension == 2 {
        Dimension::Two
    } else {
        Dimension::Three
    };
    let mut model = Model::empty(dimension);
    model.parameters = resolved.parameters.clone();
    // Curves that carry edges are part of the topology, not standalone lines.
    let edge_lines = point_calculus::edge_lines(resolved);
    let shapes = isolation::solid_shapes(resolved, &edge_lines);
    // Each primitive's box, made once (on the workers): the tolerance and the
    // isolation grid both read it.
    let boxes = isolation::shape_boxes(&shapes);
    model.tolerance = tolerance::of(resolved, &shapes, &boxes);
    let mut source_map = SourceMap::default();
    let mut entities = Entities::default();
    let expected = expected_entities(resolved);
    model.vertices.reserve(expected.vertices);
    model.edges.reserve(expected.edges);
    model.faces.reserve(expected.faces);
    model.solids.reserve(expected.solids);
    // The source map's tables too: grown by doubling, they left megabytes
    // unused at the memory peak, and copied them at every growth.
    let map = &mut source_map;
    map.vertices.reserve(expected.vertices, expected.solids);
    map.edges.reserve(expected.edges, expected.solids);
    map.faces.reserve(expected.faces, expected.solids);
    map.solids.reserve(expected.solids, expected.solids);
    let isolation::SolidPairs {
        isolated,
        overlapping,
    } = isolation::pairs(&shapes, boxes, model.tolerance);
    let mut shared = Expected::default();
    for (shape, _) in shapes.iter().zip(&isolated).filter(|(_, i)| !**i) {
        shared.add(shape);
    }
    drop(shapes);
    // The shapes' copies (a large block) would stay resident through the
    // object loop below, beside the model it fills.
    if let Some(release) = release {
        release();
    }
    let mut welder = weld::Welder::with_capacity(model.tolerance, &shared, expected.faces);
    point_calculus::report_unused_patches(resolved, diags);

    // The primitive solids in lowering order (`isolation::solid_shapes`'s);
    // everything else is lowered on the way.
    let mut jobs = Vec::with_capacity(expected.solids);
    for object in &resolved.objects {
        entities
            .solids
            .begin_object(model.solids.len() + jobs.len());
        let Some(geometry) = &object.geometry else {
            entities.failed.insert(object.name.clone());
            continue;
        };
        if edge_lines.contains(object.name.as_str()) {
            continue;
        }
        let (map, span) = (&mut source_map, object.span);
        match geometry {
            Geometry::Group(members) => {
                for (k, member) in members.iter().enumerate() {
                    let name = Cow::Owned(format!("{}[{}]", object.name, k + 1));
                    add_object(&mut model, map, &mut jobs, name, member, span);
                }
            }
            g => add_object(
                &mut model,
                map,
                &mut jobs,
                Cow::Borrowed(&object.name),
                g,
                span,
            ),
        }
    }
    entities
        .solids
        .begin_object(model.solids.len() + jobs.len());
    lower_solids(&mut model, &mut source_map, &mut welder, &jobs, &isolated);
    drop((jobs, isolated));
    // Only the face samples outlive the welder: its tables (tens of megabytes
    // on large files) must not still be alive while subdomains are built.
    let face_samples = std::mem::take(&mut welder.face_samples);
    drop(welder);
    // Freed memory is otherwise kept by the allocator for reuse (about a
    // second): the welder's and isolation's tables would stay resident
    // through the subdomains, the memory peak on files of many solids.
    // The workers, which lowered the isolated solids, free theirs too.
    if let Some(release) = release {
        release();
        rayon::broadcast(|_| release());
    }
    explicit::lower_topology(resolved, &mut model, &mut source_map, &mut entities, diags);
    let named_lists =
        !doc.boundaries.is_empty() || doc.subdomains.iter().any(|s| s.faces.is_some());
    if named_lists {
        entities.add_solid_entities(&model);
    }
    let trees = booleans::build_subdomains(
        std::mem::take(&mut doc.subdomains),
        resolved,
        &mut model,
        &mut source_map,
        &entities,
        diags,
    );
    drop(edge_lines);
    let kept = keep_resolved.then_some(resolved_objects);
    // The definitions and (unless kept) the resolved objects are gone: their
    // pages go back before the checks below.
    if let Some(release) = release {
        release();
    }
    booleans::check_subdomains(
        trees,
        &mut model,
        &source_map,
        &face_samples,
        overlapping,
        diags,
    );
    explicit::lower_boundaries(doc, &mut model, &entities, diags);
    prune::prune_interior(&mut model, &mut source_map);
    (Lowered { model, source_map }, kept)
}

/// How many entities the primitive solids will lower to at most (before
/// welding): the model's vectors and the welder's tables are sized once
/// instead of grown by doubling, which on large files copied hundreds of
/// megabytes and touched fresh pages at every growth.
#[derive(Debug, Default, Clone, Copy)]
pub(crate) struct Expected {
    pub vertices: usize,
    pub edges: usize,
    pub faces: usize,
    pub solids: usize,
}

impl Expected {
    /// Counts one primitive solid.
    pub(crate) fn add(&mut self, shape: &SolidShape) {
        // A box has the most entities of the canonical primitives;
        // the round ones have fewer (an estimate is enough).
        let (v, e, f) = match shape {
            SolidShape::Box { .. } => (8, 12, 6),
            SolidShape::Polygon { vertices, .. } => (vertices.len(), vertices.len(), 1),
            _ => (2, 3, 3),
        };
        self.vertices += v;
        self.edges += e;
        self.faces += f;
        self.solids += 1;
    }
}

fn expected_entities(resolved: &Resolved) -> Expected {
    fn visit(g: &Geometry, n: &mut Expected) {
        match g {
            Geometry::Solid(shape) => n.add(shape),
            Geometry::Group(members) => members.iter().for_each(|m| visit(m, n)),
            _ => {}
        }
    }
    let mut n = Expected::default();
    for o in &resolved.objects {
        if let Some(g) = &o.geometry {
            visit(g, &mut n);
        }
    }
    n
}

/// Queues a primitive solid for [`lower_solids`], or lowers anything else.
fn add_object<'r>(
    model: &mut Model,
    source_map: &mut SourceMap,
    jobs: &mut Vec<isolated::SolidJob<'r>>,
    name: Cow<'r, str>,
    geometry: &'r Geometry,
    span: Span,
) {
    match geometry {
        Geometry::Solid(shape) => jobs.push(isolated::SolidJob { name, shape, span }),
        g => lower_free(model, source_map, &name, g, span),
    }
}

/// Lowers the primitive solids in order: runs of isolated ones on the
/// workers (`isolated.rs`), the others one by one through the welder.
/// `isolated` holds, per job, whether its solid is isolated.
fn lower_solids(
    model: &mut Model,
    source_map: &mut SourceMap,
    welder: &mut weld::Welder,
    jobs: &[isolated::SolidJob],
    isolated: &[bool],
) {
    debug_assert_eq!(jobs.len(), isolated.len());
    let mut brep = brep::Brep::default();
    let mut k = 0;
    while k < jobs.len() {
        let run = isolated[k..].iter().take_while(|&&i| i).count();
        if run > 0 {
            let grid = welder.grid();
            let (samples, run_jobs) = (&mut welder.face_samples, &jobs[k..k + run]);
            isolated::lower_run(model, source_map, samples, grid, run_jobs);
            k += run;
        } else {
            let job = &jobs[k];
            brep.rebuild(job.shape);
            lower_solid(model, source_map, welder, &brep, job);
            k += 1;
        }
    }
}

fn lower_free(
    model: &mut Model,
    source_map: &mut SourceMap,
    name: &str,
    geometry: &Geometry,
    span: Span,
) {
    match geometry {
        Geometry::Points { points, .. } => model.point_sets.push(PointSet {
            name: name.to_string(),
            points: points.clone(),
        }),
        Geometry::Polyline { points, crack } => model.polylines.push(Polyline {
            name: name.to_string(),
            points: points.clone(),
            crack: *crack,
            ..Polyline::default()
        }),
        Geometry::PointCurve(curve) => model
            .polylines
            .push(point_calculus::standalone(name, curve)),
        Geometry::Trimmed(surface) => {
            model.trimmed.push((**surface).clone());
            source_map.trimmed.push(span);
        }
        _ => {}
    }
}

/// Lowers a solid that may weld with others: `brep` is its boundary.
fn lower_solid(
    model: &mut Model,
    source_map: &mut SourceMap,
    welder: &mut weld::Welder,
    brep: &brep::Brep,
    job: &isolated::SolidJob,
) -> SolidId {
    let (name, shape) = (job.name.as_ref(), job.shape);
    let origin = Origin { span: job.span };
    // The solid comes first: its faces and edges make their carriers from its
    // shape (3D primitives; a 2D region's entities keep their own), and the
    // welder may read them while the solid is lowered.
    let id = SolidId(model.solids.len() as u32);
    // The entities' names share the solid's ("{name}.{local}"); the name
    // tables for faces= and edges= lists are built later, and only when a
    // file has such lists.
    let base: std::sync::Arc<Box<str>> = std::sync::Arc::new(name.into());
    model.solids.push(Solid {
        name: std::sync::Arc::clone(&base),
        shape: shape.clone(),
        faces: Box::default(),
        boundary_edges: Box::default(),
        edges: Box::default(),
        vertices: Box::default(),
    });
    let by_solid = !shape.is_planar();
    let vertex_ids: Vec<_> = brep
        .vertices
        .iter()
        .map(|v| {
            let (id, new) = welder.vertex(model, || EntityName::local(&base, v.name), v.position);
            if new {
                source_map.vertices.insert(id, origin);
            }
            id
        })
        .collect();
    let edge_ids: Vec<_> = brep
        .edges
        .iter()
        .enumerate()
        .map(|(local, e)| {
            let (id, flipped, new) = welder.edge(
                model,
                || EntityName::local(&base, e.name),
                &e.curve,
                || brep::carrier(by_solid, id, local, &e.curve),
                vertex_ids[e.begin],
                vertex_ids[e.end],
            );
            if new {
                source_map.edges.insert(id, origin);
            }
            (id, flipped)
        })
        .collect();
    let orient = |(local, forward): (usize, bool)| {
        let (edge, flipped) = edge_ids[local];
        OrientedEdge {
            edge,
            forward: forward != flipped,
        }
    };
    let mut faces = Vec::with_capacity(brep.faces.len());
    for (local, f) in brep.faces.iter().enumerate() {
        let face = brep.model_face(local, &base, (id, by_solid), orient);
        let first = face.loops.first().and_then(|l| l.first()).copied();
        let (id, new) = welder.face(model, face, f.sample);
        if new {
            source_map.faces.insert(id, origin);
        }
        // A welded face keeps the first solid's orientation; this solid's
        // outward side agrees when its loop runs the same way.
        let outward = new || first.is_none_or(|probe| same_direction(model.face(id), probe));
        faces.push(OrientedFace { face: id, outward });
    }
    let boundary_edges = brep.boundary.iter().copied().map(orient).collect();
    let solid = &mut model.solids[id.index()];
    solid.faces = faces.into_boxed_slice();
    solid.boundary_edges = boundary_edges;
    solid.edges = edge_ids.iter().map(|&(e, _)| e).collect();
    solid.vertices = vertex_ids.into_boxed_slice();
    source_map.solids.insert(id, origin);
    id
}

fn same_direction(face: &Face, probe: OrientedEdge) -> bool {
    face.loops
        .edges()
        .iter()
        .find(|e| e.edge == probe.edge)
        .is_none_or(|e| e.forward == probe.forward)
}
