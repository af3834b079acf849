//! What several writers share: the mesh check that lets them index without
//! panicking, the groups viewer formats show (fragments, subdomain surfaces,
//! faces, edges), triangles oriented out of a fragment's subdomain, and
//! vertex normals that are smooth within a face and flat across its edges.

use super::WriteError;
use super::mesh_facts::MeshFacts;
use crate::mesh::Mesh;
use rayon::prelude::*;
use std::borrow::Cow;

/// Rejects a mesh whose indices leave their tables or whose coordinates are
/// not finite. After it, writers may index the mesh's tables directly.
pub(crate) fn check(mesh: &Mesh) -> Result<(), WriteError> {
    check_scanned(mesh, false).map(|_| ())
}

/// What [`check_scanned`] learned on its way, for a writer that needs it:
/// found in the same passes over the nodes and triangles as the checks.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct Scanned {
    /// Per face: [`identity_prefix`] of its triangles.
    pub identity: Vec<Option<usize>>,
    /// The bounds of all nodes (`None` without nodes).
    pub bounds: Option<Bounds>,
    /// Per face: its `node_window::block_ranges` when a reader found them
    /// (else empty, or `None`).
    pub blocks: Vec<Option<Vec<(u32, u32)>>>,
}

/// The smallest and the largest coordinates of some nodes.
pub(crate) type Bounds = ([f64; 3], [f64; 3]);

/// [`check`]; with `scan`, also each face's [`identity_prefix`] (from the
/// pass that finds its largest index) and the nodes' bounds (from the pass
/// that looks for a coordinate that is not finite), which the glTF writer
/// needs: two passes over the mesh fewer than finding them after it.
pub(crate) fn check_scanned(mesh: &Mesh, scan: bool) -> Result<Scanned, WriteError> {
    check_with(mesh, if scan { Scans::Writer } else { Scans::None })
}

/// [`check_scanned`] with scanning for a mesh a reader has summed up: the
/// nodes' bounds, each face's order and largest node come from `facts`
/// (which also say every coordinate is finite) instead of two passes over
/// the mesh. Facts that do not fit the mesh are not used.
pub(crate) fn check_known(mesh: &Mesh, facts: &MeshFacts) -> Result<Scanned, WriteError> {
    if !facts.fits(mesh) {
        return check_scanned(mesh, true);
    }
    check_with(mesh, Scans::Known(facts))
}

/// Where [`check_with`] takes the nodes' and faces' scans from.
#[derive(Clone, Copy)]
enum Scans<'f> {
    /// Finite coordinates and largest indices only.
    None,
    /// Also the bounds and each face's order, scanned here.
    Writer,
    /// All of it from a reader's facts.
    Known(&'f MeshFacts),
}

fn check_with(mesh: &Mesh, scans: Scans) -> Result<Scanned, WriteError> {
    let bad = |what: String| Err(WriteError::InvalidMesh(what));
    if mesh.dimension != 2 && mesh.dimension != 3 {
        return bad(format!("dimension {} (2 or 3 expected)", mesh.dimension));
    }
    if u32::try_from(mesh.nodes.len()).is_err() {
        return bad(format!(
            "{} nodes: more than u32 can number",
            mesh.nodes.len()
        ));
    }
    let mut scanned = Scanned::default();
    let non_finite = match scans {
        Scans::None => first_non_finite(&mesh.nodes),
        Scans::Writer => {
            let (first, bounds) = nodes_scan(&mesh.nodes);
            scanned.bounds = bounds;
            first
        }
        Scans::Known(facts) => {
            scanned.bounds = facts.bounds;
            None
        }
    };
    if let Some(i) = non_finite {
        return bad(format!("node {i} has a coordinate that is not finite"));
    }
    let n = mesh.nodes.len();
    let node_ok = |v: &u32| (*v as usize) < n;
    for v in &mesh.vertices {
        if !node_ok(&v.node) {
            return bad(format!(
                "vertex `{}` refers to node {} of {n}",
                v.name, v.node
            ));
        }
    }
    for e in &mesh.edges {
        if !e.nodes.iter().all(node_ok) {
            return bad(format!("edge `{}` refers to a node out of range", e.name));
        }
    }
    for (i, f) in mesh.faces.iter().enumerate() {
        let largest = match scans {
            Scans::None => largest_index(&f.triangles),
            Scans::Writer => {
                let order = FirstUse::of(&f.triangles);
                scanned.identity.push(order.identity());
                order.largest()
            }
            Scans::Known(facts) => {
                // `fits` said there is one per face.
                let known = &facts.faces[i];
                scanned.identity.push(known.order.identity());
                scanned.blocks.push(Some(known.blocks.clone()));
                known.largest()
            }
        };
        if !f.triangles.is_empty() && !node_ok(&largest) {
            return bad(format!("face `{}` refers to a node out of range", f.name));
        }
        if f.boundary
            .iter()
            .any(|(e, _)| *e as usize >= mesh.edges.len())
        {
            return bad(format!(
                "face `{}` is bounded by an edge out of range",
                f.name
            ));
        }
    }
    for s in &mesh.subdomains {
        if s.faces.iter().any(|(f, _)| *f as usize >= mesh.faces.len()) {
            return bad(format!("subdomain `{}` lists a face out of range", s.name));
        }
    }
    let nd = mesh.subdomains.len();
    for fr in &mesh.fragments {
        let sides_ok = (fr.subdomain as usize) < nd && fr.other.is_none_or(|o| (o as usize) < nd);
        if !sides_ok
            || fr.faces.iter().any(|f| *f as usize >= mesh.faces.len())
            || fr.edges.iter().any(|e| *e as usize >= mesh.edges.len())
        {
            return bad(format!(
                "fragment `{}` refers to an entity out of range",
                fr.name
            ));
        }
    }
    for v in &mesh.volumes {
        if v.nodes.len() % v.kind.corners() != 0 || !v.nodes.iter().all(node_ok) {
            return bad(format!(
                "volume `{}` has a cell with a node out of range or missing",
                v.name
            ));
        }
    }
    for p in mesh.polylines.iter().chain(&mesh.point_sets) {
        if !p.nodes.iter().all(node_ok) {
            return bad(format!("`{}` refers to a node out of range", p.name));
        }
    }
    Ok(scanned)
}

