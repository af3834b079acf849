//! Topological checks of the model: edges (E400), face loops (E401), the
//! closed shells bounding 3D subdomains (E402–E405), and how faces and
//! explicit entities are used (E406, W004).
//!
//! The checks look only at the topology graph and the enum fields of the
//! curves; they never evaluate geometry, so they run on any model, and ids out
//! of range (a malformed model) are skipped rather than indexed.

use crate::diag::{Code, Diagnostic, Diagnostics};
use crate::geom::Curve;
use crate::ir::{
    Carrier, Edge, EdgeId, FaceId, Model, OrientedEdge, OrientedFace, SourceMap, SubdomainCells,
    SubdomainId, VertexId,
};
use crate::span::Span;
use rayon::prelude::*;
use std::collections::{BTreeSet, VecDeque};

/// The fewest subdomains one parallel job of the shell checks takes (a
/// shell check is a few microseconds; fewer per job would cost more than it saves).
const SHELLS_PER_JOB: usize = 64;

/// How close t1 − t0 of an ellipse must be to 2π for the curve to be closed.
const ANGLE_TOLERANCE: f64 = 1e-9;

fn vertex_name(model: &Model, id: VertexId) -> String {
    model
        .vertices
        .get(id.index())
        .map_or_else(|| format!("#{}", id.0), |v| v.name.to_string())
}

fn edge_name(model: &Model, id: EdgeId) -> String {
    model
        .edges
        .get(id.index())
        .map_or_else(|| format!("#{}", id.0), |e| e.name.to_string())
}

fn face_name(model: &Model, id: FaceId) -> String {
    model
        .faces
        .get(id.index())
        .map_or_else(|| format!("#{}", id.0), |f| f.name.to_string())
}

fn subdomain_name(model: &Model, id: SubdomainId) -> String {
    model
        .subdomains
        .get(id.index())
        .map_or_else(|| format!("#{}", id.0), |s| s.name.clone())
}

/// Whether the curve returns to its start, judged from its defining data
/// only (the evaluation methods belong to the geometry kernel).
fn curve_is_closed(curve: &Curve, tolerance: f64) -> bool {
    match curve {
        Curve::Segment { .. } | Curve::Contour { .. } => false,
        Curve::Ellipse { t0, t1, .. } => {
            ((t1 - t0) - std::f64::consts::TAU).abs() <= ANGLE_TOLERANCE
        }
        Curve::Intersection { a, b, .. } => (a - b).norm() <= tolerance,
        Curve::PointCalculus(c) => (c.begin() - c.end()).norm() <= tolerance,
        Curve::Chain { points } => match (points.first(), points.last()) {
            (Some(a), Some(b)) => points.len() > 2 && (a - b).norm() <= tolerance,
            _ => false,
        },
    }
}

/// Whether the edge's curve is closed: a primitive's is judged from its
/// solid's shape without making the curve (every closed edge of a file of
/// spheres, cones and tori is a primitive's).
fn edge_curve_is_closed(edge: &Edge, model: &Model) -> bool {
    if let Carrier::Primitive { solid, local } = edge.carrier
        && let Some(closed) =
            (model.solids.get(solid.index())).and_then(|s| s.shape.edge_is_closed(local as usize))
    {
        return closed;
    }
    curve_is_closed(&edge.curve(&model.solids), model.tolerance)
}

fn curve_description(curve: &Curve) -> String {
    match curve {
        Curve::Segment { .. } => "a straight segment".to_string(),
        Curve::Contour { .. } => "a piece of a region's contour".to_string(),
        Curve::Ellipse { t0, t1, .. } => format!("an arc spanning {:.6} rad, not 2π", t1 - t0),
        Curve::Intersection { .. } => "an intersection curve with distinct ends".to_string(),
        Curve::PointCalculus(c) => format!("a {} with distinct ends", c.element()),
        Curve::Chain { .. } => "a trimmed surface's chain with distinct ends".to_string(),
    }
}

/// E400 for edges whose ends coincide on an open curve, then E401 for face
/// loops that are not closed chains (the first break of each loop).
pub fn check_faces(model: &Model, source_map: &SourceMap, diags: &mut Diagnostics) {
    for (i, edge) in model.edges.iter().enumerate() {
        let id = EdgeId(i as u32);
        if edge.begin == edge.end && !edge_curve_is_closed(edge, model) {
            diags.push(
                Diagnostic::new(
                    Code::EdgeEndsCoincide,
                    source_map.edge(id),
                    format!(
                        "edge '{}' begins and ends at vertex '{}' but its curve is open ({})",
                        edge.name,
                        vertex_name(model, edge.begin),
                        curve_description(&edge.curve(&model.solids))
                    ),
                )
                .with_help(
                    "give the edge two distinct vertices, or put it on a closed curve \
                     (a full circle or ellipse)",
                ),
            );
        }
    }

    for (i, face) in model.faces.iter().enumerate() {
        let id = FaceId(i as u32);
        for (l, edges) in face.loops.iter().enumerate() {
            // Formatted only for a finding: this runs for every loop of the model.
            let which = || {
                if face.loops.len() == 1 {
                    format!("the loop of face '{}'", face.name)
                } else {
                    format!("loop {} of face '{}'", l + 1, face.name)
                }
            };
            if edges.is_empty() {
                diags.push(
                    Diagnostic::new(
                        Code::OpenLoop,
                        source_map.face(id),
                        format!("{} has no edges", which()),
                    )
                    .with_help("list the edges of the loop, or remove the empty loop"),
                );
                continue;
            }
            // (edge, tail, head) as the loop runs; a dangling edge id is
            // another stage's error, so the loop is not judged.
            if edges.iter().any(|oe| oe.edge.index() >= model.edges.len()) {
                continue;
            }
            let step = |k: usize| loop_step(model, edges[k]);
            let n = edges.len();
            let Some(k) = first_break(model, edges) else {
                continue;
            };
            let (edge, tail, head) = step(k);
            let (next, next_tail, _) = step((k + 1) % n);
            let message = if n == 1 {
                format!(
                    "{} is not closed: its only edge '{}' runs from vertex '{}' to vertex '{}'",
                    which(),
                    edge_name(model, edge),
                    vertex_name(model, tail),
                    vertex_name(model, head)
                )
            } else {
                format!(
                    "{} is not closed: edge '{}' ends at vertex '{}' but the next edge '{}' \
                     begins at vertex '{}'",
                    which(),
                    edge_name(model, edge),
                    vertex_name(model, head),
                    edge_name(model, next),
                    vertex_name(model, next_tail)
                )
            };
            diags.push(
                Diagnostic::new(Code::OpenLoop, source_map.face(id), message).with_help(
                    "list the loop's edges in order, each beginning where the previous one ends \
                     and the last ending where the first begins",
                ),
            );
        }
    }
}

/// (edge, tail, head) of a loop's edge as the loop runs; the edge exists.
fn loop_step(model: &Model, oe: OrientedEdge) -> (EdgeId, VertexId, VertexId) {
    let e = &model.edges[oe.edge.index()];
    if oe.forward {
        (oe.edge, e.begin, e.end)
    } else {
        (oe.edge, e.end, e.begin)
    }
}

/// The first `k` whose edge does not end where edge `k + 1` (cyclically)
/// begins, each edge looked up once (this runs for every loop of the
/// model); the loop is not empty and its edges exist.
fn first_break(model: &Model, edges: &[OrientedEdge]) -> Option<usize> {
    let (_, first_tail, mut head) = loop_step(model, edges[0]);
    for (k, &oe) in edges.iter().enumerate().skip(1) {
        let (_, tail, next_head) = loop_step(model, oe);
        if tail != head {
            return Some(k - 1);
        }
        head = next_head;
    }
    (head != first_tail).then_some(edges.len() - 1)
}

/// One use of an edge by a face of a subdomain's boundary.
#[derive(Debug, Clone, Copy)]
struct EdgeUse {
    /// Index into the subdomain's boundary list, as four bytes: with the
    /// edge id a use is 12 bytes instead of 24, and every subdomain's uses
    /// are written twice (a boundary list of 2³² faces would not fit in memory).
    entry: u32,
    /// Direction in the face's own loop.
    forward: bool,
}

