//! Gmsh MSH 4.1, ASCII (the default) or binary. `$Entities` carries the
//! topology: points are the model vertices, curves the edges with their end
//! points (begin positive, end negative: Gmsh's own convention), surfaces the
//! faces with their signed bounding curves, volumes (3D) the subdomains with
//! their signed boundary surfaces, and volume cells read from another file
//! the faces on their group's boundary (`msh_bounds`). Each mesh node is written once, on the
//! lowest-dimensional entity that uses it. Physical groups: every fragment
//! (dim 2 in 3D, 1 in 2D), every subdomain (dim 3 in 3D; in 2D its region
//! faces, dim 2), faces in neither kind of group (dim 2, by face name),
//! poly_lines (dim 1, as extra curves) and point sets (dim 0, one extra point
//! entity per point), volume cells read from another file (dim 3, one
//! entity per group and cell kind). Elements (15 point, 1 line, 2 triangle;
//! second order: 8 3-node line, 9 6-node triangle; 4 tetrahedron, 5
//! hexahedron, 6 prism, 7 pyramid) are written per
//! entity, only for entities in a physical group — what Gmsh itself saves by
//! default, and what meshio needs to attach groups to every element block.

use super::groups;
use super::{Encoding, MeshWriter, Warning, WriteError, WriteOptions, count, push_num, warning};
use crate::mesh::Mesh;
use rayon::prelude::*;
use std::borrow::Cow;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::io::Write;

pub(crate) struct Msh;

impl MeshWriter for Msh {
    fn name(&self) -> &'static str {
        "msh"
    }

    fn extensions(&self) -> &'static [&'static str] {
        &["msh"]
    }

    fn keeps_volume_cells(&self) -> bool {
        true
    }

    fn write(
        &self,
        mesh: &Mesh,
        options: &WriteOptions,
        out: &mut dyn Write,
    ) -> Result<Vec<Warning>, WriteError> {
        groups::check(mesh)?;
        let model = Model::of(mesh);
        let warnings = model_warnings(&model);
        let binary = options.encoding == Some(Encoding::Binary);
        write_all(&model, mesh, binary, out)?;
        Ok(warnings)
    }
}

/// What an MSH file (either version) cannot hold of the mesh.
pub(super) fn model_warnings(model: &Model<'_>) -> Vec<Warning> {
    let mut warnings = Vec::new();
    if model.renamed > 0 {
        warnings.push(warning(
            "msh",
            format!(
                "MSH names cannot hold `\"`: replaced by `'` in {}",
                count(model.renamed, "name")
            ),
        ));
    }
    if model.unused_nodes > 0 {
        warnings.push(warning(
            "msh",
            format!(
                "{} used by no vertex, edge, face, poly_line or point set: not written",
                count(model.unused_nodes, "node")
            ),
        ));
    }
    warnings
}

/// An entity of the Gmsh model.
pub(super) struct Entity<'a> {
    pub(super) tag: i32,
    pub(super) physicals: Vec<i32>,
    /// Signed tags of the bounding entities one dimension down.
    bounding: Vec<i32>,
    /// Mesh nodes whose bounding box the entity has (all it uses), in
    /// pieces: a surface's are its face's triangles and a volume's its
    /// faces', borrowed from the mesh rather than copied (the copies were a
    /// third of the peak memory of writing a large mesh).
    used: Vec<Cow<'a, [u32]>>,
    /// Elements, as mesh node lists of `per` nodes each, one after the
    /// other (one allocation per entity, not per element; a face's
    /// triangles are borrowed as they are).
    pub(super) elements: Cow<'a, [u32]>,
    pub(super) per: usize,
    /// The Gmsh element type when `per` does not tell it (volume cells).
    gmsh_type: Option<i32>,
}

impl<'a> Entity<'a> {
    /// How many elements it holds.
    pub(super) fn count(&self) -> usize {
        self.elements.len() / self.per
    }

    /// Its Gmsh element type (the same numbers in MSH 2.2 and 4.1): 15
    /// point, 1 line, 8 3-node line, 2 triangle, 9 6-node triangle, or the
    /// volume cell's.
    pub(super) fn element_type(&self, dim: usize) -> i32 {
        self.gmsh_type.unwrap_or(match (dim, self.per) {
            (0, _) => 15,
            (1, 3) => 8,
            (1, _) => 1,
            (_, 6) => 9,
            _ => 2,
        })
    }