/// What a group stands for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Source {
    Fragment(u32),
    Subdomain(u32),
    Face(u32),
    Edge(u32),
    Polyline(u32),
}

/// Triangles of some faces, each face flipped or not.
#[derive(Debug, Clone)]
pub(crate) struct SurfaceGroup<'a> {
    pub name: &'a str,
    pub source: Source,
    /// (face, flip): flip reverses the face's triangles.
    pub faces: Vec<(u32, bool)>,
}

/// Line segments (node pairs).
#[derive(Debug, Clone)]
pub(crate) struct LineGroup<'a> {
    pub name: &'a str,
    pub source: Source,
    pub segments: Vec<[u32; 2]>,
}

/// The surface partition viewers show: in 3D one group per fragment, faces
/// oriented out of the fragment's first subdomain; in 2D one per region
/// subdomain. Faces in no such group get a group each, so every triangle is
/// shown once (a mesh without subdomains gives one group per face).
pub(crate) fn surface_groups(mesh: &Mesh) -> Vec<SurfaceGroup<'_>> {
    let mut covered = vec![false; mesh.faces.len()];
    let mut groups = Vec::new();
    if mesh.dimension == 3 {
        for (i, fr) in mesh.fragments.iter().enumerate() {
            let faces = fr
                .faces
                .iter()
                .map(|&f| (f, !outward(mesh, fr.subdomain, f)))
                .collect();
            for &f in &fr.faces {
                covered[f as usize] = true;
            }
            groups.push(SurfaceGroup {
                name: &fr.name,
                source: Source::Fragment(i as u32),
                faces,
            });
        }
    } else {
        for (i, s) in mesh.subdomains.iter().enumerate() {
            for &(f, _) in &s.faces {
                covered[f as usize] = true;
            }
            groups.push(SurfaceGroup {
                name: &s.name,
                source: Source::Subdomain(i as u32),
                faces: s.faces.iter().map(|&(f, _)| (f, false)).collect(),
            });
        }
    }
    for (i, face) in mesh.faces.iter().enumerate() {
        if !covered[i] {
            groups.push(SurfaceGroup {
                name: &face.name,
                source: Source::Face(i as u32),
                faces: vec![(i as u32, false)],
            });
        }
    }
    groups
}

/// 3D only: each subdomain's whole boundary, oriented outward.
pub(crate) fn subdomain_surfaces(mesh: &Mesh) -> Vec<SurfaceGroup<'_>> {
    if mesh.dimension != 3 {
        return Vec::new();
    }
    mesh.subdomains
        .iter()
        .enumerate()
        .map(|(i, s)| SurfaceGroup {
            name: &s.name,
            source: Source::Subdomain(i as u32),
            faces: s.faces.iter().map(|&(f, out)| (f, !out)).collect(),
        })
        .collect()
}

/// Whether `face` is listed outward in `subdomain` (true when not listed: the
/// face's own orientation is then the only one there is).
fn outward(mesh: &Mesh, subdomain: u32, face: u32) -> bool {
    mesh.subdomains
        .get(subdomain as usize)
        .and_then(|s| s.faces.iter().find(|(f, _)| *f == face))
        .is_none_or(|(_, out)| *out)
}

/// Line groups: in 2D the fragments (their edges), then every edge in no
/// fragment; in 3D every edge; then the poly_lines.
pub(crate) fn line_groups(mesh: &Mesh) -> Vec<LineGroup<'_>> {
    let mut groups = Vec::new();
    let mut covered = vec![false; mesh.edges.len()];
    if mesh.dimension == 2 {
        for (i, fr) in mesh.fragments.iter().enumerate() {
            let segments = fr
                .edges
                .iter()
                .flat_map(|&e| segments(&mesh.edges[e as usize].nodes))
                .collect();
            for &e in &fr.edges {
                covered[e as usize] = true;
            }
            groups.push(LineGroup {
                name: &fr.name,
                source: Source::Fragment(i as u32),
                segments,
            });
        }
    }
    for (i, edge) in mesh.edges.iter().enumerate() {
        if !covered[i] {
            groups.push(LineGroup {
                name: &edge.name,
                source: Source::Edge(i as u32),
                segments: segments(&edge.nodes),
            });
        }
    }
    for (i, p) in mesh.polylines.iter().enumerate() {
        groups.push(LineGroup {
            name: &p.name,
            source: Source::Polyline(i as u32),
            segments: segments(&p.nodes),
        });
    }
    groups
}

/// Consecutive node pairs of a polyline.
pub(crate) fn segments(nodes: &[u32]) -> Vec<[u32; 2]> {
    nodes.windows(2).map(|w| [w[0], w[1]]).collect()
}

/// A face's triangles in the requested orientation.
pub(crate) fn oriented(mesh: &Mesh, face: u32, flip: bool) -> impl Iterator<Item = [u32; 3]> + '_ {
    mesh.faces[face as usize]
        .triangles
        .iter()
        .map(move |&[a, b, c]| if flip { [a, c, b] } else { [a, b, c] })
}

/// A group's triangles with vertices of their own: a mesh node used by two
/// faces becomes two vertices, so normals are smooth within a face and flat
/// across the edges between faces (the creases).
#[derive(Debug, Default)]
pub(crate) struct Expanded<'a> {
    pub normals: Vec<[f64; 3]>,
    /// The mesh node each vertex copies; `None` when vertex `i` is node `i`.
    nodes: Option<Vec<u32>>,
    pub triangles: Cow<'a, [[u32; 3]]>,
}

impl Expanded<'_> {
    /// The mesh node a vertex copies.
    pub(crate) fn node(&self, vertex: usize) -> u32 {
        match &self.nodes {
            Some(nodes) => nodes[vertex],
            None => vertex as u32,
        }
    }
}

/// What a group's expansion will hold, found without building it: its
/// vertex and triangle counts and the `f32` bounds of its positions (what a
/// glTF accessor states before its bytes are written).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Measure {
    pub vertices: usize,
    pub triangles: usize,
    pub lo: [f32; 3],
    pub hi: [f32; 3],
    /// `Some(k)`: one face as it is whose nodes are `0..k` in first-use
    /// order (the expansion copies nothing), found once for the writer.
    pub identity: Option<usize>,
}