impl EdgeUse {
    fn entry(self) -> usize {
        self.entry as usize
    }
}

/// Every use of every edge by the listed faces, grouped by edge id
/// (ascending), each group in boundary order. One flat vector sorted by edge
/// instead of a map of vectors: this runs for every subdomain of the model.
struct EdgeUses {
    uses: Vec<(EdgeId, EdgeUse)>,
}

impl EdgeUses {
    /// Fills `scratch.uses` (emptied first, its capacity reused) and takes it.
    fn of(model: &Model, boundary: &[OrientedFace], scratch: &mut Scratch) -> EdgeUses {
        let unsorted = &mut scratch.unsorted_uses;
        unsorted.clear();
        let (mut low, mut high) = (u32::MAX, 0);
        for (entry, of) in boundary.iter().enumerate() {
            let Some(face) = model.faces.get(of.face.index()) else {
                continue;
            };
            // Every loop's edges, loop after loop, as one slice.
            for oe in face.loops.edges() {
                if oe.edge.index() < model.edges.len() {
                    let forward = oe.forward;
                    unsorted.push((
                        oe.edge,
                        EdgeUse {
                            entry: entry as u32,
                            forward,
                        },
                    ));
                    low = low.min(oe.edge.0);
                    high = high.max(oe.edge.0);
                }
            }
        }
        let mut uses = std::mem::take(&mut scratch.uses);
        uses.clear();
        let span = high.saturating_sub(low) as usize + 1;
        if unsorted.is_empty() || span > BUCKETS_PER_USE * unsorted.len() + BUCKETS_EXTRA {
            // Stable: within an edge the uses stay in boundary order.
            uses.extend_from_slice(unsorted);
            uses.sort_by_key(|&(edge, _)| edge);
        } else {
            bucket_by_edge(unsorted, low, span, &mut scratch.bucket_starts, &mut uses);
        }
        EdgeUses { uses }
    }

    /// The uses of every used edge, ascending by edge, without copying.
    fn lists(&self) -> impl Iterator<Item = (EdgeId, &[(EdgeId, EdgeUse)])> + '_ {
        self.uses
            .chunk_by(|a, b| a.0 == b.0)
            .map(|group| (group[0].0, group))
    }
}

/// Edge ids a subdomain's uses may span, per use (plus a few), for them to
/// be grouped by counting rather than sorted: a solid's edges are numbered
/// together, so its boundary's uses span about a quarter of their number.
const BUCKETS_PER_USE: usize = 4;
const BUCKETS_EXTRA: usize = 64;

/// `uses` = `unsorted` grouped by edge in ascending order, each group in
/// `unsorted`'s order: what a stable sort by edge gives, by counting the uses
/// of each edge in `low..low + span` (every subdomain's uses are grouped, so
/// sorting them was most of the shell checks).
fn bucket_by_edge(
    unsorted: &[(EdgeId, EdgeUse)],
    low: u32,
    span: usize,
    starts: &mut Vec<u32>,
    uses: &mut Vec<(EdgeId, EdgeUse)>,
) {
    starts.clear();
    starts.resize(span + 1, 0);
    for &(edge, _) in unsorted {
        starts[(edge.0 - low) as usize + 1] += 1;
    }
    for k in 0..span {
        starts[k + 1] += starts[k];
    }
    let filler = (
        EdgeId(0),
        EdgeUse {
            entry: 0,
            forward: false,
        },
    );
    uses.resize(unsorted.len(), filler);
    for &item in unsorted {
        let next = &mut starts[(item.0.0 - low) as usize];
        uses[*next as usize] = item;
        *next += 1;
    }
}

/// Buffers the shell checks reuse from one subdomain to the next (one set
/// per parallel job): fresh vectors were about fifteen allocations per
/// subdomain, and files of many primitives have one subdomain per solid.
#[derive(Default)]
struct Scratch {
    uses: Vec<(EdgeId, EdgeUse)>,
    unsorted_uses: Vec<(EdgeId, EdgeUse)>,
    /// Per edge (from the lowest used): where its uses go.
    bucket_starts: Vec<u32>,
    parent: Vec<usize>,
    component_of_root: Vec<usize>,
    component_of_entry: Vec<usize>,
    /// Entry `a`'s neighbours are `adjacent[adjacent_start[a]..adjacent_start[a + 1]]`.
    adjacent_start: Vec<usize>,
    adjacent: Vec<(usize, bool, EdgeId)>,
    seam_conflict: Vec<Option<EdgeId>>,
    flip: Vec<Option<bool>>,
    members: Vec<usize>,
    queue: VecDeque<usize>,
    vertices: Vec<(usize, VertexId)>,
    all_vertices: Vec<VertexId>,
    /// Per vertex (from the lowest used): whether it was counted.
    seen: Vec<bool>,
    counts: Vec<ShellCounts>,
}

/// Groups boundary entries (with a valid face) connected through shared
/// edges into components numbered by their first entry; fills
/// `scratch.component_of_entry` (`usize::MAX` for an invalid face) and
/// returns the number of components.
fn components(
    model: &Model,
    boundary: &[OrientedFace],
    uses: &EdgeUses,
    scratch: &mut Scratch,
) -> usize {
    // Union–find over the entries rather than adjacency sets and a search:
    // the same components, without an allocation per face.
    let n = boundary.len();
    let parent = &mut scratch.parent;
    parent.clear();
    parent.extend(0..n);
    fn root(parent: &mut [usize], mut a: usize) -> usize {
        while parent[a] != a {
            parent[a] = parent[parent[a]];
            a = parent[a];
        }
        a
    }
    for (_, list) in uses.lists() {
        for pair in list.windows(2) {
            let (a, b) = (
                root(parent, pair[0].1.entry()),
                root(parent, pair[1].1.entry()),
            );
            parent[a.max(b)] = a.min(b);
        }
    }
    // Entries in ascending order: a component starts at its first entry.
    let component_of_root = &mut scratch.component_of_root;
    component_of_root.clear();
    component_of_root.resize(n, usize::MAX);
    let component_of_entry = &mut scratch.component_of_entry;
    component_of_entry.clear();
    component_of_entry.resize(n, usize::MAX);
    let mut count = 0;
    for (entry, of) in boundary.iter().enumerate() {
        if of.face.index() >= model.faces.len() {
            continue;
        }
        let r = root(parent, entry);
        if component_of_root[r] == usize::MAX {
            component_of_root[r] = count;
            count += 1;
        }
        component_of_entry[entry] = component_of_root[r];
    }
    count
}

/// V − E + F − (L − F): inner loops (rings) count against faces.
fn euler_characteristic(vertices: usize, edges: usize, faces: usize, loops: usize) -> i64 {
    let f = faces as i64;
    vertices as i64 - edges as i64 + f - (loops as i64 - f)
}

/// G from χ = 2(1 − G) for one shell; `None` when no whole G ≥ 0 fits.
fn genus(chi: i64) -> Option<u64> {
    (chi <= 2 && chi % 2 == 0).then(|| ((2 - chi) / 2) as u64)
}

/// One connected shell of a subdomain's boundary (faces joined through shared
/// edges) with the counts of the Euler–Poincaré formula.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Shell {
    /// Faces of the shell, in the subdomain's boundary order.
    pub faces: Vec<FaceId>,
    pub vertices: usize,
    pub edges: usize,
    pub loops: usize,
}

impl Shell {
    /// χ = V − E + F − (L − F): inner loops (rings) count against faces.
    pub fn euler_characteristic(&self) -> i64 {
        euler_characteristic(self.vertices, self.edges, self.faces.len(), self.loops)
    }

    /// G from χ = 2(1 − G) for one shell; `None` when no whole G ≥ 0 fits.
    pub fn genus(&self) -> Option<u64> {
        genus(self.euler_characteristic())
    }
}