    fn new(tag: usize) -> Entity<'a> {
        Entity {
            tag: tag as i32,
            physicals: Vec::new(),
            bounding: Vec::new(),
            used: Vec::new(),
            elements: Cow::Borrowed(&[]),
            per: 1,
            gmsh_type: None,
        }
    }
}

/// The MSH view of a mesh: entities per dimension, physical names, node owners.
pub(super) struct Model<'a> {
    /// Index = dimension.
    pub(super) entities: [Vec<Entity<'a>>; 4],
    /// (dim, tag, name).
    pub(super) physical_names: Vec<(u8, i32, String)>,
    /// The (dimension, entity index) owning each node; `None` for nodes no
    /// element uses.
    pub(super) owner: Vec<Option<(u8, usize)>>,
    renamed: usize,
    unused_nodes: usize,
}

impl<'a> Model<'a> {
    pub(super) fn of(mesh: &'a Mesh) -> Model<'a> {
        let three = mesh.dimension == 3;
        let vertex_of_node: BTreeMap<u32, usize> = mesh
            .vertices
            .iter()
            .enumerate()
            .map(|(i, v)| (v.node, i))
            .rev() // the first vertex on a node wins
            .collect();

        let mut points: Vec<Entity> = mesh
            .vertices
            .iter()
            .enumerate()
            .map(|(i, v)| {
                let mut e = Entity::new(i + 1);
                e.used = vec![Cow::Owned(vec![v.node])];
                e.elements = Cow::Owned(vec![v.node]);
                e
            })
            .collect();
        let mut curves: Vec<Entity> = mesh
            .edges
            .iter()
            .enumerate()
            .map(|(i, edge)| {
                let mut e = Entity::new(i + 1);
                e.bounding = end_points(&edge.nodes, &vertex_of_node);
                e.used = vec![Cow::Borrowed(&edge.nodes[..])];
                e.elements = Cow::Owned(segment_nodes(&edge.nodes));
                e.per = 2;
                if let Some(q) = &mesh.quadratic {
                    add_mid_nodes(&mut e, q.edges.get(i).map(|m| m.as_slice()));
                }
                e
            })
            .collect();
        let mut surfaces: Vec<Entity> = mesh
            .faces
            .iter()
            .enumerate()
            .map(|(i, face)| {
                let mut e = Entity::new(i + 1);
                e.bounding = face
                    .boundary
                    .iter()
                    .map(|&(edge, fwd)| signed(edge as usize + 1, fwd))
                    .collect();
                e.used = vec![Cow::Borrowed(face.triangles.as_flattened())];
                e.elements = Cow::Borrowed(face.triangles.as_flattened());
                e.per = 3;
                if let Some(q) = &mesh.quadratic {
                    let mids: Vec<u32> = q
                        .faces
                        .get(i)
                        .into_iter()
                        .flatten()
                        .flatten()
                        .copied()
                        .collect();
                    add_mid_nodes_grouped(&mut e, &mids, 3);
                }
                e
            })
            .collect();
        let mut volumes: Vec<Entity> = Vec::new();
        if three {
            volumes = mesh
                .subdomains
                .iter()
                .enumerate()
                .map(|(i, s)| {
                    let mut e = Entity::new(i + 1);
                    e.bounding = s
                        .faces
                        .iter()
                        .map(|&(f, out)| signed(f as usize + 1, out))
                        .collect();
                    e.used = s
                        .faces
                        .iter()
                        .filter_map(|&(f, _)| mesh.faces.get(f as usize))
                        .map(|f| Cow::Borrowed(f.triangles.as_flattened()))
                        .collect();
                    e
                })
                .collect();
        }

        let mut names = Names::default();
        // Fragments: faces in 3D, edges in 2D.
        let mut face_grouped = vec![false; mesh.faces.len()];
        for fr in &mesh.fragments {
            if three {
                let tag = names.add(2, &fr.name);
                for &f in &fr.faces {
                    surfaces[f as usize].physicals.push(tag);
                    face_grouped[f as usize] = true;
                }
            } else {
                let tag = names.add(1, &fr.name);
                for &e in &fr.edges {
                    curves[e as usize].physicals.push(tag);
                }
            }
        }
        for (i, s) in mesh.subdomains.iter().enumerate() {
            if three {
                let tag = names.add(3, &s.name);
                volumes[i].physicals.push(tag);
            } else {
                let tag = names.add(2, &s.name);
                for &(f, _) in &s.faces {
                    surfaces[f as usize].physicals.push(tag);
                    face_grouped[f as usize] = true;
                }
            }
        }
        let bounding = super::msh_bounds::volume_bounding(mesh);
        for v in &mesh.volumes {
            // One physical group per name, shared with a subdomain of that name.
            let tag = names
                .list
                .iter()
                .find(|(d, _, n)| *d == 3 && *n == v.name.replace('"', "'"))
                .map(|(_, t, _)| *t)
                .unwrap_or_else(|| names.add(3, &v.name));
            let mut e = Entity::new(volumes.len() + 1);
            e.physicals.push(tag);
            e.used = vec![Cow::Borrowed(&v.nodes[..])];
            e.elements = Cow::Borrowed(&v.nodes[..]);
            e.per = v.kind.corners();
            e.gmsh_type = Some(v.kind.gmsh_type());
            if let Some((_, b)) = bounding.iter().find(|(n, _)| *n == v.name) {
                e.bounding = b.clone();
            }
            volumes.push(e);
        }
        for (i, face) in mesh.faces.iter().enumerate() {
            if !face_grouped[i] {
                let tag = names.add(2, &face.name);
                surfaces[i].physicals.push(tag);
            }
        }
        for (line_index, p) in mesh.polylines.iter().enumerate() {
            let tag = names.add(1, &p.name);
            let mut e = Entity::new(curves.len() + 1);
            e.physicals.push(tag);
            // Only when a poly_line ends on model vertices does it have bounding points.
            e.bounding = end_points(&p.nodes, &vertex_of_node);
            e.used = vec![Cow::Borrowed(&p.nodes[..])];
            e.elements = Cow::Owned(segment_nodes(&p.nodes));
            e.per = 2;
            if let Some(q) = &mesh.quadratic {
                add_mid_nodes(&mut e, q.polylines.get(line_index).map(|m| m.as_slice()));
            }
            curves.push(e);
        }
        for p in &mesh.point_sets {
            let tag = names.add(0, &p.name);
            for &node in &p.nodes {
                let mut e = Entity::new(points.len() + 1);
                e.physicals.push(tag);
                e.used = vec![Cow::Owned(vec![node])];
                e.elements = Cow::Owned(vec![node]);
                points.push(e);
            }
        }

        let mut entities = [points, curves, surfaces, volumes];
        // Lowest dimension first, so a node on a vertex belongs to its point,
        // one on an edge to its curve.
        let mut owner: Vec<Option<(u8, usize)>> = vec![None; mesh.nodes.len()];
        for (dim, list) in entities.iter().enumerate() {
            for (i, e) in list.iter().enumerate() {
                for &n in e.used.iter().flat_map(|piece| piece.iter()) {
                    let slot = &mut owner[n as usize];
                    if slot.is_none() {
                        *slot = Some((dim as u8, i));
                    }
                }
            }
        }
        // Elements only where a physical group holds them, as Gmsh saves by
        // default: readers such as meshio expect every element block to have a
        // physical tag. The entities and their nodes stay.
        for e in entities.iter_mut().flatten() {
            if e.physicals.is_empty() {
                e.elements = Cow::Borrowed(&[]);
            }
        }
        let unused_nodes = owner.iter().filter(|o| o.is_none()).count();
        Model {
            entities,
            physical_names: names.list,
            owner,
            renamed: names.renamed,
            unused_nodes,
        }
    }
}

/// Appends each segment's mid node (3-node lines); segments without one
/// stay linear.
fn add_mid_nodes(e: &mut Entity<'_>, mids: Option<&[u32]>) {
    add_mid_nodes_grouped(e, mids.unwrap_or(&[]), 1);
}

/// Appends `per` mid nodes to each element (6-node triangles: 3), when
/// there is exactly one group per element.
fn add_mid_nodes_grouped(e: &mut Entity<'_>, mids: &[u32], per: usize) {
    if mids.len() != e.count() * per || mids.is_empty() {
        return;
    }
    let mut elements = Vec::with_capacity(e.elements.len() + mids.len());
    for (element, extra) in e.elements.chunks_exact(e.per).zip(mids.chunks_exact(per)) {
        elements.extend_from_slice(element);
        elements.extend_from_slice(extra);
    }
    e.elements = Cow::Owned(elements);
    e.per += per;
    e.used.push(Cow::Owned(mids.to_vec()));
}

/// Consecutive node pairs of a polyline, flat.
fn segment_nodes(nodes: &[u32]) -> Vec<u32> {
    nodes.windows(2).flatten().copied().collect()
}

/// Physical tags numbered per dimension from 1, with their names.
#[derive(Default)]
struct Names {
    list: Vec<(u8, i32, String)>,
    next: [i32; 4],
    renamed: usize,
}

impl Names {
    fn add(&mut self, dim: u8, name: &str) -> i32 {
        let d = dim as usize;
        self.next[d] += 1;
        let tag = self.next[d];
        let clean = name.replace('"', "'");
        if clean != name {
            self.renamed += 1;
        }
        self.list.push((dim, tag, clean));
        tag
    }
}

fn signed(tag: usize, positive: bool) -> i32 {
    if positive { tag as i32 } else { -(tag as i32) }
}

/// A polyline's bounding points, Gmsh's way: +begin, −end, when on vertices.
fn end_points(nodes: &[u32], vertex_of_node: &BTreeMap<u32, usize>) -> Vec<i32> {
    let mut out = Vec::new();
    if let Some(v) = nodes.first().and_then(|n| vertex_of_node.get(n)) {
        out.push(*v as i32 + 1);
    }
    if let Some(v) = nodes.last().and_then(|n| vertex_of_node.get(n)) {
        out.push(-(*v as i32 + 1));
    }
    out
}

/// Writes values as ASCII tokens on lines, or as little-endian binary (the
/// header's integer 1 tells readers the byte order). Shared with the MSH 2.2
/// writer (`msh22.rs`).
pub(super) struct Sink<'a> {
    out: &'a mut dyn Write,
    binary: bool,
    /// ASCII lines gathered the same way.
    line: String,
    /// No token written on the current ASCII line yet.
    fresh_line: bool,
    /// Binary values gathered here and handed to `out` in large pieces: one
    /// dynamic `write_all` per 8-byte value costs more than the copy itself.
    bytes: Vec<u8>,
}