/// A normal sum made unit as [`node_normals`] makes it (`fallback` for a
/// zero sum), then `f32`: what a writer streaming the sums writes.
pub(crate) fn unit_f32(sum: [f64; 3], fallback: [f64; 3]) -> [f32; 3] {
    unit(sum).unwrap_or(fallback).map(|c| c as f32)
}

/// Expands groups of one mesh: each node's vertex in the current face sits in
/// a table indexed by node, valid while its stamp is the face's, so no hash
/// map is built per face and the table is reused across calls.
pub(crate) struct Expander<'a> {
    mesh: &'a Mesh,
    /// Made on first use: the common single-face case needs none.
    slot: Vec<(u32, u32)>,
    stamp: u32,
    /// What the mesh's check found, if it scanned ([`check_scanned`]).
    scanned: Option<&'a Scanned>,
}

impl<'a> Expander<'a> {
    pub(crate) fn new(mesh: &'a Mesh) -> Expander<'a> {
        Expander {
            mesh,
            slot: Vec::new(),
            stamp: 0,
            scanned: None,
        }
    }

    /// An expander that measures with what [`check_scanned`] found on
    /// `mesh` instead of scanning again.
    pub(crate) fn scanned(mesh: &'a Mesh, scanned: &'a Scanned) -> Expander<'a> {
        Expander {
            scanned: Some(scanned),
            ..Expander::new(mesh)
        }
    }

    pub(crate) fn expand(&mut self, faces: &[(u32, bool)]) -> Expanded<'a> {
        if let [(face, false)] = faces {
            // One face as it is whose nodes first appear in their own order
            // (an STL solid, a mesh written face by face): its vertices are
            // the mesh's first nodes, so nothing is copied.
            let mesh = self.mesh;
            let triangles = &mesh.faces[*face as usize].triangles;
            if let Some(used) = identity_prefix(triangles) {
                return Expanded {
                    normals: node_normals(mesh, triangles, used),
                    nodes: None,
                    triangles: Cow::Borrowed(triangles),
                };
            }
        }
        self.prepare();
        expand_into(self, faces)
    }

    /// The counts and bounds [`Expander::expand`] would give, with one
    /// stamped pass over the corners and no vertex copied.
    pub(crate) fn measure(&mut self, faces: &[(u32, bool)]) -> Measure {
        let mesh = self.mesh;
        let mut m = Measure {
            vertices: 0,
            triangles: 0,
            lo: [f32::INFINITY; 3],
            hi: [f32::NEG_INFINITY; 3],
            identity: None,
        };
        let include = |m: &mut Measure, node: u32| {
            for (k, &c) in mesh.nodes[node as usize].iter().enumerate() {
                let c = c as f32;
                m.lo[k] = m.lo[k].min(c);
                m.hi[k] = m.hi[k].max(c);
            }
        };
        if let [(face, false)] = faces {
            let triangles = &mesh.faces[*face as usize].triangles;
            let identity = match self.scanned {
                Some(s) => s.identity.get(*face as usize).copied().flatten(),
                None => identity_prefix(triangles),
            };
            if let Some(used) = identity {
                m.identity = Some(used);
                m.vertices = used;
                m.triangles = triangles.len();
                // Bounds in `f64`, converted once: rounding to `f32` never
                // changes the order of two values, so the converted bounds
                // are the bounds of the converted values.
                let all = self
                    .scanned
                    .and_then(|s| s.bounds)
                    .filter(|_| used == mesh.nodes.len());
                let (lo, hi) = all.unwrap_or_else(|| {
                    let mut lo = [f64::INFINITY; 3];
                    let mut hi = [f64::NEG_INFINITY; 3];
                    for p in &mesh.nodes[..used] {
                        for k in 0..3 {
                            lo[k] = lo[k].min(p[k]);
                            hi[k] = hi[k].max(p[k]);
                        }
                    }
                    (lo, hi)
                });
                if used > 0 {
                    m.lo = lo.map(|c| c as f32);
                    m.hi = hi.map(|c| c as f32);
                }
                return m;
            }
        }
        self.prepare();
        for &(face, _) in faces {
            let stamp = self.next_stamp();
            let triangles = &mesh.faces[face as usize].triangles;
            m.triangles += triangles.len();
            for &node in triangles.as_flattened() {
                let entry = &mut self.slot[node as usize];
                if entry.0 != stamp {
                    *entry = (stamp, 0);
                    m.vertices += 1;
                    include(&mut m, node);
                }
            }
        }
        m
    }

    /// The vertices [`Expander::expand`] would make for these faces, in its
    /// order, as the mesh node each copies: nothing is stored (a glTF
    /// writer streams their positions).
    pub(crate) fn each_vertex<E>(
        &mut self,
        faces: &[(u32, bool)],
        mut vertex: impl FnMut(u32) -> Result<(), E>,
    ) -> Result<(), E> {
        self.prepare();
        for &(face, flip) in faces {
            let stamp = self.next_stamp();
            for tri in oriented(self.mesh, face, flip) {
                for node in tri {
                    let entry = &mut self.slot[node as usize];
                    if entry.0 != stamp {
                        *entry = (stamp, 0);
                        vertex(node)?;
                    }
                }
            }
        }
        Ok(())
    }

    /// The unit normals [`Expander::expand`] would give these faces'
    /// vertices, in its order (the same sums in `f64`, face by face): only
    /// one face's sums are held, in `sums`.
    pub(crate) fn each_normal<E>(
        &mut self,
        faces: &[(u32, bool)],
        sums: &mut Vec<[f64; 3]>,
        mut normal: impl FnMut([f64; 3]) -> Result<(), E>,
    ) -> Result<(), E> {
        let mesh = self.mesh;
        self.prepare();
        for &(face, flip) in faces {
            let stamp = self.next_stamp();
            sums.clear();
            let mut total = [0.0; 3];
            for tri in oriented(mesh, face, flip) {
                let n = triangle_normal(mesh, tri);
                total = add(total, n);
                for node in tri {
                    let entry = &mut self.slot[node as usize];
                    if entry.0 != stamp {
                        *entry = (stamp, sums.len() as u32);
                        sums.push([0.0; 3]);
                    }
                    let s = &mut sums[entry.1 as usize];
                    *s = add(*s, n);
                }
            }
            let fallback = unit(total).unwrap_or([0.0, 0.0, 1.0]);
            for s in sums.iter() {
                normal(unit(*s).unwrap_or(fallback))?;
            }
        }
        Ok(())
    }

    /// The triangles [`Expander::expand`] would give, renumbered onto its
    /// vertices, in its order, without storing them.
    pub(crate) fn each_triangle<E>(
        &mut self,
        faces: &[(u32, bool)],
        mut triangle: impl FnMut([u32; 3]) -> Result<(), E>,
    ) -> Result<(), E> {
        self.prepare();
        let mut count = 0u32;
        for &(face, flip) in faces {
            let stamp = self.next_stamp();
            for tri in oriented(self.mesh, face, flip) {
                let mut t = [0u32; 3];
                for (k, node) in tri.into_iter().enumerate() {
                    let entry = &mut self.slot[node as usize];
                    if entry.0 != stamp {
                        *entry = (stamp, count);
                        count += 1;
                    }
                    t[k] = entry.1;
                }
                triangle(t)?;
            }
        }
        Ok(())
    }

    /// The mesh it expands.
    pub(crate) fn mesh(&self) -> &'a Mesh {
        self.mesh
    }

    /// The node table, made on first use (the single-face case needs none).
    fn prepare(&mut self) {
        if self.slot.len() != self.mesh.nodes.len() {
            self.slot = vec![(u32::MAX, 0); self.mesh.nodes.len()];
            self.stamp = 0;
        }
    }

    /// A fresh stamp for the next face (the table is cleared when they run out).
    fn next_stamp(&mut self) -> u32 {
        if self.stamp == u32::MAX - 1 {
            self.slot.fill((u32::MAX, 0));
            self.stamp = 0;
        }
        self.stamp += 1;
        self.stamp
    }
}