/// A [`Shell`]'s counts without its face list (the checks need only the
/// first face, for messages).
#[derive(Debug, Clone, Copy, Default)]
struct ShellCounts {
    first_face: Option<FaceId>,
    faces: usize,
    vertices: usize,
    edges: usize,
    loops: usize,
}

impl ShellCounts {
    fn euler_characteristic(&self) -> i64 {
        euler_characteristic(self.vertices, self.edges, self.faces, self.loops)
    }

    fn genus(&self) -> Option<u64> {
        genus(self.euler_characteristic())
    }
}

/// The counts of every shell (in `scratch.counts`, shells numbered by their
/// first entry; `scratch.component_of_entry` gives each entry's shell) and
/// the number of distinct vertices of the whole boundary. The counts come
/// from the edge uses (every valid edge of every valid face, grouped by
/// edge, each group within one shell), so each edge is looked up once
/// instead of once per use and per count.
fn shell_counts(
    model: &Model,
    boundary: &[OrientedFace],
    uses: &EdgeUses,
    scratch: &mut Scratch,
) -> usize {
    let count = components(model, boundary, uses, scratch);
    let counts = &mut scratch.counts;
    counts.clear();
    counts.resize(count, ShellCounts::default());
    for (entry, &shell) in scratch.component_of_entry.iter().enumerate() {
        if shell == usize::MAX {
            continue;
        }
        let face = boundary[entry].face;
        let c = &mut counts[shell];
        c.first_face.get_or_insert(face);
        c.faces += 1;
        c.loops += model.faces.get(face.index()).map_or(0, |f| f.loops.len());
    }
    // (shell, vertex) for both ends of every distinct edge.
    let vertices = &mut scratch.vertices;
    vertices.clear();
    vertices.reserve(2 * uses.uses.len());
    let (mut low, mut high) = (u32::MAX, 0);
    for (edge, list) in uses.lists() {
        let shell = scratch.component_of_entry[list[0].1.entry()];
        let Some(e) = model.edges.get(edge.index()) else {
            continue;
        };
        counts[shell].edges += 1;
        vertices.extend([(shell, e.begin), (shell, e.end)]);
        low = low.min(e.begin.0.min(e.end.0));
        high = high.max(e.begin.0.max(e.end.0));
    }
    let span = high.saturating_sub(low) as usize + 1;
    if count == 1
        && !vertices.is_empty()
        && span <= BUCKETS_PER_USE * vertices.len() + BUCKETS_EXTRA
    {
        // One shell (every primitive's): its distinct vertices are the
        // boundary's, marked by id instead of sorted.
        let seen = &mut scratch.seen;
        seen.clear();
        seen.resize(span, false);
        let mut distinct = 0;
        for &(_, v) in vertices.iter() {
            let mark = &mut seen[(v.0 - low) as usize];
            distinct += usize::from(!*mark);
            *mark = true;
        }
        counts[0].vertices = distinct;
        return distinct;
    }
    count_distinct(vertices);
    for &(shell, _) in vertices.iter() {
        counts[shell].vertices += 1;
    }
    let all = &mut scratch.all_vertices;
    all.clear();
    all.extend(vertices.iter().map(|&(_, v)| v));
    count_distinct(all)
}

/// How many different values `items` holds (sorting it).
fn count_distinct<T: Ord>(items: &mut Vec<T>) -> usize {
    items.sort_unstable();
    items.dedup();
    items.len()
}

/// The connected shells of a 3D subdomain's boundary; empty for a 2D region
/// or an id out of range.
pub fn shells(model: &Model, subdomain: SubdomainId) -> Vec<Shell> {
    let Some(SubdomainCells::Volume { boundary }) =
        model.subdomains.get(subdomain.index()).map(|s| &s.cells)
    else {
        return Vec::new();
    };
    let mut scratch = Scratch::default();
    let uses = EdgeUses::of(model, boundary, &mut scratch);
    shell_counts(model, boundary, &uses, &mut scratch);
    let mut shells: Vec<Shell> = (scratch.counts.iter())
        .map(|c| Shell {
            faces: Vec::with_capacity(c.faces),
            vertices: c.vertices,
            edges: c.edges,
            loops: c.loops,
        })
        .collect();
    for (entry, &shell) in scratch.component_of_entry.iter().enumerate() {
        if shell != usize::MAX {
            shells[shell].faces.push(boundary[entry].face);
        }
    }
    shells
}

/// E402/E403 (every edge used exactly twice), then, for 2-manifold
/// boundaries only (so one missing face does not cascade), E404 (consistent
/// outward orientation) and E405 (Euler–Poincaré per connected shell).
pub fn check_subdomain_shells(model: &Model, source_map: &SourceMap, diags: &mut Diagnostics) {
    // Each subdomain's shell is checked on its own, in parallel; the findings
    // are appended in subdomain order, so they do not depend on the threads.
    let findings: Vec<Diagnostics> = model
        .subdomains
        .par_iter()
        .enumerate()
        .with_min_len(SHELLS_PER_JOB)
        .map_init(Scratch::default, |scratch, (k, subdomain)| {
            let mut found = Diagnostics::default();
            check_shell(
                model,
                source_map,
                SubdomainId(k as u32),
                subdomain,
                scratch,
                &mut found,
            );
            found
        })
        .filter(|found| !found.items.is_empty())
        .collect();
    for found in findings {
        diags.extend(found);
    }
}

/// The checks of [`check_subdomain_shells`] for one subdomain.
fn check_shell(
    model: &Model,
    source_map: &SourceMap,
    id: SubdomainId,
    subdomain: &crate::ir::Subdomain,
    scratch: &mut Scratch,
    diags: &mut Diagnostics,
) {
    let SubdomainCells::Volume { boundary } = &subdomain.cells else {
        return;
    };
    // With trimmed faces the shell closes on the mesh (their chains are
    // made there); meshing checks it.
    if !subdomain.trimmed.is_empty() {
        return;
    }
    let uses = EdgeUses::of(model, boundary, scratch);
    check_edge_uses(
        model, source_map, id, subdomain, boundary, &uses, scratch, diags,
    );
    scratch.uses = uses.uses;
}

/// The checks of [`check_shell`] on the boundary's edge uses.
#[allow(clippy::too_many_arguments)]
fn check_edge_uses(
    model: &Model,
    source_map: &SourceMap,
    id: SubdomainId,
    subdomain: &crate::ir::Subdomain,
    boundary: &[OrientedFace],
    uses: &EdgeUses,
    scratch: &mut Scratch,
    diags: &mut Diagnostics,
) {
    let mut manifold = true;
    for (edge, list) in uses.lists() {
        // Looked up only for a finding: this runs for every edge of every subdomain.
        let span = || source_map.subdomain(id).or_else(|| source_map.edge(edge));
        match list.len() {
            2 => {}
            1 => {
                manifold = false;
                let face = face_name(model, boundary[list[0].1.entry()].face);
                diags.push(
                    Diagnostic::new(
                        Code::OpenShell,
                        span(),
                        format!(
                            "the boundary of subdomain '{}' is not closed: edge '{}' is used \
                             only by face '{face}'",
                            subdomain.name,
                            edge_name(model, edge)
                        ),
                    )
                    .with_help(format!(
                        "add the missing face across edge '{}' to subdomain '{}', or check \
                         that the neighbouring face names the same edge",
                        edge_name(model, edge),
                        subdomain.name
                    )),
                );
            }
            n => {
                manifold = false;
                let faces: BTreeSet<String> = list
                    .iter()
                    .map(|(_, u)| format!("'{}'", face_name(model, boundary[u.entry()].face)))
                    .collect();
                diags.push(
                    Diagnostic::new(
                        Code::NonManifoldEdge,
                        span(),
                        format!(
                            "edge '{}' is used {n} times in the boundary of subdomain '{}' \
                             (faces {}), more than twice",
                            edge_name(model, edge),
                            subdomain.name,
                            faces.into_iter().collect::<Vec<_>>().join(", ")
                        ),
                    )
                    .with_help(format!(
                        "split subdomain '{}' so that each edge of a boundary is shared by \
                         exactly two of its faces",
                        subdomain.name
                    )),
                );
            }
        }
    }
    if !manifold {
        return;
    }
    check_orientation(model, source_map, id, boundary, uses, scratch, diags);
    check_euler(model, source_map, id, boundary, uses, scratch, diags);
}