/// How many binary bytes [`Sink`] gathers before writing them out.
const CHUNK: usize = 1 << 16;

impl<'a> Sink<'a> {
    pub(super) fn new(out: &'a mut dyn Write, binary: bool) -> Sink<'a> {
        Sink {
            out,
            binary,
            line: String::with_capacity(if binary { 0 } else { CHUNK + 256 }),
            fresh_line: true,
            bytes: Vec::with_capacity(if binary { CHUNK + 64 } else { 0 }),
        }
    }

    /// Starts a token: a space unless it is the first on its line.
    fn space(&mut self) {
        if !self.fresh_line {
            self.line.push(' ');
        }
        self.fresh_line = false;
    }

    fn raw(&mut self, bytes: &[u8]) -> std::io::Result<()> {
        self.bytes.extend_from_slice(bytes);
        if self.bytes.len() >= CHUNK {
            self.flush()?;
        }
        Ok(())
    }

    pub(super) fn flush(&mut self) -> std::io::Result<()> {
        self.out.write_all(&self.bytes)?;
        self.bytes.clear();
        self.out.write_all(self.line.as_bytes())?;
        self.line.clear();
        Ok(())
    }

    pub(super) fn int(&mut self, v: i32) -> std::io::Result<()> {
        if self.binary {
            self.raw(&v.to_le_bytes())
        } else {
            self.space();
            let _ = write!(self.line, "{v}");
            Ok(())
        }
    }

    pub(super) fn size(&mut self, v: usize) -> std::io::Result<()> {
        if self.binary {
            self.raw(&(v as u64).to_le_bytes())
        } else {
            self.space();
            let _ = write!(self.line, "{v}");
            Ok(())
        }
    }

    pub(super) fn real(&mut self, v: f64) -> std::io::Result<()> {
        if self.binary {
            self.raw(&v.to_le_bytes())
        } else {
            self.space();
            push_num(&mut self.line, v);
            Ok(())
        }
    }

    pub(super) fn end_line(&mut self) -> std::io::Result<()> {
        if !self.binary {
            // Lines gathered like binary values: one dynamic write per piece.
            self.line.push('\n');
            if self.line.len() >= CHUNK {
                self.out.write_all(self.line.as_bytes())?;
                self.line.clear();
            }
            self.fresh_line = true;
        }
        Ok(())
    }

    pub(super) fn text(&mut self, s: &str) -> std::io::Result<()> {
        self.flush()?;
        self.out.write_all(s.as_bytes())
    }

    /// Binary only: `count` records of `size` bytes, record `i` made by
    /// `encode(i, buffer)`. Built in pieces, a window of pieces at a time in
    /// parallel, written in order (the bytes do not depend on the thread count).
    fn records(
        &mut self,
        count: usize,
        size: usize,
        encode: impl Fn(usize, &mut Vec<u8>) + Sync,
    ) -> std::io::Result<()> {
        const PIECE: usize = 1 << 13;
        const WINDOW: usize = 16;
        self.flush()?;
        for window in (0..count).step_by(PIECE * WINDOW) {
            let end = (window + PIECE * WINDOW).min(count);
            let pieces: Vec<Vec<u8>> = (window..end)
                .step_by(PIECE)
                .collect::<Vec<usize>>()
                .par_iter()
                .map(|&start| {
                    let stop = (start + PIECE).min(end);
                    let mut bytes = Vec::with_capacity(size * (stop - start));
                    for i in start..stop {
                        encode(i, &mut bytes);
                    }
                    bytes
                })
                .collect();
            for piece in pieces {
                self.out.write_all(&piece)?;
            }
        }
        Ok(())
    }

    /// Ends a section; binary data is followed by a newline before `$End…`.
    pub(super) fn end_section(&mut self, name: &str) -> std::io::Result<()> {
        if self.binary {
            self.text("\n")?;
        }
        self.text(&format!("$End{name}\n"))
    }
}

fn write_all(
    model: &Model<'_>,
    mesh: &Mesh,
    binary: bool,
    out: &mut dyn Write,
) -> Result<(), WriteError> {
    let mut s = Sink::new(out, binary);
    write_preamble(&mut s, "4.1", model)?;
    write_entities(&mut s, model, mesh)?;
    write_nodes(&mut s, model, mesh)?;
    write_elements(&mut s, model)?;
    s.flush()?;
    Ok(())
}

/// `$MeshFormat` for `version` in the sink's encoding, then `$PhysicalNames`
/// (always ASCII): the same in MSH 4.1 and 2.2.
pub(super) fn write_preamble(
    s: &mut Sink,
    version: &str,
    model: &Model<'_>,
) -> std::io::Result<()> {
    s.text("$MeshFormat\n")?;
    if s.binary {
        s.text(&format!("{version} 1 8\n"))?;
        s.raw(&1i32.to_le_bytes())?;
        s.text("\n")?;
    } else {
        s.text(&format!("{version} 0 8\n"))?;
    }
    s.text("$EndMeshFormat\n")?;
    if !model.physical_names.is_empty() {
        s.text("$PhysicalNames\n")?;
        s.text(&format!("{}\n", model.physical_names.len()))?;
        for (dim, tag, name) in &model.physical_names {
            s.text(&format!("{dim} {tag} \"{name}\"\n"))?;
        }
        s.text("$EndPhysicalNames\n")?;
    }
    Ok(())
}

fn write_entities(s: &mut Sink, model: &Model<'_>, mesh: &Mesh) -> std::io::Result<()> {
    s.text("$Entities\n")?;
    for list in &model.entities {
        s.size(list.len())?;
    }
    s.end_line()?;
    for (dim, list) in model.entities.iter().enumerate() {
        for e in list {
            s.int(e.tag)?;
            if dim == 0 {
                let first = e.used.iter().flat_map(|piece| piece.iter()).next();
                let p = first.map_or([0.0; 3], |&n| mesh.nodes[n as usize]);
                for c in p {
                    s.real(c)?;
                }
            } else {
                let (lo, hi) =
                    groups::bounds(mesh, e.used.iter().flat_map(|piece| piece.iter().copied()))
                        .unwrap_or(([0.0; 3], [0.0; 3]));
                for c in lo.into_iter().chain(hi) {
                    s.real(c)?;
                }
            }
            s.size(e.physicals.len())?;
            for &p in &e.physicals {
                s.int(p)?;
            }
            if dim > 0 {
                s.size(e.bounding.len())?;
                for &b in &e.bounding {
                    s.int(b)?;
                }
            }
            s.end_line()?;
        }
    }
    s.end_section("Entities")
}

fn write_nodes(s: &mut Sink, model: &Model<'_>, mesh: &Mesh) -> std::io::Result<()> {
    // Owned nodes per entity, in node order.
    let mut blocks: BTreeMap<(u8, usize), Vec<u32>> = BTreeMap::new();
    for (n, o) in model.owner.iter().enumerate() {
        if let Some(key) = o {
            blocks.entry(*key).or_default().push(n as u32);
        }
    }
    let total: usize = blocks.values().map(Vec::len).sum();
    let min = blocks
        .values()
        .flatten()
        .min()
        .map_or(0, |n| *n as usize + 1);
    let max = blocks
        .values()
        .flatten()
        .max()
        .map_or(0, |n| *n as usize + 1);
    s.text("$Nodes\n")?;
    s.size(blocks.len())?;
    s.size(total)?;
    s.size(min)?;
    s.size(max)?;
    s.end_line()?;
    for ((dim, index), nodes) in &blocks {
        s.int(i32::from(*dim))?;
        s.int(model.entities[*dim as usize][*index].tag)?;
        s.int(0)?; // no parametric coordinates
        s.size(nodes.len())?;
        s.end_line()?;
        if s.binary {
            s.records(nodes.len(), 8, |i, b| {
                b.extend_from_slice(&(u64::from(nodes[i]) + 1).to_le_bytes())
            })?;
            s.records(nodes.len(), 24, |i, b| {
                for c in mesh.nodes[nodes[i] as usize] {
                    b.extend_from_slice(&c.to_le_bytes());
                }
            })?;
            continue;
        }
        for &n in nodes {
            s.size(n as usize + 1)?;
            s.end_line()?;
        }
        for &n in nodes {
            for c in mesh.nodes[n as usize] {
                s.real(c)?;
            }
            s.end_line()?;
        }
    }
    s.end_section("Nodes")
}

fn write_elements(s: &mut Sink, model: &Model<'_>) -> std::io::Result<()> {
    let blocks: Vec<(usize, &Entity<'_>)> = model
        .entities
        .iter()
        .enumerate()
        .flat_map(|(dim, list)| list.iter().map(move |e| (dim, e)))
        .filter(|(_, e)| !e.elements.is_empty())
        .collect();
    let total: usize = blocks.iter().map(|(_, e)| e.count()).sum();
    s.text("$Elements\n")?;
    s.size(blocks.len())?;
    s.size(total)?;
    s.size(usize::from(total > 0))?;
    s.size(total)?;
    s.end_line()?;
    let mut tag = 0usize;
    for (dim, e) in blocks {
        let kind = e.element_type(dim);
        s.int(dim as i32)?;
        s.int(e.tag)?;
        s.int(kind)?;
        s.size(e.count())?;
        s.end_line()?;
        if s.binary {
            let (first, per) = (tag, e.per);
            s.records(e.count(), 8 * (per + 1), |i, b| {
                b.extend_from_slice(&((first + i + 1) as u64).to_le_bytes());
                for &n in &e.elements[i * per..(i + 1) * per] {
                    b.extend_from_slice(&(u64::from(n) + 1).to_le_bytes());
                }
            })?;
            tag += e.count();
            continue;
        }
        for element in e.elements.chunks_exact(e.per) {
            tag += 1;
            s.size(tag)?;
            for &n in element {
                s.size(n as usize + 1)?;
            }
            s.end_line()?;
        }
    }
    s.end_section("Elements")
}