/// `Some(k)` when the triangles use nodes `0..k` and each first appears after
/// all smaller ones (the order the expansion would number them in): every
/// index is at most one more than the largest before it. Parts of the
/// indices are summed up on their own ([`FirstUse`]); a part passes when
/// its indices beyond its own largest so far are covered by the largest
/// of the parts before it.
fn identity_prefix(triangles: &[[u32; 3]]) -> Option<usize> {
    FirstUse::of(triangles).identity()
}

/// Indices per parallel piece of [`FirstUse::of`].
const FIRST_USE_PIECE: usize = 1 << 16;

/// Parts [`FirstUse::piece`] scans side by side.
const LANES: usize = 4;

/// How some indices follow first-use order, summed up so that the
/// summaries of consecutive parts combine ([`FirstUse::then`]).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct FirstUse {
    /// One more than the largest index (0: none).
    top: u64,
    /// The largest index that came before its turn: the parts before must
    /// reach it (0: none).
    need: u64,
}

impl FirstUse {
    /// The summary of the triangles' indices, from parallel pieces.
    fn of(triangles: &[[u32; 3]]) -> FirstUse {
        triangles
            .as_flattened()
            .par_chunks(FIRST_USE_PIECE)
            .map(FirstUse::piece)
            .reduce(FirstUse::default, FirstUse::then)
    }

    /// The indices follow first-use order: `Some(k)`, they are `0..k`.
    pub(crate) fn identity(self) -> Option<usize> {
        if self.need > 0 {
            return None;
        }
        usize::try_from(self.top).ok()
    }

    /// The largest index (0 when there is none).
    pub(crate) fn largest(self) -> u32 {
        u32::try_from(self.top.saturating_sub(1)).unwrap_or(u32::MAX)
    }

    /// This part, then `later`.
    pub(crate) fn then(self, later: FirstUse) -> FirstUse {
        let early = if later.need > self.top { later.need } else { 0 };
        FirstUse {
            top: self.top.max(later.top),
            need: self.need.max(early),
        }
    }

    /// One piece, cut into [`LANES`] parts scanned side by side, each with
    /// its own largest index so far (one chain of dependent steps per part
    /// instead of one for all: the single chain was 80% of the writer's
    /// measuring pass).
    pub(crate) fn piece(values: &[u32]) -> FirstUse {
        let part = values.len().div_ceil(LANES).max(1);
        let mut lanes = [FirstUse::default(); LANES];
        let mut parts = values.chunks(part);
        let heads: [&[u32]; LANES] = std::array::from_fn(|_| parts.next().unwrap_or_default());
        let together = heads.iter().map(|h| h.len()).min().unwrap_or(0);
        let [a, b, c, d] = heads.map(|h| h.get(..together).unwrap_or_default());
        for (((&a, &b), &c), &d) in a.iter().zip(b).zip(c).zip(d) {
            for (lane, v) in lanes.iter_mut().zip([a, b, c, d]) {
                lane.step(v);
            }
        }
        for (lane, head) in lanes.iter_mut().zip(&heads) {
            for &v in head.get(together..).unwrap_or_default() {
                lane.step(v);
            }
        }
        lanes.into_iter().fold(FirstUse::default(), FirstUse::then)
    }

    #[inline(always)]
    fn step(&mut self, v: u32) {
        let v = u64::from(v);
        let early = if v > self.top { v } else { 0 };
        self.need = self.need.max(early);
        self.top = self.top.max(v + 1);
    }
}