/// Two faces sharing an edge must traverse it in opposite directions once
/// their loops are taken as seen from outside (reversed for inward faces).
/// Solves for a relative flip per face (2-colouring); a contradiction means
/// the shell is one-sided, a solution that disagrees with the `outward` flags
/// names the faces whose flags (or loops) are wrong.
fn check_orientation(
    model: &Model,
    source_map: &SourceMap,
    id: SubdomainId,
    boundary: &[OrientedFace],
    uses: &EdgeUses,
    scratch: &mut Scratch,
    diags: &mut Diagnostics,
) {
    // The subdomain's name is copied only for a finding: this runs for every subdomain.
    let n = boundary.len();
    // Faces sharing an edge, both ways: (face a, face b, whether the flips
    // must differ, shared edge), in edge order.
    let pairs = || {
        uses.lists().filter_map(|(edge, list)| match list {
            [(_, a), (_, b)] if a.entry() != b.entry() => {
                Some((a, b, a.forward == b.forward, edge))
            }
            _ => None,
        })
    };
    // A seam used twice the same way by one face makes that face one-sided.
    let seam_conflict = &mut scratch.seam_conflict;
    seam_conflict.clear();
    seam_conflict.resize(n, None);
    for (edge, list) in uses.lists() {
        if let [(_, a), (_, b)] = list
            && a.entry() == b.entry()
            && a.forward == b.forward
        {
            seam_conflict[a.entry()].get_or_insert(edge);
        }
    }
    // (neighbour, whether the flips must differ, shared edge), each face's
    // neighbours in edge order, all in one vector.
    let start = &mut scratch.adjacent_start;
    start.clear();
    start.resize(n + 1, 0);
    for (a, b, _, _) in pairs() {
        start[a.entry() + 1] += 1;
        start[b.entry() + 1] += 1;
    }
    for i in 0..n {
        start[i + 1] += start[i];
    }
    let adjacent = &mut scratch.adjacent;
    adjacent.clear();
    adjacent.resize(start[n], (0, false, EdgeId(0)));
    // Filled at each face's next free slot: `members` counts them.
    let next = &mut scratch.members;
    next.clear();
    next.extend_from_slice(&start[..n]);
    for (a, b, differ, edge) in pairs() {
        adjacent[next[a.entry()]] = (b.entry(), differ, edge);
        next[a.entry()] += 1;
        adjacent[next[b.entry()]] = (a.entry(), differ, edge);
        next[b.entry()] += 1;
    }
    let (start, adjacent) = (&scratch.adjacent_start, &scratch.adjacent);
    let neighbours = |a: usize| &adjacent[start[a]..start[a + 1]];

    let flip = &mut scratch.flip;
    flip.clear();
    flip.resize(n, None);
    let members = &mut scratch.members;
    let queue = &mut scratch.queue;
    for first in 0..n {
        if flip[first].is_some() || boundary[first].face.index() >= model.faces.len() {
            continue;
        }
        flip[first] = Some(false);
        members.clear();
        members.push(first);
        queue.clear();
        queue.push_back(first);
        let mut conflict = seam_conflict[first];
        while let Some(a) = queue.pop_front() {
            let fa = flip[a].unwrap_or(false);
            for &(b, differ, edge) in neighbours(a) {
                match flip[b] {
                    None => {
                        flip[b] = Some(fa ^ differ);
                        conflict = conflict.or(seam_conflict[b]);
                        members.push(b);
                        queue.push_back(b);
                    }
                    Some(fb) if fb != fa ^ differ => {
                        conflict.get_or_insert(edge);
                    }
                    Some(_) => {}
                }
            }
        }

        if let Some(edge) = conflict {
            let name = subdomain_name(model, id);
            diags.push(
                Diagnostic::new(
                    Code::InconsistentOrientation,
                    source_map.subdomain(id),
                    format!(
                        "the boundary of subdomain '{name}' is one-sided: its faces cannot be \
                         oriented consistently (the contradiction closes at edge '{}')",
                        edge_name(model, edge)
                    ),
                )
                .with_help(
                    "check the faces' loops: a closed boundary has an inside and an outside, \
                     unlike a Möbius strip or a Klein bottle",
                ),
            );
            continue;
        }

        // Relative to the solved orientation, a face is "wrong" when its
        // outward flag disagrees; the minority is taken to be wrong, the first
        // listed face breaking a tie.
        let class = |e: usize| flip[e].unwrap_or(false) ^ !boundary[e].outward;
        let odd = members.iter().filter(|&&e| class(e)).count();
        if odd == 0 || odd == members.len() {
            continue;
        }
        let wrong = if 2 * odd == members.len() {
            !class(members[0])
        } else {
            2 * odd < members.len()
        };
        members.sort_unstable();
        let name = subdomain_name(model, id);
        for &e in members.iter().filter(|&&e| class(e) == wrong) {
            let face = boundary[e].face;
            let neighbour = neighbours(e).iter().find(|&&(b, _, _)| class(b) != wrong);
            let along = neighbour.map_or_else(String::new, |&(b, _, edge)| {
                format!(
                    ": it runs along edge '{}' in the same direction as face '{}'",
                    edge_name(model, edge),
                    face_name(model, boundary[b].face)
                )
            });
            diags.push(
                Diagnostic::new(
                    Code::InconsistentOrientation,
                    source_map.face(face).or_else(|| source_map.subdomain(id)),
                    format!(
                        "face '{}' is oriented against the rest of the boundary of subdomain \
                         '{name}' (normal taken {}){along}",
                        face_name(model, face),
                        if boundary[e].outward {
                            "outward"
                        } else {
                            "inward"
                        }
                    ),
                )
                .with_help(format!(
                    "reverse the loop of face '{}' so that it runs counter-clockwise seen from \
                     outside subdomain '{name}'",
                    face_name(model, face)
                )),
            );
        }
    }
}

/// E405 for every connected shell whose V − E + F − (L − F) is not 2(1 − G)
/// for a whole G ≥ 0.
fn check_euler(
    model: &Model,
    source_map: &SourceMap,
    id: SubdomainId,
    boundary: &[OrientedFace],
    uses: &EdgeUses,
    scratch: &mut Scratch,
    diags: &mut Diagnostics,
) {
    let distinct_vertices = shell_counts(model, boundary, uses, scratch);
    let shells = &scratch.counts;
    let shared_vertices = shells.iter().map(|s| s.vertices).sum::<usize>() - distinct_vertices;
    if shared_vertices > 0 && shells.iter().all(|s| s.genus().is_some()) {
        // Shells that touch only at vertices: each is a closed surface, but the
        // boundary is not a manifold there, and χ of the whole boundary shows it.
        let chi: i64 = shells
            .iter()
            .map(ShellCounts::euler_characteristic)
            .sum::<i64>()
            - shared_vertices as i64;
        let name = subdomain_name(model, id);
        diags.push(
            Diagnostic::new(
                Code::EulerMismatch,
                source_map.subdomain(id),
                format!(
                    "the boundary of subdomain '{name}' fails the Euler–Poincaré check: its {} shells share {shared_vertices} vertex{} so V − E + F − (L − F) = {chi}, not 2(S − G) for whole S, G",
                    shells.len(),
                    if shared_vertices == 1 { "" } else { "es" }
                ),
            )
            .with_help("shells of one subdomain must not touch; split it into two subdomains or separate the solids"),
        );
    }
    for shell in shells {
        if shell.genus().is_some() {
            continue;
        }
        let first = shell.first_face.map_or_else(String::new, |f| {
            format!(" (the shell with face '{}')", face_name(model, f))
        });
        let f = shell.faces;
        let name = subdomain_name(model, id);
        diags.push(
            Diagnostic::new(
                Code::EulerMismatch,
                source_map.subdomain(id),
                format!(
                    "the boundary of subdomain '{name}'{first} fails the Euler–Poincaré check: \
                     V − E + F − (L − F) = {} − {} + {f} − ({} − {f}) = {}, not 2(1 − G) for a \
                     whole G ≥ 0",
                    shell.vertices,
                    shell.edges,
                    shell.loops,
                    shell.euler_characteristic()
                ),
            )
            .with_help("check the faces of this shell for missing or extra edges and loops"),
        );
    }
}