/// [`first_non_finite`] and the nodes' bounds, in one pass of parallel
/// pieces (no bounds when a coordinate is not finite, or without nodes).
pub(crate) fn nodes_scan(nodes: &[[f64; 3]]) -> (Option<usize>, Option<Bounds>) {
    const RUN: usize = 1024;
    type Run = (bool, [f64; 3], [f64; 3]);
    let empty: Run = (false, [f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    let (bad, lo, hi) = nodes
        .par_chunks(RUN)
        .with_min_len(64)
        .map(|run| {
            run.iter().fold(empty, |(bad, lo, hi), p| {
                (
                    bad | !(p[0].is_finite() & p[1].is_finite() & p[2].is_finite()),
                    std::array::from_fn(|k| lo[k].min(p[k])),
                    std::array::from_fn(|k| hi[k].max(p[k])),
                )
            })
        })
        .reduce(
            || empty,
            |a, b| {
                (
                    a.0 | b.0,
                    std::array::from_fn(|k| a.1[k].min(b.1[k])),
                    std::array::from_fn(|k| a.2[k].max(b.2[k])),
                )
            },
        );
    if bad {
        return (first_non_finite(nodes), None);
    }
    (None, (!nodes.is_empty()).then_some((lo, hi)))
}

/// The first node with a coordinate that is not finite. Runs of nodes are
/// scanned in parallel, each with no early exit inside, so the compiler
/// vectorises it.
pub(crate) fn first_non_finite(nodes: &[[f64; 3]]) -> Option<usize> {
    const RUN: usize = 1024;
    let r = nodes
        .par_chunks(RUN)
        .with_min_len(64)
        .position_first(|run| {
            run.as_flattened()
                .iter()
                .fold(false, |bad, c| bad | !c.is_finite())
        })?;
    let run = nodes.get(r * RUN..)?;
    let i = run.iter().position(|p| p.iter().any(|c| !c.is_finite()));
    i.map(|i| r * RUN + i)
}

/// The largest node index of some triangles (0 when there are none), from
/// parallel pieces, each a loop the compiler vectorises (a short-circuiting
/// `any` is a branch per index).
pub(crate) fn largest_index(triangles: &[[u32; 3]]) -> u32 {
    triangles
        .as_flattened()
        .par_chunks(1 << 16)
        .map(|piece| piece.iter().fold(0, |m, &v| m.max(v)))
        .max()
        .unwrap_or(0)
}

/// The unit normals of nodes `0..used` over one face's triangles: the
/// area-weighted sums, in triangle order, that [`expand_into`] forms (the
/// same numbers, so the output does not depend on which path made it).
fn node_normals(mesh: &Mesh, triangles: &[[u32; 3]], used: usize) -> Vec<[f64; 3]> {
    let (mut normals, fallback) = node_sums(mesh, triangles, used);
    for s in &mut normals {
        *s = unit(*s).unwrap_or(fallback);
    }
    normals
}

/// [`node_normals`] before they are made unit: the sums, and the normal of a
/// node whose sum is zero (the face's total direction).
fn node_sums(mesh: &Mesh, triangles: &[[u32; 3]], used: usize) -> (Vec<[f64; 3]>, [f64; 3]) {
    // Sums read before written: zeroed by writing (see `filled_vec`).
    let mut sums = crate::allocator::filled_vec(used, [0.0; 3]);
    let mut total = [0.0; 3];
    for &tri in triangles {
        let n = triangle_normal(mesh, tri);
        total = add(total, n);
        for v in tri {
            let s = &mut sums[v as usize];
            *s = add(*s, n);
        }
    }
    (sums, unit(total).unwrap_or([0.0, 0.0, 1.0]))
}

/// Normals handed to [`emit_unit_normals`]'s caller at a time (48 kB).
const NORMAL_RUN: usize = 4096;

/// Most ring slots of [`emit_unit_normals`] (1.5 MB of sums).
const MAX_NORMAL_WINDOW: usize = 1 << 16;

/// The unit normals of nodes `0..used` over one face's triangles, as `f32`
/// (the numbers [`node_normals`] gives, converted), handed to `emit` in node
/// order a run at a time. When the face uses its nodes in a sliding range
/// (`node_window`), the sums live in a small ring and each node's normal
/// goes out once no later triangle uses it: no vector of sums as large as
/// the mesh (24 MB of fresh pages on 2 million triangles). Else all sums
/// are formed first.
///
/// `blocks`: the triangles' `node_window::block_ranges`, when known (the
/// plan is then made without a pass over the triangles).
pub(crate) fn emit_unit_normals(
    mesh: &Mesh,
    triangles: &[[u32; 3]],
    blocks: Option<&[(u32, u32)]>,
    used: usize,
    emit: &mut dyn FnMut(&[[f32; 3]]) -> std::io::Result<()>,
) -> std::io::Result<()> {
    let plan = match blocks {
        Some(ranges) => {
            super::node_window::plan_from(&[triangles], ranges, used, MAX_NORMAL_WINDOW)
        }
        None => super::node_window::plan(&[triangles], used, MAX_NORMAL_WINDOW),
    };
    let Some(plan) = plan else {
        let (sums, fallback) = node_sums(mesh, triangles, used);
        let mut run = Vec::with_capacity(NORMAL_RUN);
        for chunk in sums.chunks(NORMAL_RUN) {
            run.clear();
            run.extend(chunk.iter().map(|&s| unit_f32(s, fallback)));
            emit(&run)?;
        }
        return Ok(());
    };
    let mut stream = NormalRing {
        // Sums read before written: zeroed by writing (see `filled_vec`).
        ring: crate::allocator::filled_vec(plan.size, [0.0; 3]),
        mask: plan.size - 1,
        done: 0,
        run: Vec::with_capacity(NORMAL_RUN),
        waiting: Vec::new(),
    };
    let mut total = [0.0; 3];
    for (block, &start) in plan.blocks.iter().zip(&plan.first) {
        stream.complete(start as usize, emit)?;
        for &tri in *block {
            let n = triangle_normal(mesh, tri);
            total = add(total, n);
            for v in tri {
                let s = &mut stream.ring[v as usize & stream.mask];
                *s = add(*s, n);
            }
        }
    }
    stream.complete(used, emit)?;
    if !stream.run.is_empty() {
        emit(&stream.run)?;
    }
    let fallback = unit(total).unwrap_or([0.0, 0.0, 1.0]);
    for chunk in stream.waiting.chunks(NORMAL_RUN) {
        stream.run.clear();
        stream
            .run
            .extend(chunk.iter().map(|&s| unit_f32(s, fallback)));
        emit(&stream.run)?;
    }
    Ok(())
}

/// [`emit_unit_normals`]' ring of sums and the normals ready to go out.
struct NormalRing {
    ring: Vec<[f64; 3]>,
    mask: usize,
    /// Nodes below are out of the ring.
    done: usize,
    run: Vec<[f32; 3]>,
    /// The sums from the first node whose sum is zero on: its normal is the
    /// face's total direction, known only at the end.
    waiting: Vec<[f64; 3]>,
}

impl NormalRing {
    /// Takes the sums of the nodes below `upto` out of the ring.
    fn complete(
        &mut self,
        upto: usize,
        emit: &mut dyn FnMut(&[[f32; 3]]) -> std::io::Result<()>,
    ) -> std::io::Result<()> {
        for v in self.done..upto {
            let slot = &mut self.ring[v & self.mask];
            let sum = std::mem::replace(slot, [0.0; 3]);
            match unit(sum) {
                Some(u) if self.waiting.is_empty() => self.run.push(u.map(|c| c as f32)),
                _ => self.waiting.push(sum),
            }
            if self.run.len() == NORMAL_RUN {
                emit(&self.run)?;
                self.run.clear();
            }
        }
        self.done = self.done.max(upto);
        Ok(())
    }
}

fn expand_into<'a>(ex: &mut Expander<'a>, faces: &[(u32, bool)]) -> Expanded<'a> {
    let (nodes, normals, triangles) = expand_faces(ex, faces, |n| n);
    Expanded {
        normals,
        nodes: Some(nodes),
        triangles: Cow::Owned(triangles),
    }
}

/// The faces' nodes (each once per face, in first-use order), their unit
/// normals as `convert` makes them, and the triangles renumbered onto them.
/// A node's normal is the area-weighted sum of its triangles' normals in the
/// face, summed and made unit in `f64` whatever `N` is, so every writer gets
/// the same numbers.
fn expand_faces<N>(
    ex: &mut Expander<'_>,
    faces: &[(u32, bool)],
    convert: impl Fn([f64; 3]) -> N,
) -> (Vec<u32>, Vec<N>, Vec<[u32; 3]>) {
    let mesh = ex.mesh;
    let triangles: usize = faces
        .iter()
        .map(|&(f, _)| mesh.faces[f as usize].triangles.len())
        .sum();
    // Each node once per face: at most all nodes, at most three per triangle
    // (reserved at once: growing by doubling copied and touched twice the memory).
    let vertices = mesh.nodes.len().min(3 * triangles);
    let mut out_triangles = Vec::with_capacity(triangles);
    let mut nodes = Vec::with_capacity(vertices);
    let mut normals = Vec::with_capacity(vertices);
    // One face's normal sums, reused from face to face.
    let mut sums: Vec<[f64; 3]> = Vec::new();
    for &(face, flip) in faces {
        let stamp = ex.next_stamp();
        let first = nodes.len();
        sums.clear();
        let mut total = [0.0; 3];
        for tri in oriented(mesh, face, flip) {
            // Area weighting: the unnormalised cross product is twice the area.
            let n = triangle_normal(mesh, tri);
            total = add(total, n);
            let mut t = [0u32; 3];
            for (k, &node) in tri.iter().enumerate() {
                let entry = &mut ex.slot[node as usize];
                if entry.0 != stamp {
                    nodes.push(node);
                    sums.push([0.0; 3]);
                    *entry = (stamp, (nodes.len() - 1) as u32);
                }
                let index = entry.1 as usize;
                let s = &mut sums[index - first];
                *s = add(*s, n);
                t[k] = entry.1;
            }
            out_triangles.push(t);
        }
        let fallback = unit(total).unwrap_or([0.0, 0.0, 1.0]);
        normals.extend(sums.iter().map(|s| convert(unit(*s).unwrap_or(fallback))));
    }
    (nodes, normals, out_triangles)
}

/// Twice the area times the unit normal, by the right-hand rule.
#[inline]
pub(crate) fn triangle_normal(mesh: &Mesh, [a, b, c]: [u32; 3]) -> [f64; 3] {
    let (p, q, r) = (
        mesh.nodes[a as usize],
        mesh.nodes[b as usize],
        mesh.nodes[c as usize],
    );
    cross(sub(q, p), sub(r, p))
}

#[inline]
pub(crate) fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[inline]
fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

#[inline]
pub(crate) fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

#[inline]
pub(crate) fn norm(a: [f64; 3]) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

/// The unit vector along `a`, `None` for a (near) zero vector.
#[inline]
pub(crate) fn unit(a: [f64; 3]) -> Option<[f64; 3]> {
    let n = norm(a);
    (n > 0.0 && n.is_finite()).then(|| [a[0] / n, a[1] / n, a[2] / n])
}

/// The area of a face's triangulation.
pub(crate) fn face_area(mesh: &Mesh, face: u32) -> f64 {
    mesh.faces[face as usize]
        .triangles
        .iter()
        .map(|&t| norm(triangle_normal(mesh, t)) / 2.0)
        .sum()
}

/// The length of a polyline.
pub(crate) fn length(mesh: &Mesh, nodes: &[u32]) -> f64 {
    segments(nodes)
        .iter()
        .map(|&[a, b]| norm(sub(mesh.nodes[b as usize], mesh.nodes[a as usize])))
        .sum()
}

/// The bounding box of some nodes, `None` when there are none.
pub(crate) fn bounds(
    mesh: &Mesh,
    nodes: impl IntoIterator<Item = u32>,
) -> Option<([f64; 3], [f64; 3])> {
    let mut it = nodes.into_iter().map(|n| mesh.nodes[n as usize]);
    let first = it.next()?;
    Some(it.fold((first, first), |(lo, hi), p| {
        (
            [lo[0].min(p[0]), lo[1].min(p[1]), lo[2].min(p[2])],
            [hi[0].max(p[0]), hi[1].max(p[1]), hi[2].max(p[2])],
        )
    }))
}