/// E406 for faces listed by more than two 3D subdomains, then W004 for
/// explicit vertices, edges and faces that nothing uses. Entities of solids
/// are generated, so only those in the source map and in no solid count.
pub fn check_face_usage(model: &Model, source_map: &SourceMap, diags: &mut Diagnostics) {
    // Flag and count vectors indexed by id, not sets: this runs over every
    // entity of the model. Ids out of range are skipped (a malformed model).
    let n_faces = model.faces.len();
    let mut used_faces = vec![false; n_faces];
    let mut bounding_count = vec![0u32; n_faces];
    let mut last_subdomain = vec![u32::MAX; n_faces];
    for (k, subdomain) in model.subdomains.iter().enumerate() {
        match &subdomain.cells {
            SubdomainCells::Volume { boundary } => {
                for of in boundary {
                    let f = of.face.index();
                    if f >= n_faces {
                        continue;
                    }
                    used_faces[f] = true;
                    if last_subdomain[f] != k as u32 {
                        last_subdomain[f] = k as u32;
                        bounding_count[f] += 1;
                    }
                }
            }
            SubdomainCells::Region { faces } => {
                for f in faces {
                    if let Some(u) = used_faces.get_mut(f.index()) {
                        *u = true;
                    }
                }
            }
        }
    }
    for f in model.boundaries.iter().flat_map(|b| &b.faces) {
        if let Some(u) = used_faces.get_mut(f.index()) {
            *u = true;
        }
    }

    for (f, _) in bounding_count.iter().enumerate().filter(|(_, n)| **n > 2) {
        let face = FaceId(f as u32);
        let subdomains: BTreeSet<SubdomainId> = model
            .subdomains
            .iter()
            .enumerate()
            .filter(|(_, s)| match &s.cells {
                SubdomainCells::Volume { boundary } => boundary.iter().any(|of| of.face == face),
                SubdomainCells::Region { .. } => false,
            })
            .map(|(k, _)| SubdomainId(k as u32))
            .collect();
        let names: Vec<String> = subdomains
            .iter()
            .map(|&s| format!("'{}'", subdomain_name(model, s)))
            .collect();
        diags.push(
            Diagnostic::new(
                Code::TooManySubdomains,
                source_map.face(face),
                format!(
                    "face '{}' bounds {} subdomains ({}); a face separates at most two",
                    face_name(model, face),
                    subdomains.len(),
                    names.join(", ")
                ),
            )
            .with_help(format!(
                "keep face '{}' in the face lists of at most two of these subdomains",
                face_name(model, face)
            )),
        );
    }

    // Generic, not a `dyn Iterator`: it runs over every id of every entity
    // list, and a call per id was most of this check.
    fn flags(len: usize, ids: impl Iterator<Item = usize>) -> Vec<bool> {
        let mut flags = vec![false; len];
        for i in ids {
            if let Some(flag) = flags.get_mut(i) {
                *flag = true;
            }
        }
        flags
    }
    let in_solids_v = flags(
        model.vertices.len(),
        model
            .solids
            .iter()
            .flat_map(|s| &s.vertices)
            .map(|v| v.index()),
    );
    let in_solids_e = flags(
        model.edges.len(),
        model
            .solids
            .iter()
            .flat_map(|s| &s.edges)
            .map(|e| e.index()),
    );
    let in_solids_f = flags(
        n_faces,
        model
            .solids
            .iter()
            .flat_map(|s| &s.faces)
            .map(|of| of.face.index()),
    );
    // Which entities are used matters only for those of no solid: on a file
    // of primitives there are none, and these passes read every edge and
    // every face's loops again.
    let any_outside = |in_solids: &[bool]| in_solids.iter().any(|&f| !f);
    let used_vertices = any_outside(&in_solids_v).then(|| {
        flags(
            model.vertices.len(),
            model
                .edges
                .iter()
                .flat_map(|e| [e.begin.index(), e.end.index()]),
        )
    });
    let used_edges = any_outside(&in_solids_e).then(|| {
        flags(
            model.edges.len(),
            model
                .faces
                .iter()
                .flat_map(|f| f.loops.edges().iter().map(|oe| oe.edge.index())),
        )
    });
    // An entity of a solid is never reported, used or not.
    let unused_at = |in_solids: &[bool], used: &Option<Vec<bool>>, i: usize| {
        !in_solids[i] && !used.as_ref().is_some_and(|u| u[i])
    };

    let mut unused = |span: Option<Span>, message: String, help: &str| {
        diags.push(Diagnostic::new(Code::Dangling, span, message).with_help(help));
    };
    for (i, vertex) in model.vertices.iter().enumerate() {
        let id = VertexId(i as u32);
        let explicit_unused = unused_at(&in_solids_v, &used_vertices, i);
        if let Some(span) = explicit_unused.then(|| source_map.vertex(id)).flatten() {
            unused(
                Some(span),
                format!("vertex '{}' is not used by any edge", vertex.name),
                "remove the vertex, or use it as the begin or end of an edge",
            );
        }
    }
    for (i, edge) in model.edges.iter().enumerate() {
        let id = EdgeId(i as u32);
        let explicit_unused = unused_at(&in_solids_e, &used_edges, i);
        if let Some(span) = explicit_unused.then(|| source_map.edge(id)).flatten() {
            unused(
                Some(span),
                format!("edge '{}' is not used by any face", edge.name),
                "remove the edge, or list it in a face's loop",
            );
        }
    }
    for (i, face) in model.faces.iter().enumerate() {
        let id = FaceId(i as u32);
        let explicit_unused = !in_solids_f[i] && !used_faces[i];
        if let Some(span) = explicit_unused.then(|| source_map.face(id)).flatten() {
            unused(
                Some(span),
                format!(
                    "face '{}' is not used by any subdomain or boundary",
                    face.name
                ),
                "remove the face, or list it in a subdomain's faces",
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diag::Severity;
    use crate::geom::{Frame, Point3, SolidShape, Vec3};
    use crate::ir::{Dimension, OrientedEdge, Solid};
    use crate::valid::check_topology;
    use crate::valid::fixtures::{Builder, cube, sphere, torus};

    /// Box, ball, cone and torus shapes of random frames and sizes: radii
    /// of every sign, zero and NaN, so cones keep one, two or no rims.
    fn random_primitives(rng: &mut crate::test_rng::TestRng) -> Vec<SolidShape> {
        let size = |rng: &mut crate::test_rng::TestRng| match rng.below(6) {
            0 => 0.0,
            1 => -1.5,
            2 => f64::NAN,
            _ => rng.within(1_000) as f64 / 100.0,
        };
        let angles = Vec3::new(
            rng.within(180) as f64,
            rng.within(180) as f64,
            rng.within(180) as f64,
        );
        let shift = Vec3::new(rng.within(50) as f64, rng.within(50) as f64, 0.5);
        let frame = Frame::translation(shift).compose(&Frame::rotation_degrees(angles));
        vec![
            SolidShape::Box { frame },
            SolidShape::Ball { frame },
            SolidShape::Cone {
                frame,
                r0: size(rng),
                r1: size(rng),
            },
            SolidShape::Torus {
                frame,
                major: size(rng),
                minor: size(rng),
            },
            SolidShape::Disk { frame },
        ]
    }

    #[test]
    fn primitive_edges_are_closed_exactly_when_their_curves_are() {
        let mut rng = crate::test_rng::TestRng::new(0x5eed_0021);
        let mut closed = [0usize; 2];
        for _ in 0..400 {
            for shape in random_primitives(&mut rng) {
                for local in 0..14 {
                    let plain = (shape.edge_curve(local)).map(|c| curve_is_closed(&c, 1e-9));
                    assert_eq!(shape.edge_is_closed(local), plain, "{shape:?} edge {local}");
                    if let Some(c) = plain {
                        closed[usize::from(c)] += 1;
                    }
                }
            }
        }
        // 12 open edges per box; a ball's, a torus's two and the cones' rims closed.
        assert_eq!(closed[0], 400 * 12);
        assert!(closed[1] > 400 * 3, "{closed:?}");
    }

    #[test]
    fn closed_primitive_edges_are_judged_as_their_made_curves() {
        // Every edge of random primitives begins and ends at one vertex:
        // the boxes' segments are E400, the rest closed, whether the curve
        // is the solid's (judged from its shape) or made and owned.
        let mut rng = crate::test_rng::TestRng::new(0x0dd_ba11);
        let mut b = Builder::new(Dimension::Three);
        let v = b.vertex([0.0; 3]);
        for _ in 0..30 {
            for shape in random_primitives(&mut rng) {
                let solid = crate::ir::SolidId(b.model.solids.len() as u32);
                let edges = (0..).take_while(|&k| shape.edge_curve(k).is_some()).count();
                b.model.solids.push(Solid {
                    name: std::sync::Arc::new("s".into()),
                    shape,
                    faces: Box::new([]),
                    boundary_edges: Box::new([]),
                    edges: Box::new([]),
                    vertices: Box::new([]),
                });
                for local in 0..edges {
                    let id = b.push_edge(Curve::Chain { points: Vec::new() }, v, v);
                    b.model.edges[id.index()].carrier = Carrier::primitive(solid, local);
                }
            }
        }
        let mut from_shapes = Diagnostics::default();
        check_faces(&b.model, &b.map, &mut from_shapes);
        let solids = b.model.solids.clone();
        for edge in &mut b.model.edges {
            let curve = edge.curve(&solids).into_owned();
            edge.carrier = Carrier::own(curve);
        }
        let mut from_curves = Diagnostics::default();
        check_faces(&b.model, &b.map, &mut from_curves);
        assert_eq!(from_shapes.items, from_curves.items);
        assert_eq!(from_shapes.items.len(), 30 * 12);
        assert!(codes(&from_shapes).iter().all(|&c| c == "E400"));
        assert!(
            messages(&from_shapes)
                .iter()
                .all(|m| m.contains("a straight segment"))
        );
    }

    #[test]
    fn a_loop_breaks_where_a_lookup_of_both_neighbours_finds_it() {
        // Random edges among four vertices, random loops of one to six of
        // them: the first break, found with one lookup per edge, is the one
        // comparing each edge's head with the next one's tail finds.
        let mut rng = crate::test_rng::TestRng::new(0x100b_5eed);
        let mut b = Builder::new(Dimension::Three);
        let v: Vec<VertexId> = (0..4).map(|i| b.vertex([i as f64, 0.0, 0.0])).collect();
        for _ in 0..24 {
            let (a, z) = (v[rng.below(4)], v[rng.below(4)]);
            b.push_edge(Curve::Chain { points: Vec::new() }, a, z);
        }
        let mut found = [0usize; 2];
        for _ in 0..20_000 {
            let n = 1 + rng.below(6);
            let edges: Vec<OrientedEdge> = (0..n)
                .map(|_| OrientedEdge {
                    edge: EdgeId(rng.below(24) as u32),
                    forward: rng.below(2) == 0,
                })
                .collect();
            let step = |k: usize| loop_step(&b.model, edges[k]);
            let plain = (0..n).find(|&k| step(k).2 != step((k + 1) % n).1);
            assert_eq!(first_break(&b.model, &edges), plain, "{edges:?}");
            found[usize::from(plain.is_some())] += 1;
        }
        assert!(found[0] > 500 && found[1] > 10_000, "{found:?}");
    }

    fn codes(diags: &Diagnostics) -> Vec<&'static str> {
        diags.items.iter().map(|d| d.code.as_str()).collect()
    }

    fn messages(diags: &Diagnostics) -> Vec<&str> {
        diags.items.iter().map(|d| d.message.as_str()).collect()
    }

    fn face_id(b: &Builder, name: &str) -> FaceId {
        let i = b.model.faces.iter().position(|f| f.name == name);
        FaceId(i.expect("fixture face") as u32)
    }

    fn boundary_mut(b: &mut Builder, k: usize) -> &mut Vec<OrientedFace> {
        match &mut b.model.subdomains[k].cells {
            SubdomainCells::Volume { boundary } => boundary,
            SubdomainCells::Region { .. } => panic!("fixture is 3D"),
        }
    }

    #[test]
    fn cube_is_a_closed_sphere_like_shell() {
        let b = cube();
        assert_eq!(
            (
                b.model.vertices.len(),
                b.model.edges.len(),
                b.model.faces.len()
            ),
            (8, 12, 6)
        );
        let diags = check_topology(&b.model, &b.map);
        assert!(diags.items.is_empty(), "{:?}", messages(&diags));
        let shells = shells(&b.model, SubdomainId(0));
        assert_eq!(shells.len(), 1);
        let s = &shells[0];
        assert_eq!((s.vertices, s.edges, s.faces.len(), s.loops), (8, 12, 6, 6));
        assert_eq!(s.euler_characteristic(), 2);
        assert_eq!(s.genus(), Some(0));
    }

    #[test]
    fn cube_without_top_is_an_open_shell() {
        let mut b = cube();
        let top = face_id(&b, "box.top");
        boundary_mut(&mut b, 0).retain(|of| of.face != top);
        let mut diags = Diagnostics::default();
        check_subdomain_shells(&b.model, &b.map, &mut diags);
        assert_eq!(codes(&diags), ["E402"; 4]);
        let top_edges: BTreeSet<String> = b.model.faces[top.index()].loops[0]
            .iter()
            .map(|oe| format!("edge '{}'", edge_name(&b.model, oe.edge)))
            .collect();
        for d in &diags.items {
            assert!(
                top_edges.iter().any(|e| d.message.contains(e)),
                "{}",
                d.message
            );
            assert!(d.message.contains("subdomain 'box'"), "{}", d.message);
            assert!(d.help.is_some());
            assert_eq!(d.span, b.map.subdomain(SubdomainId(0)));
        }
        // e4 runs (0,0,1) → (1,0,1): the top's first edge, shared with the front.
        assert_eq!(
            diags.items[0].message,
            "the boundary of subdomain 'box' is not closed: edge 'e4' is used only by face \
             'box.front'"
        );
        // The unused top face is reported too, as a warning.
        let all = check_topology(&b.model, &b.map);
        assert_eq!(codes(&all), ["E402", "E402", "E402", "E402", "W004"]);
        assert_eq!(all.items[4].severity, Severity::Warning);
        assert!(all.items[4].message.contains("face 'box.top'"));
    }

    #[test]
    fn reversed_loop_is_named() {
        let mut b = cube();
        let top = face_id(&b, "box.top");
        let lp = &mut b.model.faces[top.index()].loops[0];
        lp.reverse();
        for oe in lp.iter_mut() {
            oe.forward = !oe.forward;
        }
        let diags = check_topology(&b.model, &b.map);
        assert_eq!(codes(&diags), ["E404"]);
        let d = &diags.items[0];
        assert!(
            d.message.starts_with("face 'box.top' is oriented against"),
            "{}",
            d.message
        );
        assert_eq!(d.span, b.map.face(top));
        assert!(d.help.as_deref().is_some_and(|h| h.contains("box.top")));
    }

    #[test]
    fn wrong_outward_flag_is_named() {
        let mut b = cube();
        let left = face_id(&b, "box.left");
        for of in boundary_mut(&mut b, 0)
            .iter_mut()
            .filter(|of| of.face == left)
        {
            of.outward = false;
        }
        let diags = check_topology(&b.model, &b.map);
        assert_eq!(codes(&diags), ["E404"]);
        assert!(diags.items[0].message.contains("face 'box.left'"));
        assert!(diags.items[0].message.contains("(normal taken inward)"));
    }

    #[test]
    fn two_cubes_sharing_a_face_are_valid() {
        let mut b = Builder::new(Dimension::Three);
        b.unit_box("A", [0.0; 3]);
        b.unit_box("B", [1.0, 0.0, 0.0]);
        assert_eq!(b.model.faces.len(), 11);
        let diags = check_topology(&b.model, &b.map);
        assert!(diags.items.is_empty(), "{:?}", messages(&diags));
    }

    #[test]
    fn cubes_sharing_an_edge_in_one_subdomain_are_non_manifold() {
        let mut b = Builder::new(Dimension::Three);
        let mut boundary = b.unit_box_faces("A", [0.0; 3]);
        boundary.extend(b.unit_box_faces("B", [1.0, 1.0, 0.0]));
        b.push_subdomain("both", SubdomainCells::Volume { boundary });
        let diags = check_topology(&b.model, &b.map);
        assert_eq!(codes(&diags), ["E403"]);
        let d = &diags.items[0];
        assert!(d.message.contains("is used 4 times"), "{}", d.message);
        assert!(d.message.contains("subdomain 'both'"), "{}", d.message);
    }

    #[test]
    fn torus_has_genus_one() {
        let b = torus(false);
        let diags = check_topology(&b.model, &b.map);
        assert!(diags.items.is_empty(), "{:?}", messages(&diags));
        let shells = shells(&b.model, SubdomainId(0));
        assert_eq!(shells.len(), 1);
        let s = &shells[0];
        assert_eq!((s.vertices, s.edges, s.faces.len(), s.loops), (1, 2, 1, 1));
        assert_eq!(s.euler_characteristic(), 0);
        assert_eq!(s.genus(), Some(1));
    }

    #[test]
    fn klein_bottle_is_one_sided() {
        let b = torus(true);
        let diags = check_topology(&b.model, &b.map);
        assert_eq!(codes(&diags), ["E404"]);
        assert!(diags.items[0].message.contains("one-sided"));
        assert!(diags.items[0].message.contains("edge 'm'"));
    }

    #[test]
    fn hemispheres_make_a_sphere() {
        let b = sphere();
        let diags = check_topology(&b.model, &b.map);
        assert!(diags.items.is_empty(), "{:?}", messages(&diags));
        let shells = shells(&b.model, SubdomainId(0));
        assert_eq!(shells.len(), 1);
        let s = &shells[0];
        assert_eq!((s.vertices, s.edges, s.faces.len(), s.loops), (1, 1, 2, 2));
        assert_eq!(s.euler_characteristic(), 2);
    }

    #[test]
    fn rings_make_a_handle_and_an_odd_count_fails_euler() {
        let mut b = cube();
        let v = b.vertex([0.5, 0.5, 1.0]);
        let ring = b.push_edge(
            Curve::Ellipse {
                center: Point3::new(0.5, 0.5, 1.0),
                major: Vec3::new(0.1, 0.0, 0.0),
                minor: Vec3::new(0.0, 0.1, 0.0),
                t0: 0.0,
                t1: std::f64::consts::TAU,
            },
            v,
            v,
        );
        // The same ring as an inner loop of the top and of the bottom glues
        // them into a handle: V − E + F − (L − F) = 9 − 13 + 6 − (8 − 6) = 0,
        // genus 1, accepted.
        let top = face_id(&b, "box.top");
        let bottom = face_id(&b, "box.bottom");
        b.model.faces[top.index()].loops.push(vec![OrientedEdge {
            edge: ring,
            forward: false,
        }]);
        b.model.faces[bottom.index()].loops.push(vec![OrientedEdge {
            edge: ring,
            forward: true,
        }]);
        let diags = check_topology(&b.model, &b.map);
        assert!(diags.items.is_empty(), "{:?}", messages(&diags));
        // One more ring on the top alone leaves χ odd: V 10, E 14, F 6, L 9.
        let w = b.vertex([0.2, 0.2, 1.0]);
        let lonely = b.push_edge(
            Curve::Ellipse {
                center: Point3::new(0.2, 0.2, 1.0),
                major: Vec3::new(0.05, 0.0, 0.0),
                minor: Vec3::new(0.0, 0.05, 0.0),
                t0: 0.0,
                t1: std::f64::consts::TAU,
            },
            w,
            w,
        );
        let twice = vec![
            OrientedEdge {
                edge: lonely,
                forward: false,
            },
            OrientedEdge {
                edge: lonely,
                forward: true,
            },
        ];
        // Traversed both ways in one loop, the lonely ring counts as used twice.
        b.model.faces[top.index()].loops.push(twice);
        let diags = check_topology(&b.model, &b.map);
        assert_eq!(codes(&diags), ["E405"]);
        assert_eq!(
            diags.items[0].message,
            "the boundary of subdomain 'box' (the shell with face 'box.bottom') fails the \
             Euler–Poincaré check: V − E + F − (L − F) = 10 − 14 + 6 − (9 − 6) = -1, not \
             2(1 − G) for a whole G ≥ 0"
        );
    }

    #[test]
    fn open_face_loop_names_the_break() {
        let mut b = cube();
        let front = face_id(&b, "box.front");
        b.model.faces[front.index()].loops[0].swap(1, 2);
        let diags = check_topology(&b.model, &b.map);
        assert_eq!(codes(&diags), ["E401"]);
        let d = &diags.items[0];
        assert_eq!(d.span, b.map.face(front));
        assert!(
            d.message
                .starts_with("the loop of face 'box.front' is not closed: edge 'e")
        );
        let lp = &b.model.faces[front.index()].loops[0];
        let expected = format!("edge '{}' ends at vertex", edge_name(&b.model, lp[0].edge));
        assert!(d.message.contains(&expected), "{}", d.message);
    }

    #[test]
    fn open_curve_with_coincident_ends() {
        let mut b = Builder::new(Dimension::Three);
        let v = b.vertex([0.0; 3]);
        let p = Point3::origin();
        let bad = b.push_edge(Curve::Segment { a: p, b: p }, v, v);
        let arc = Curve::Ellipse {
            center: Point3::new(1.0, 0.0, 0.0),
            major: Vec3::new(-1.0, 0.0, 0.0),
            minor: Vec3::new(0.0, 1.0, 0.0),
            t0: 0.0,
            t1: std::f64::consts::PI,
        };
        b.push_edge(arc, v, v);
        let mut diags = Diagnostics::default();
        check_faces(&b.model, &b.map, &mut diags);
        assert_eq!(codes(&diags), ["E400", "E400"]);
        assert_eq!(diags.items[0].span, b.map.edge(bad));
        assert_eq!(
            diags.items[0].message,
            "edge 'e0' begins and ends at vertex 'v0' but its curve is open (a straight segment)"
        );
        assert!(
            diags.items[1]
                .message
                .contains("an arc spanning 3.141593 rad")
        );
    }

    #[test]
    fn face_shared_by_three_subdomains() {
        let mut b = cube();
        let boundary = match &b.model.subdomains[0].cells {
            SubdomainCells::Volume { boundary } => boundary.clone(),
            SubdomainCells::Region { .. } => Vec::new(),
        };
        b.push_subdomain(
            "twin",
            SubdomainCells::Volume {
                boundary: boundary.clone(),
            },
        );
        b.push_subdomain("triplet", SubdomainCells::Volume { boundary });
        let mut diags = Diagnostics::default();
        check_face_usage(&b.model, &b.map, &mut diags);
        assert_eq!(codes(&diags), ["E406"; 6]);
        assert_eq!(
            diags.items[0].message,
            "face 'box.bottom' bounds 3 subdomains ('box', 'twin', 'triplet'); a face separates \
             at most two"
        );
    }

    #[test]
    fn unused_explicit_entities_warn_but_solid_entities_do_not() {
        let mut b = cube();
        let lonely = b.vertex([5.0, 5.0, 5.0]);
        let u = b.vertex([6.0, 5.0, 5.0]);
        let w = b.vertex([7.0, 5.0, 5.0]);
        b.segment(u, w);
        let generated = b.vertex([9.0, 9.0, 9.0]);
        b.model.solids.push(Solid {
            name: std::sync::Arc::new("ball".into()),
            shape: SolidShape::Ball {
                frame: Frame::identity(),
            },
            faces: Box::default(),
            boundary_edges: Box::default(),
            edges: Box::default(),
            vertices: Box::new([generated]),
        });
        // Not in the source map: not explicit, so not reported either.
        b.model.vertices.push(crate::ir::Vertex {
            name: "anon".into(),
            position: Point3::origin(),
        });
        let diags = check_topology(&b.model, &b.map);
        assert_eq!(codes(&diags), ["W004", "W004"]);
        assert_eq!(
            diags.items[0].message,
            "vertex 'v8' is not used by any edge"
        );
        assert_eq!(diags.items[0].span, b.map.vertex(lonely));
        assert_eq!(diags.items[1].message, "edge 'e12' is not used by any face");
    }

    #[test]
    fn malformed_ids_do_not_panic() {
        let mut b = cube();
        b.model.edges[0].begin = VertexId(99);
        let mut loops = b.model.faces[0].loops.to_vecs();
        loops[0].push(OrientedEdge {
            edge: EdgeId(77),
            forward: true,
        });
        b.model.faces[0].loops = loops.into();
        boundary_mut(&mut b, 0).push(OrientedFace {
            face: FaceId(55),
            outward: true,
        });
        b.model.boundaries.push(crate::ir::Boundary {
            name: "x".into(),
            faces: vec![FaceId(66)],
            edges: vec![EdgeId(88)],
        });
        let _ = check_topology(&b.model, &b.map);
        let _ = shells(&b.model, SubdomainId(0));
        let _ = shells(&b.model, SubdomainId(9));
        let _ = crate::ir::IncidenceMatrices::of(&b.model);
        let _ = crate::ir::derive_fragments(&b.model);
    }

    #[test]
    fn shell_findings_do_not_depend_on_the_threads() {
        // More subdomains than two parallel jobs take, each a unit cube with
        // one face left out: four E402 each, in subdomain order.
        let n = 2 * SHELLS_PER_JOB + 5;
        let mut b = Builder::new(Dimension::Three);
        for k in 0..n {
            let mut faces = b.unit_box_faces(&format!("b{k}"), [2.0 * k as f64, 0.0, 0.0]);
            faces.remove(k % 6);
            b.push_subdomain(&format!("d{k}"), SubdomainCells::Volume { boundary: faces });
        }
        let run = |threads: usize| {
            crate::test_threads::on_threads(threads, || check_topology(&b.model, &b.map))
        };
        let one = run(1);
        let open: Vec<&Diagnostic> = (one.items.iter())
            .filter(|d| d.code == Code::OpenShell)
            .collect();
        assert_eq!(open.len(), 4 * n);
        for (k, four) in open.chunks(4).enumerate() {
            for d in four {
                assert!(
                    d.message.contains(&format!("subdomain 'd{k}'")),
                    "{}",
                    d.message
                );
            }
        }
        assert_eq!(run(4).items, one.items);
    }

    /// Uses of random edges in `low..low + span`, with random entries and directions.
    fn random_uses(seed: u64, len: usize, low: u32, span: u32) -> Vec<(EdgeId, EdgeUse)> {
        let mut state = seed;
        let mut next = move || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (state >> 33) as u32
        };
        (0..len)
            .map(|_| {
                let edge = EdgeId(low + next() % span);
                let entry = next() % 16;
                let forward = next() % 2 == 0;
                (edge, EdgeUse { entry, forward })
            })
            .collect()
    }

    fn plain(uses: &[(EdgeId, EdgeUse)]) -> Vec<(u32, usize, bool)> {
        uses.iter()
            .map(|(e, u)| (e.0, u.entry(), u.forward))
            .collect()
    }

    #[test]
    fn bucketed_edge_uses_are_a_stable_sort_by_edge() {
        let mut starts = Vec::new();
        let mut bucketed = Vec::new();
        for (seed, len, low, span) in [
            (1, 24, 0, 12),
            (2, 60, 9000, 40),
            (3, 7, 5, 1),
            (4, 300, 17, 900),
        ] {
            let unsorted = random_uses(seed, len, low, span);
            let mut sorted = unsorted.clone();
            sorted.sort_by_key(|&(edge, _)| edge);
            bucket_by_edge(&unsorted, low, span as usize, &mut starts, &mut bucketed);
            assert_eq!(plain(&bucketed), plain(&sorted), "seed {seed}");
            // Repeated edges keep their uses' order: the entries of one edge
            // in `unsorted` order.
            assert!(bucketed.windows(2).any(|w| w[0].0 == w[1].0));
        }
    }

    /// `b`'s model with vertex `v` renumbered `v · gap` and edge `e`
    /// renumbered `e · gap` (unused fillers between), so that a shell's ids
    /// span far more than its uses and are sorted rather than bucketed.
    fn spread(b: &Builder, gap: u32) -> crate::ir::Model {
        let mut model = b.model.clone();
        let filler_vertex = model.vertices[0].clone();
        let filler_edge = model.edges[0].clone();
        let vertex = |v: VertexId| VertexId(v.0 * gap);
        let edge = |e: EdgeId| EdgeId(e.0 * gap);
        model.vertices = (0..b.model.vertices.len() as u32 * gap)
            .map(|k| match k % gap {
                0 => b.model.vertices[(k / gap) as usize].clone(),
                _ => filler_vertex.clone(),
            })
            .collect();
        model.edges = (0..b.model.edges.len() as u32 * gap)
            .map(|k| {
                let mut e = match k % gap {
                    0 => b.model.edges[(k / gap) as usize].clone(),
                    _ => filler_edge.clone(),
                };
                (e.begin, e.end) = (vertex(e.begin), vertex(e.end));
                e
            })
            .collect();
        for face in &mut model.faces {
            for oe in face.loops.edges_mut() {
                oe.edge = edge(oe.edge);
            }
        }
        model
    }

    #[test]
    fn shells_spread_over_far_ids_count_as_close_ones() {
        let mut open = cube();
        let top = face_id(&open, "box.top");
        boundary_mut(&mut open, 0).retain(|of| of.face != top);
        let mut two = Builder::new(Dimension::Three);
        let mut faces = two.unit_box_faces("a", [0.0; 3]);
        faces.extend(two.unit_box_faces("b", [3.0, 0.0, 0.0]));
        two.push_subdomain("ab", SubdomainCells::Volume { boundary: faces });
        for (name, b, counts) in [
            ("cube", cube(), vec![(8, 12, 6, 6)]),
            ("open cube", open, vec![]),
            ("torus", torus(false), vec![(1, 2, 1, 1)]),
            ("klein bottle", torus(true), vec![]),
            ("sphere", sphere(), vec![(1, 1, 2, 2)]),
            ("two cubes", two, vec![(8, 12, 6, 6), (8, 12, 6, 6)]),
        ] {
            let close = &b.model;
            let far = spread(&b, 100);
            let found = |model: &crate::ir::Model| {
                let mut diags = Diagnostics::default();
                check_subdomain_shells(model, &b.map, &mut diags);
                (diags.items.iter())
                    .map(|d| (d.code, d.message.clone()))
                    .collect::<Vec<_>>()
            };
            assert_eq!(found(&far), found(close), "{name}");
            let shells_of = |model: &crate::ir::Model| {
                shells(model, SubdomainId(0))
                    .iter()
                    .map(|s| (s.vertices, s.edges, s.faces.len(), s.loops))
                    .collect::<Vec<_>>()
            };
            assert_eq!(shells_of(&far), shells_of(close), "{name}");
            if !counts.is_empty() {
                assert_eq!(shells_of(close), counts, "{name}");
            }
        }
    }
}