/// The warning of a surface format given a mesh with volume cells: they are
/// not written (only the mesh's surface triangles are), said with counts.
pub(crate) fn dropped_volumes(format: &'static str, mesh: &Mesh) -> Option<super::Warning> {
    if mesh.volumes.is_empty() {
        return None;
    }
    Some(super::warning(
        format,
        format!(
            "{format} holds surfaces only: {} in {} not written (convert to .msh or .vtu to keep them)",
            crate::mesh::volume::describe(&mesh.volumes),
            super::count(
                {
                    let mut names: Vec<&str> =
                        mesh.volumes.iter().map(|v| v.name.as_str()).collect();
                    names.sort_unstable();
                    names.dedup();
                    names.len()
                },
                "volume group"
            )
        ),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identity_prefix_accepts_nodes_in_first_use_order_only() {
        assert_eq!(identity_prefix(&[[0, 1, 2], [2, 1, 3], [0, 3, 4]]), Some(5));
        assert_eq!(identity_prefix(&[[0, 2, 1]]), None);
        assert_eq!(identity_prefix(&[]), Some(0));
        // A node ahead of its turn in a later run of 4,096 indices.
        let mut long: Vec<[u32; 3]> = (0..3000).map(|i| [i, i + 1, i + 2]).collect();
        assert_eq!(identity_prefix(&long), Some(3002));
        long.push([0, 1, 5000]);
        assert_eq!(identity_prefix(&long), None);
        // Every way of breaking the order, at every place (so in each part
        // and at the parts' edges), against the index-by-index rule.
        let strip: Vec<[u32; 3]> = (0..40).map(|i| [i, i + 1, i + 2]).collect();
        for at in 0..strip.len() * 3 {
            for delta in [-2i64, -1, 1, 2, 40] {
                let mut t = strip.clone();
                let slot = &mut t[at / 3][at % 3];
                *slot = (i64::from(*slot) + delta).max(0) as u32;
                assert_eq!(
                    identity_prefix(&t),
                    first_use_one_by_one(&t),
                    "index {at} moved by {delta}"
                );
                for cut in [1, 2, 7, 13] {
                    let short = &t[..t.len() - cut];
                    assert_eq!(identity_prefix(short), first_use_one_by_one(short));
                }
            }
        }
        assert_eq!(identity_prefix(&[[u32::MAX, 0, 1]]), None);
        assert_eq!(identity_prefix(&[[0, 0, 0]]), Some(1));
    }

    /// The normals [`emit_unit_normals`] hands out, gathered.
    fn emitted(
        mesh: &Mesh,
        triangles: &[[u32; 3]],
        blocks: Option<&[(u32, u32)]>,
        used: usize,
    ) -> Vec<[f32; 3]> {
        let mut all = Vec::new();
        emit_unit_normals(mesh, triangles, blocks, used, &mut |run| {
            all.extend_from_slice(run);
            Ok(())
        })
        .expect("no write fails");
        all
    }

    /// A wavy strip of triangles numbered in first-use order, with a node
    /// in the middle whose only triangle has no area (a zero sum: its
    /// normal is the face's direction, known only at the end): the ring and
    /// the whole-table path give `node_normals`' numbers exactly.
    #[test]
    fn streamed_normals_equal_the_whole_table() {
        let columns = 40_000u32;
        let mut points = Vec::new();
        for i in 0..columns {
            let x = f64::from(i) * 0.01;
            points.push([x, 0.0, (x * 7.0).sin()]);
            points.push([x, 1.0, (x * 5.0).cos()]);
        }
        let mut triangles = Vec::new();
        for i in 0..columns - 1 {
            let (a, b, c, d) = (2 * i, 2 * i + 1, 2 * i + 2, 2 * i + 3);
            triangles.push([a, c, b]);
            triangles.push([b, c, d]);
        }
        let lone = points.len() as u32;
        points.push([5.0, 5.0, 5.0]);
        triangles.insert(2000, [lone, lone, 900]);
        // Numbered in first-use order, as an STL reader numbers them.
        let mut number = vec![u32::MAX; points.len()];
        let mut mesh = Mesh {
            dimension: 3,
            ..Mesh::default()
        };
        for v in triangles.iter_mut().flatten() {
            if number[*v as usize] == u32::MAX {
                number[*v as usize] = mesh.nodes.len() as u32;
                mesh.nodes.push(points[*v as usize]);
            }
            *v = number[*v as usize];
        }
        let check = |triangles: &[[u32; 3]]| {
            let used = identity_prefix(triangles).expect("first-use order");
            let whole: Vec<[f32; 3]> = node_normals(&mesh, triangles, used)
                .iter()
                .map(|v| v.map(|c| c as f32))
                .collect();
            assert_eq!(emitted(&mesh, triangles, None, used), whole);
            // The plan made from known block ranges: the same normals.
            let blocks = super::super::node_window::block_ranges(triangles);
            assert_eq!(emitted(&mesh, triangles, Some(&blocks), used), whole);
            whole
        };
        let windowed = |triangles: &[[u32; 3]]| {
            super::super::node_window::plan(&[triangles], mesh.nodes.len(), MAX_NORMAL_WINDOW)
                .is_some()
        };
        assert!(windowed(&triangles));
        let ring = check(&triangles);
        assert_eq!(ring.len(), mesh.nodes.len());
        let zero_sum = number[lone as usize] as usize;
        assert!(zero_sum > 1000 && zero_sum < ring.len() - 1000);
        let total = triangles
            .iter()
            .fold([0.0; 3], |t, &tri| add(t, triangle_normal(&mesh, tri)));
        let direction = unit(total).expect("a direction").map(|c| c as f32);
        assert_eq!(ring[zero_sum], direction);
        // Node 0 used again at the end: too wide a window, all sums at once.
        let mut late = triangles.clone();
        late.push([0, 1, 2]);
        assert!(!windowed(&late));
        assert_eq!(check(&late).len(), ring.len());
    }

    /// The index-by-index first-use rule [`identity_prefix`] must agree with.
    fn first_use_one_by_one(t: &[[u32; 3]]) -> Option<usize> {
        let mut next = 0u32;
        for &n in t.as_flattened() {
            if n > next {
                return None;
            }
            next += u32::from(n == next);
        }
        Some(next as usize)
    }

    /// Over several parallel pieces, an index moved at a piece's edge or
    /// inside one gives the one-by-one answer, and the summary's largest
    /// index is [`largest_index`]'s.
    #[test]
    fn first_use_over_many_pieces_is_the_one_by_one_rule() {
        let n = FIRST_USE_PIECE as u32 + 5_000;
        let strip: Vec<[u32; 3]> = (0..n).map(|i| [i, i + 1, i + 2]).collect();
        assert_eq!(identity_prefix(&strip), Some(n as usize + 2));
        assert_eq!(FirstUse::of(&strip).largest(), n + 1);
        let values = 3 * n as usize;
        let piece = FIRST_USE_PIECE;
        for at in [piece - 1, piece, piece + 1, 2 * piece + 7, values - 1] {
            for delta in [-3i64, 2, 3, 50_000] {
                let mut t = strip.clone();
                let slot = &mut t.as_flattened_mut()[at];
                *slot = (i64::from(*slot) + delta).max(0) as u32;
                let want = first_use_one_by_one(&t);
                assert_eq!(identity_prefix(&t), want, "index {at} moved by {delta}");
                assert_eq!(FirstUse::of(&t).largest(), largest_index(&t));
            }
        }
        assert_eq!(FirstUse::of(&[]).largest(), 0);
    }

    /// One pass gives the first bad node as [`first_non_finite`] does, or
    /// the nodes' bounds.
    #[test]
    fn nodes_scan_gives_the_bounds_or_the_first_bad_node() {
        let mut nodes: Vec<[f64; 3]> = (0..5_000)
            .map(|i| {
                let x = f64::from(i);
                [x.sin(), 2.0 * (0.3 * x).cos(), 1e-3 * x - 1.0]
            })
            .collect();
        let (bad, bounds) = nodes_scan(&nodes);
        assert_eq!(bad, None);
        let (lo, hi) = bounds.expect("bounds");
        for k in 0..3 {
            let c = nodes.iter().map(|p| p[k]);
            assert_eq!(lo[k], c.clone().fold(f64::INFINITY, f64::min));
            assert_eq!(hi[k], c.fold(f64::NEG_INFINITY, f64::max));
        }
        assert_eq!(lo[2], -1.0);
        assert_eq!(hi[2], 1e-3 * 4_999.0 - 1.0);
        nodes[4_000][0] = f64::INFINITY;
        nodes[3_100][2] = f64::NAN;
        assert_eq!(nodes_scan(&nodes), (Some(3_100), None));
        assert_eq!(nodes_scan(&[]), (None, None));
    }

    /// Two faces over four nodes (the second at `second`): the first uses
    /// its nodes in order (0, 1, 2, 3), the second does not.
    fn in_and_out_of_order(second: [f64; 3]) -> Mesh {
        let face = |name: &str, triangles: Vec<[u32; 3]>| crate::mesh::MeshFace {
            name: name.into(),
            triangles,
            boundary: Vec::new(),
        };
        Mesh {
            dimension: 3,
            nodes: vec![[0.0, 0.0, 0.0], second, [0.0, 1.0, 2.0], [1.0, 1.0, 0.5]],
            faces: vec![
                face("in order", vec![[0, 1, 2], [2, 1, 3]]),
                face("out of order", vec![[0, 2, 1]]),
            ],
            ..Mesh::default()
        }
    }

    /// The scanning check finds each face's first-use prefix and the same
    /// errors as the plain one.
    #[test]
    fn the_scanning_check_finds_each_faces_order() {
        let mut mesh = in_and_out_of_order([1.0, 0.0, 0.0]);
        let scanned = check_scanned(&mesh, true).expect("a valid mesh");
        assert_eq!(scanned.identity, vec![Some(4), None]);
        assert_eq!(scanned.bounds, Some(([0.0, 0.0, 0.0], [1.0, 1.0, 2.0])));
        mesh.faces[1].triangles.push([0, 1, 4]);
        let plain = check(&mesh).map_err(|e| e.to_string());
        let scanning = check_scanned(&mesh, true).map_err(|e| e.to_string());
        assert_eq!(scanning, plain.clone().map(|_| Scanned::default()));
        assert_eq!(
            plain,
            Err("invalid mesh: face `out of order` refers to a node out of range".into())
        );
    }

    #[test]
    fn the_known_check_takes_a_readers_facts_that_fit_the_mesh() {
        use crate::formats::mesh_facts::FaceFacts;
        let facts_of = |mesh: &Mesh| {
            let faces = mesh
                .faces
                .iter()
                .map(|f| FaceFacts::of(&f.triangles))
                .collect();
            MeshFacts::of(&mesh.nodes, faces).expect("finite nodes")
        };
        let mut mesh = in_and_out_of_order([1.0, -3.0, 0.0]);
        let facts = facts_of(&mesh);
        let known = check_known(&mesh, &facts).expect("a valid mesh");
        assert_eq!(known.identity, vec![Some(4), None]);
        assert_eq!(known.bounds, Some(([0.0, -3.0, 0.0], [1.0, 1.0, 2.0])));
        assert_eq!(known.blocks, vec![Some(vec![(0, 3)]), Some(vec![(0, 2)])]);
        // The scanning check finds the same, without block ranges.
        let scanned = check_scanned(&mesh, true).expect("a valid mesh");
        assert_eq!(
            (scanned.identity, scanned.bounds),
            (known.identity, known.bounds)
        );
        assert!(scanned.blocks.is_empty());
        // Facts of the mesh before a triangle was added do not fit: the
        // check scans, and finds the node out of range.
        mesh.faces[1].triangles.push([0, 1, 4]);
        let stale = check_known(&mesh, &facts).map_err(|e| e.to_string());
        let out_of_range = "invalid mesh: face `out of order` refers to a node out of range";
        assert_eq!(stale, Err(out_of_range.into()));
        // Facts that fit and know the largest node: the same error.
        let fitting = check_known(&mesh, &facts_of(&mesh)).map_err(|e| e.to_string());
        assert_eq!(fitting, Err(out_of_range.into()));
    }

    #[test]
    fn first_non_finite_finds_the_first_bad_node_in_any_run() {
        let mut nodes = vec![[1.0, 2.0, 3.0]; 3000];
        assert_eq!(first_non_finite(&nodes), None);
        nodes[2500][1] = f64::NAN;
        nodes[2900][0] = f64::INFINITY;
        assert_eq!(first_non_finite(&nodes), Some(2500));
        nodes[7][2] = f64::NEG_INFINITY;
        assert_eq!(first_non_finite(&nodes), Some(7));
    }
}
