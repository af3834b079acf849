//! glTF 2.0, as `.gltf` (JSON; the buffer in a side file `NAME.bin` when the
//! file name is known, else embedded as a base64 data URI) or `.glb` (one
//! binary file). The scene has up to four parent nodes: `surfaces` (a node and
//! mesh per fragment in 3D, per region in 2D, per face outside those),
//! `subdomains` (3D: each subdomain's whole boundary, outward), `lines`
//! (LINES: 2D fragments, edges, poly_lines) and `point_sets` (POINTS).
//! Triangles carry vertex normals, smooth within a face and flat across its
//! edges; each node's `extras` say what it is and, for a fragment, its
//! subdomain pair. Floats are `f32`, as glTF requires.

use super::file_ranges::{self, Range, fill_converted};
use super::groups::{self, Source};
use super::{
    FileOutput, MeshFacts, MeshWriter, SideFile, Warning, WriteError, WriteOptions, base64, count,
    warning,
};
use crate::mesh::Mesh;
use serde_json::{Value, json};
use std::io::Write;

pub(crate) struct Gltf {
    glb: bool,
}

pub(crate) static GLTF: Gltf = Gltf { glb: false };
pub(crate) static GLB: Gltf = Gltf { glb: true };

const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;
const FLOAT: u32 = 5126;
const UNSIGNED_INT: u32 = 5125;

impl MeshWriter for Gltf {
    fn name(&self) -> &'static str {
        if self.glb { "glb" } else { "gltf" }
    }

    fn extensions(&self) -> &'static [&'static str] {
        if self.glb { &["glb"] } else { &["gltf"] }
    }

    fn write(
        &self,
        mesh: &Mesh,
        options: &WriteOptions,
        out: &mut dyn Write,
    ) -> Result<Vec<Warning>, WriteError> {
        let (doc, warnings) = self.document(mesh, None, options)?;
        if self.glb {
            let json = doc.json(None);
            write_glb(&json, &doc, out)?;
        } else {
            let uri = match bin_name(options) {
                Some(name) => percent_encode(&name),
                None => format!(
                    "data:application/octet-stream;base64,{}",
                    base64::encode(&doc.buffer_bytes())
                ),
            };
            out.write_all(&doc.json(Some(uri)))?;
        }
        Ok(warnings)
    }

    fn write_file(
        &self,
        mesh: &Mesh,
        options: &WriteOptions,
        out: &mut FileOutput,
    ) -> Result<Vec<Warning>, WriteError> {
        self.write_file_known(mesh, None, options, out)
    }

    fn write_file_known(
        &self,
        mesh: &Mesh,
        facts: Option<&MeshFacts>,
        options: &WriteOptions,
        out: &mut FileOutput,
    ) -> Result<Vec<Warning>, WriteError> {
        if !self.glb {
            return self.write(mesh, options, out);
        }
        let (doc, warnings) = self.document(mesh, facts, options)?;
        write_glb_file(&doc.json(None), &doc, out, PARALLEL_FROM)?;
        Ok(warnings)
    }

    fn side_files(&self, mesh: &Mesh, options: &WriteOptions) -> Result<Vec<SideFile>, WriteError> {
        if self.glb {
            return Ok(Vec::new());
        }
        let scanned = groups::check_scanned(mesh, true)?;
        Ok(match bin_name(options) {
            Some(name) => vec![SideFile {
                name,
                bytes: Document::of(mesh, self.name(), &scanned).buffer_bytes(),
            }],
            None => Vec::new(),
        })
    }
}

impl Gltf {
    /// The checked mesh's document and the warnings of writing it; the
    /// check takes what it can from a reader's `facts`.
    fn document<'m>(
        &self,
        mesh: &'m Mesh,
        facts: Option<&MeshFacts>,
        options: &WriteOptions,
    ) -> Result<(Document<'m>, Vec<Warning>), WriteError> {
        let scanned = match facts {
            Some(facts) => groups::check_known(mesh, facts)?,
            None => groups::check_scanned(mesh, true)?,
        };
        let doc = Document::of(mesh, self.name(), &scanned);
        let mut warnings = doc.warnings.clone();
        warnings.extend(groups::dropped_volumes(self.name(), mesh));
        if options.encoding.is_some() {
            warnings.push(warning(
                self.name(),
                "glTF has one encoding: the encoding option is ignored",
            ));
        }
        Ok((doc, warnings))
    }
}

/// `part.gltf` → `part.bin`.
fn bin_name(options: &WriteOptions) -> Option<String> {
    let name = options.file_name.as_deref()?;
    let stem = if name.to_ascii_lowercase().ends_with(".gltf") {
        &name[..name.len() - 5]
    } else {
        name
    };
    Some(format!("{stem}.bin"))
}

/// URIs are percent-encoded: a file name with a space must still resolve.
fn percent_encode(s: &str) -> String {
    let mut out = String::new();
    for b in s.bytes() {
        if b.is_ascii_alphanumeric() || b"-._~".contains(&b) {
            out.push(char::from(b));
        } else {
            out.push_str(&format!("%{b:02X}"));
        }
    }
    out
}

/// One part of the binary buffer, kept where it is (the mesh's nodes and
/// triangles, a group's faces) and converted while it is written: no copy of
/// the whole buffer is built before the output.
enum Piece {
    /// Vectors made for this output, kept as the `f32` they are written as.
    Vec3F32(Vec<[f32; 3]>),
    /// Indices written as little-endian `u32`.
    Indices(Vec<u32>),
    /// A triangle group's positions, normals and indices, one after the
    /// other: the expansion's vertices, normals and triangles are made
    /// while they are written (one pass over the faces each), so none of
    /// them is held; only one face's normal sums are.
    Group {
        faces: Vec<(u32, bool)>,
        measured: groups::Measure,
    },
}

impl Piece {
    fn byte_len(&self) -> usize {
        match self {
            Piece::Vec3F32(v) => 12 * v.len(),
            Piece::Indices(i) => 4 * i.len(),
            Piece::Group { measured, .. } => 24 * measured.vertices + 12 * measured.triangles,
        }
    }

    /// Converts and writes the piece in blocks of about [`BLOCK`] bytes.
    fn write(
        &self,
        expander: &mut groups::Expander,
        block: &mut Vec<u8>,
        out: &mut dyn Write,
    ) -> std::io::Result<()> {
        match self {
            Piece::Vec3F32(v) => write_blocks(v.as_flattened(), block, out, f32::to_le_bytes),
            Piece::Indices(i) => write_blocks(i, block, out, u32::to_le_bytes),
            Piece::Group { faces, measured } => {
                let mesh = expander.mesh();
                if let ([(face, false)], Some(used)) = (faces.as_slice(), measured.identity) {
                    // One face as it is: its vertices are the mesh's first
                    // nodes and its triangles the face's own.
                    write_blocks(&mesh.nodes[..used], block, out, position)?;
                    let triangles = &mesh.faces[*face as usize].triangles;
                    groups::emit_unit_normals(mesh, triangles, None, used, &mut |run| {
                        write_blocks(run.as_flattened(), block, out, f32::to_le_bytes)
                    })?;
                    return write_blocks(triangles.as_flattened(), block, out, u32::to_le_bytes);
                }
                let mut blocks = Blocks::new(block, out);
                expander.each_vertex(faces, |n| blocks.put(&position(mesh.nodes[n as usize])))?;
                // One face's sums at a time; reserved for the whole group
                // at once (pages only count once written).
                let mut sums = Vec::with_capacity(measured.vertices);
                expander.each_normal(faces, &mut sums, |n| {
                    blocks.put(&f32x3_bytes(n.map(|c| c as f32)))
                })?;
                drop(sums);
                expander.each_triangle(faces, |t| {
                    let mut b = [0u8; 12];
                    for (slot, i) in b.chunks_exact_mut(4).zip(t) {
                        slot.copy_from_slice(&i.to_le_bytes());
                    }
                    blocks.put(&b)
                })?;
                blocks.finish()
            }
        }
    }
}

/// An `f64` position as the 12 bytes of its `f32` coordinates.
fn position(p: [f64; 3]) -> [u8; 12] {
    f32x3_bytes(p.map(|c| c as f32))
}

/// Values made one at a time, gathered into blocks of about [`BLOCK`]
/// bytes before each write.
struct Blocks<'b> {
    block: &'b mut Vec<u8>,
    out: &'b mut dyn Write,
}

impl<'b> Blocks<'b> {
    /// Starts empty (`write_blocks` leaves its last block in `block`).
    fn new(block: &'b mut Vec<u8>, out: &'b mut dyn Write) -> Blocks<'b> {
        block.clear();
        Blocks { block, out }
    }

    fn put(&mut self, bytes: &[u8]) -> std::io::Result<()> {
        self.block.extend_from_slice(bytes);
        if self.block.len() >= BLOCK {
            self.out.write_all(self.block)?;
            self.block.clear();
        }
        Ok(())
    }

    /// Writes what is left.
    fn finish(self) -> std::io::Result<()> {
        self.out.write_all(self.block)?;
        self.block.clear();
        Ok(())
    }
}

/// Bytes per block converted before a write (256 kB). Blocks go through
/// `write_atomic`'s buffer: writing them straight to the file from wherever
/// they lie made the kernel's copy into the page cache up to three times
/// slower for some offsets of the file against the memory (measured).
const BLOCK: usize = 1 << 18;

/// Three `f32` as 12 little-endian bytes.
fn f32x3_bytes(v: [f32; 3]) -> [u8; 12] {
    let mut b = [0u8; 12];
    for (slot, c) in b.chunks_exact_mut(4).zip(v) {
        slot.copy_from_slice(&c.to_le_bytes());
    }
    b
}

/// Writes `values` converted to `N` bytes each, a block at a time.
fn write_blocks<T: Copy, const N: usize>(
    values: &[T],
    block: &mut Vec<u8>,
    out: &mut dyn Write,
    bytes: impl Fn(T) -> [u8; N],
) -> std::io::Result<()> {
    for chunk in values.chunks(BLOCK.div_ceil(N)) {
        // Every byte is written below: resizing fills only when it grows.
        block.resize(N * chunk.len(), 0);
        for (slot, &v) in block.chunks_exact_mut(N).zip(chunk) {
            slot.copy_from_slice(&bytes(v));
        }
        out.write_all(block)?;
    }
    Ok(())
}

/// The JSON parts and the binary buffer's pieces, built together.
struct Document<'a> {
    mesh: &'a Mesh,
    nodes: Vec<Value>,
    meshes: Vec<Value>,
    accessors: Vec<Value>,
    views: Vec<Value>,
    pieces: Vec<Piece>,
    /// The buffer's length so far: the sum of the pieces' lengths.
    buffer_len: usize,
    scene: Vec<usize>,
    warnings: Vec<Warning>,
    /// Per face: its triangles' `node_window::block_ranges`, when the
    /// mesh's check had them from a reader.
    blocks: Vec<Option<Vec<(u32, u32)>>>,
}

impl<'a> Document<'a> {
    fn of(mesh: &'a Mesh, format: &'static str, scanned: &groups::Scanned) -> Document<'a> {
        let mut d = Document {
            mesh,
            nodes: Vec::new(),
            meshes: Vec::new(),
            accessors: Vec::new(),
            views: Vec::new(),
            pieces: Vec::new(),
            buffer_len: 0,
            scene: Vec::new(),
            warnings: Vec::new(),
            blocks: scanned.blocks.clone(),
        };
        let mut empty = Vec::new();
        let mut expander = groups::Expander::scanned(mesh, scanned);

        let mut children = Vec::new();
        for g in groups::surface_groups(mesh) {
            let m = expander.measure(&g.faces);
            if m.triangles == 0 {
                empty.push(g.name.to_string());
                continue;
            }
            let primitive = d.triangles(g.faces, m);
            children.push(d.node(g.name, primitive, extras(mesh, g.source)));
        }
        d.parent("surfaces", children);

        let mut children = Vec::new();
        for g in groups::subdomain_surfaces(mesh) {
            let m = expander.measure(&g.faces);
            if m.triangles == 0 {
                empty.push(g.name.to_string());
                continue;
            }
            let primitive = d.triangles(g.faces, m);
            children.push(d.node(g.name, primitive, extras(mesh, g.source)));
        }
        d.parent("subdomains", children);

        let mut children = Vec::new();
        for g in groups::line_groups(mesh) {
            if g.segments.is_empty() {
                empty.push(g.name.to_string());
                continue;
            }
            let (nodes, local) = compact(g.segments.iter().flatten().copied());
            let primitive = d.indexed(mesh, &nodes, Some(&local), 1);
            children.push(d.node(g.name, primitive, extras(mesh, g.source)));
        }
        d.parent("lines", children);

        let mut children = Vec::new();
        for p in &mesh.point_sets {
            if p.nodes.is_empty() {
                empty.push(p.name.clone());
                continue;
            }
            let primitive = d.indexed(mesh, &p.nodes, None, 0);
            children.push(d.node(&p.name, primitive, json!({"kind": "point_set"})));
        }
        d.parent("point_sets", children);

        if !empty.is_empty() {
            d.warnings.push(warning(
                format,
                format!(
                    "glTF meshes cannot be empty: {} without elements left out ({})",
                    count(empty.len(), "group"),
                    empty.join(", ")
                ),
            ));
        }
        d
    }

    /// Appends a piece to the buffer as a new buffer view; returns its index.
    fn view(&mut self, piece: Piece, target: u32) -> usize {
        let length = piece.byte_len();
        self.views.push(json!({
            "buffer": 0,
            "byteOffset": self.buffer_len,
            "byteLength": length,
            "target": target,
        }));
        self.buffer_len += length;
        self.pieces.push(piece);
        self.views.len() - 1
    }

    fn vec3_accessor(&mut self, values: Vec<[f64; 3]>, with_bounds: bool) -> usize {
        let count = values.len();
        // The validator compares the bounds with the stored f32 values exactly.
        let mut lo = [f32::INFINITY; 3];
        let mut hi = [f32::NEG_INFINITY; 3];
        if with_bounds {
            for v in &values {
                for k in 0..3 {
                    let c = v[k] as f32;
                    lo[k] = lo[k].min(c);
                    hi[k] = hi[k].max(c);
                }
            }
        }
        // Converted now (the same `as f32` the write would do) and the
        // `f64` copy freed.
        let piece = Piece::Vec3F32(values.iter().map(|p| p.map(|c| c as f32)).collect());
        let view = self.view(piece, ARRAY_BUFFER);
        let mut accessor = json!({
            "bufferView": view,
            "componentType": FLOAT,
            "count": count,
            "type": "VEC3",
        });
        if with_bounds {
            accessor["min"] = json!(lo);
            accessor["max"] = json!(hi);
        }
        self.accessors.push(accessor);
        self.accessors.len() - 1
    }

    fn index_accessor(&mut self, piece: Piece) -> usize {
        let count = piece.byte_len() / 4;
        let view = self.view(piece, ELEMENT_ARRAY_BUFFER);
        self.accessors.push(json!({
            "bufferView": view,
            "componentType": UNSIGNED_INT,
            "count": count,
            "type": "SCALAR",
        }));
        self.accessors.len() - 1
    }

    /// A triangle group's primitive: its three buffer views follow one
    /// another and are filled from one expansion while the buffer is written.
    fn triangles(&mut self, faces: Vec<(u32, bool)>, m: groups::Measure) -> Value {
        let first_view = self.views.len();
        let lengths = [12 * m.vertices, 12 * m.vertices, 12 * m.triangles];
        let targets = [ARRAY_BUFFER, ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER];
        let mut offset = self.buffer_len;
        for (length, target) in lengths.into_iter().zip(targets) {
            self.views.push(json!({
                "buffer": 0,
                "byteOffset": offset,
                "byteLength": length,
                "target": target,
            }));
            offset += length;
        }
        let piece = Piece::Group { faces, measured: m };
        self.buffer_len += piece.byte_len();
        self.pieces.push(piece);
        let mut accessor = |view: usize, component: u32, count: usize, kind: &str| {
            self.accessors.push(json!({
                "bufferView": first_view + view,
                "componentType": component,
                "count": count,
                "type": kind,
            }));
            self.accessors.len() - 1
        };
        let position = accessor(0, FLOAT, m.vertices, "VEC3");
        let normal = accessor(1, FLOAT, m.vertices, "VEC3");
        let indices = accessor(2, UNSIGNED_INT, 3 * m.triangles, "SCALAR");
        // The validator compares the bounds with the stored f32 values exactly.
        self.accessors[position]["min"] = json!(m.lo);
        self.accessors[position]["max"] = json!(m.hi);
        json!({
            "attributes": {"POSITION": position, "NORMAL": normal},
            "indices": indices,
            "mode": 4,
        })
    }

    /// A LINES (mode 1) or POINTS (mode 0) primitive over some mesh nodes.
    fn indexed(&mut self, mesh: &Mesh, nodes: &[u32], indices: Option<&[u32]>, mode: u32) -> Value {
        let points = nodes.iter().map(|&n| mesh.nodes[n as usize]).collect();
        let position = self.vec3_accessor(points, true);
        let mut primitive = json!({"attributes": {"POSITION": position}, "mode": mode});
        if let Some(indices) = indices {
            primitive["indices"] = json!(self.index_accessor(Piece::Indices(indices.to_vec())));
        }
        primitive
    }

    fn node(&mut self, name: &str, primitive: Value, extras: Value) -> usize {
        self.meshes
            .push(json!({"name": name, "primitives": [primitive]}));
        self.nodes.push(json!({
            "name": name,
            "mesh": self.meshes.len() - 1,
            "extras": extras,
        }));
        self.nodes.len() - 1
    }

    fn parent(&mut self, name: &str, children: Vec<usize>) {
        if children.is_empty() {
            return;
        }
        self.nodes.push(json!({"name": name, "children": children}));
        self.scene.push(self.nodes.len() - 1);
    }

    fn json(&self, uri: Option<String>) -> Vec<u8> {
        let mut root = json!({
            "asset": {"version": "2.0", "generator": "geomc"},
            "scene": 0,
            "scenes": [{"nodes": self.scene}],
        });
        if !self.nodes.is_empty() {
            root["nodes"] = json!(self.nodes);
        }
        if !self.meshes.is_empty() {
            root["meshes"] = json!(self.meshes);
            root["accessors"] = json!(self.accessors);
            root["bufferViews"] = json!(self.views);
            let mut buffer = json!({"byteLength": self.buffer_len});
            if let Some(uri) = uri {
                buffer["uri"] = json!(uri);
            }
            root["buffers"] = json!([buffer]);
        }
        // serde_json's maps are sorted: the same document gives the same bytes.
        serde_json::to_vec_pretty(&root).unwrap_or_default()
    }

    /// Writes the binary buffer's pieces in order.
    fn write_buffer(&self, out: &mut dyn Write) -> std::io::Result<()> {
        let mut block = Vec::with_capacity(BLOCK + 12);
        let mut expander = groups::Expander::new(self.mesh);
        for piece in &self.pieces {
            piece.write(&mut expander, &mut block, out)?;
        }
        Ok(())
    }

    /// The binary buffer as bytes (a `.gltf`'s side file or data URI).
    fn buffer_bytes(&self) -> Vec<u8> {
        let mut bytes = Vec::with_capacity(self.buffer_len);
        // Writing to a vector cannot fail.
        let _ = self.write_buffer(&mut bytes);
        bytes
    }
}

/// Distinct nodes in first-use order, and each input node's index among them.
fn compact(nodes: impl Iterator<Item = u32>) -> (Vec<u32>, Vec<u32>) {
    let mut seen = std::collections::HashMap::new();
    let mut distinct = Vec::new();
    let local = nodes
        .map(|n| {
            *seen.entry(n).or_insert_with(|| {
                distinct.push(n);
                (distinct.len() - 1) as u32
            })
        })
        .collect();
    (distinct, local)
}

fn extras(mesh: &Mesh, source: Source) -> Value {
    let name = |s: u32| mesh.subdomains.get(s as usize).map(|s| s.name.clone());
    match source {
        Source::Fragment(i) => {
            let Some(fr) = mesh.fragments.get(i as usize) else {
                return json!({"kind": "fragment"});
            };
            json!({
                "kind": "fragment",
                "subdomain": name(fr.subdomain),
                "other": fr.other.map_or(Some("exterior".to_string()), name),
                "subdomain_index": fr.subdomain,
                "other_index": fr.other,
            })
        }
        Source::Subdomain(i) => json!({
            "kind": "subdomain",
            "material": mesh.subdomains.get(i as usize).and_then(|s| s.material.clone()),
        }),
        Source::Face(_) => json!({"kind": "face"}),
        Source::Edge(_) => json!({"kind": "edge"}),
        Source::Polyline(_) => json!({"kind": "poly_line"}),
    }
}

/// GLB container: a 12-byte header, the JSON chunk padded with spaces and the
/// BIN chunk padded with zeros, both to 4 bytes.
fn write_glb(json: &[u8], doc: &Document, out: &mut dyn Write) -> Result<(), WriteError> {
    write_glb_head(json, doc.buffer_len, out)?;
    let bin = doc.buffer_len;
    if bin > 0 {
        doc.write_buffer(out)?;
        out.write_all(&[0u8; 3][..pad(bin)])?;
    }
    Ok(())
}

/// Bytes that pad `n` to a multiple of 4.
fn pad(n: usize) -> usize {
    (4 - n % 4) % 4
}

/// The GLB's bytes before its binary buffer: the header, the JSON chunk
/// and the BIN chunk's header (when there is a buffer of `bin` bytes).
fn write_glb_head(json: &[u8], bin: usize, out: &mut dyn Write) -> Result<(), WriteError> {
    let json_len = json.len() + pad(json.len());
    let bin_len = bin + pad(bin);
    let mut total = 12 + 8 + json_len;
    if bin > 0 {
        total += 8 + bin_len;
    }
    let total = u32::try_from(total).map_err(|_| {
        WriteError::Unsupported(format!("GLB files hold at most 4 GiB, not {total} bytes"))
    })?;
    out.write_all(b"glTF")?;
    out.write_all(&2u32.to_le_bytes())?;
    out.write_all(&total.to_le_bytes())?;
    out.write_all(&(json_len as u32).to_le_bytes())?;
    out.write_all(b"JSON")?;
    out.write_all(json)?;
    out.write_all(&b"   "[..pad(json.len())])?;
    if bin > 0 {
        out.write_all(&(bin_len as u32).to_le_bytes())?;
        out.write_all(b"BIN\0")?;
    }
    Ok(())
}

/// Binary buffers from this size on are written by [`write_glb_file`]'s
/// two sides (below it the threads' start costs more than they save).
const PARALLEL_FROM: usize = 4 << 20;

/// [`write_glb`] into a file, the same bytes: when the buffer has at least
/// `parallel_from` bytes, the parts that are copies of the mesh's values
/// (positions and indices of a face as it is, other positions and
/// indices) are cut into pieces written at their offsets, while this
/// thread writes the rest in order (normals, expanded groups) and skips
/// over them. This thread takes the pieces in step with its own progress
/// (a share of them after each run of normals), so they reach the file
/// early and mostly from one thread at a time: written last by two threads
/// at once, they waited on each other for the file (ext4 takes one write
/// into a file at a time) and left most of the file to the final sync.
/// A thread that is free (beside `convert`'s surface checks, the checks'
/// thread once done) takes the pieces left.
fn write_glb_file(
    json: &[u8],
    doc: &Document,
    out: &mut FileOutput,
    parallel_from: usize,
) -> Result<(), WriteError> {
    let bin = doc.buffer_len;
    let parts = if bin > 0 && bin >= parallel_from {
        out.parts()
    } else {
        None
    };
    let Some(parts) = parts else {
        return write_glb(json, doc, out);
    };
    write_glb_head(json, bin, out)?;
    let base = out.position();
    let (in_order, ranges) = doc.layout(base);
    let pieces = file_ranges::Pieces::of(&ranges);
    let (ordered, ranged) = rayon::join(
        || -> std::io::Result<()> {
            let mut pace = Pace {
                pieces: &pieces,
                parts: &parts,
                total: in_order.iter().map(|(_, part)| part.byte_len()).sum(),
                done: 0,
                buffer: file_ranges::piece_buffer(),
            };
            let mut block = Vec::with_capacity(BLOCK + 12);
            let mut expander = groups::Expander::new(doc.mesh);
            for (offset, part) in &in_order {
                out.skip_to(*offset)?;
                part.write(&mut expander, &mut block, out, &mut pace)?;
            }
            pace.finish()?;
            out.skip_to(base + bin as u64)?;
            out.write_all(&[0u8; 3][..pad(bin)])
        },
        || pieces.write_rest(&parts),
    );
    drop(parts);
    ordered?;
    ranged?;
    Ok(())
}

/// [`write_glb_file`]'s share of the pieces for its own thread: after `n`
/// of the `total` in-order bytes, the same fraction of the pieces.
struct Pace<'p, 'r, 'a> {
    pieces: &'p file_ranges::Pieces<'r, 'a>,
    parts: &'p super::atomic::Parts,
    total: usize,
    done: usize,
    buffer: Vec<u8>,
}

impl Pace<'_, '_, '_> {
    /// `n` more in-order bytes are written: takes the pieces due by now.
    fn wrote(&mut self, n: usize) -> std::io::Result<()> {
        self.done += n;
        let share = self.pieces.len() as u64 * self.done as u64 / self.total.max(1) as u64;
        let due = usize::try_from(share).unwrap_or(usize::MAX);
        self.pieces.write_until(self.parts, due, &mut self.buffer)
    }

    /// Takes every piece left.
    fn finish(&mut self) -> std::io::Result<()> {
        self.pieces
            .write_until(self.parts, self.pieces.len(), &mut self.buffer)
    }
}

/// What [`write_glb_file`]'s own thread writes, in order.
enum InOrder<'d> {
    /// A whole piece.
    Piece(&'d Piece),
    /// The normals of a face as it is, nodes `0..used`.
    Normals {
        triangles: &'d [[u32; 3]],
        /// The triangles' block ranges, when known.
        blocks: Option<&'d [(u32, u32)]>,
        used: usize,
    },
}

impl InOrder<'_> {
    fn byte_len(&self) -> usize {
        match self {
            InOrder::Piece(piece) => piece.byte_len(),
            InOrder::Normals { used, .. } => 12 * used,
        }
    }

    fn write(
        &self,
        expander: &mut groups::Expander,
        block: &mut Vec<u8>,
        out: &mut FileOutput,
        pace: &mut Pace,
    ) -> std::io::Result<()> {
        match self {
            InOrder::Piece(piece) => {
                piece.write(expander, block, out)?;
                pace.wrote(piece.byte_len())
            }
            InOrder::Normals {
                triangles,
                blocks,
                used,
            } => {
                groups::emit_unit_normals(expander.mesh(), triangles, *blocks, *used, &mut |run| {
                    out.write_converted(run.as_flattened(), f32::to_le_bytes)?;
                    pace.wrote(12 * run.len())
                })
            }
        }
    }
}

impl Document<'_> {
    /// The buffer's parts at their file offsets (the buffer starting at
    /// `base`): what is written in order, and the ranges any thread can make.
    fn layout(&self, base: u64) -> (Vec<(u64, InOrder<'_>)>, Vec<Range<'_>>) {
        let mesh = self.mesh;
        let mut in_order = Vec::new();
        let mut ranges = Vec::new();
        let mut offset = base;
        for piece in &self.pieces {
            let len = piece.byte_len();
            match piece {
                Piece::Vec3F32(v) => {
                    let values = v.as_flattened();
                    ranges.push(Range {
                        offset,
                        len,
                        fill: Box::new(move |from, out| {
                            fill_converted(values, f32::to_le_bytes, from, out)
                        }),
                    });
                }
                Piece::Indices(values) => ranges.push(Range {
                    offset,
                    len,
                    fill: Box::new(move |from, out| {
                        fill_converted(values, u32::to_le_bytes, from, out)
                    }),
                }),
                Piece::Group { faces, measured } => match (faces.as_slice(), measured.identity) {
                    ([(face, false)], Some(used)) => {
                        let triangles = &mesh.faces[*face as usize].triangles;
                        let nodes = &mesh.nodes[..used];
                        ranges.push(Range {
                            offset,
                            len: 12 * used,
                            fill: Box::new(move |from, out| {
                                fill_converted(nodes, position, from, out)
                            }),
                        });
                        let normals = offset + 12 * used as u64;
                        let blocks = self.blocks.get(*face as usize).and_then(|b| b.as_deref());
                        in_order.push((
                            normals,
                            InOrder::Normals {
                                triangles,
                                blocks,
                                used,
                            },
                        ));
                        ranges.push(Range {
                            offset: normals + 12 * used as u64,
                            len: 12 * triangles.len(),
                            fill: Box::new(move |from, out| {
                                fill_converted(
                                    triangles.as_flattened(),
                                    u32::to_le_bytes,
                                    from,
                                    out,
                                )
                            }),
                        });
                    }
                    _ => in_order.push((offset, InOrder::Piece(piece))),
                },
            }
            offset += len as u64;
        }
        (in_order, ranges)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::formats::mesh_facts::FaceFacts;
    use crate::mesh::{MeshFace, MeshPolyline};

    /// A wavy strip of `n` triangles over nodes numbered in first-use order.
    fn strip(n: u32) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        let nodes = (0..n + 2)
            .map(|i| {
                let x = f64::from(i / 2) * 0.01;
                [x, f64::from(i % 2), (x * 3.0).sin()]
            })
            .collect();
        let triangles = (0..n)
            .map(|i| {
                if i % 2 == 0 {
                    [i, i + 1, i + 2]
                } else {
                    [i + 1, i, i + 2]
                }
            })
            .collect();
        (nodes, triangles)
    }

    fn face(name: &str, triangles: Vec<[u32; 3]>) -> MeshFace {
        MeshFace {
            name: name.into(),
            triangles,
            boundary: Vec::new(),
        }
    }

    /// The GLB written with its copied parts made by offset (threshold 0)
    /// is the GLB written in order, byte for byte.
    fn written_by_parts_equals_in_order(mesh: &Mesh, ranges: usize, in_order: usize) {
        let mut whole = Vec::new();
        GLB.write(mesh, &WriteOptions::default(), &mut whole)
            .expect("written in order");
        let dir = tempfile::tempdir().expect("temporary folder");
        let path = dir.path().join("parts.glb");
        // Checked by scanning, and with a reader's facts of the mesh.
        let faces = mesh
            .faces
            .iter()
            .map(|f| FaceFacts::of(&f.triangles))
            .collect();
        let facts = MeshFacts::of(&mesh.nodes, faces).expect("finite nodes");
        for facts in [None, Some(&facts)] {
            super::super::write_atomic_file(&path, |out| {
                let (doc, _) = GLB.document(mesh, facts, &WriteOptions::default())?;
                let (order, parts) = doc.layout(0);
                assert_eq!((parts.len(), order.len()), (ranges, in_order));
                let planned = doc.blocks.iter().filter(|b| b.is_some()).count();
                let known = if facts.is_some() { mesh.faces.len() } else { 0 };
                assert_eq!(planned, known);
                write_glb_file(&doc.json(None), &doc, out, 0)
            })
            .expect("written by parts");
            assert_eq!(std::fs::read(&path).expect("read back"), whole);
        }
    }

    #[test]
    fn a_face_as_it_is_written_by_parts_gives_the_same_bytes() {
        // 150,000 triangles: 1.8 MB of indices, several pieces each.
        let (nodes, triangles) = strip(150_000);
        let mesh = Mesh {
            dimension: 3,
            nodes,
            faces: vec![face("strip", triangles)],
            ..Mesh::default()
        };
        // Positions and indices by offset, the normals in order.
        written_by_parts_equals_in_order(&mesh, 2, 1);
    }

    #[test]
    fn expanded_groups_lines_and_points_written_by_parts_give_the_same_bytes() {
        let (nodes, triangles) = strip(30_000);
        let (first, second) = triangles.split_at(12_345);
        let mut flipped: Vec<[u32; 3]> = second.to_vec();
        flipped.reverse();
        let mesh = Mesh {
            dimension: 3,
            nodes,
            faces: vec![face("a", first.to_vec()), face("b", flipped)],
            polylines: vec![MeshPolyline {
                name: "rail".into(),
                nodes: (0..5_000).map(|i| 2 * i).collect(),
            }],
            point_sets: vec![MeshPolyline {
                name: "marks".into(),
                nodes: vec![7, 3, 30_001],
            }],
            ..Mesh::default()
        };
        // Face `a` is as it is (positions and indices by offset, normals in
        // order); face `b` is renumbered (in order); the poly_line's
        // positions and indices and the point set's positions by offset.
        written_by_parts_equals_in_order(&mesh, 5, 2);
    }

    /// A fragment of two large faces, the first with its triangles in
    /// reverse order of their nodes' first use, the second turned over: the
    /// GLB's bytes are the same on one thread and on three (a guard for any
    /// later parallel making of normals; session 22's blocked one was slower).
    #[test]
    fn a_large_expanded_group_gives_the_same_bytes_on_any_thread_count() {
        use crate::mesh::{MeshFragment, MeshSubdomain};
        let (nodes, triangles) = strip(60_000);
        let (first, second) = triangles.split_at(40_000);
        let mut scrambled = first.to_vec();
        scrambled.reverse();
        let mesh = Mesh {
            dimension: 3,
            nodes,
            faces: vec![face("a", scrambled), face("b", second.to_vec())],
            subdomains: vec![MeshSubdomain {
                name: "inside".into(),
                material: None,
                faces: vec![(0, true), (1, false)],
            }],
            fragments: vec![MeshFragment {
                name: "skin".into(),
                subdomain: 0,
                other: None,
                faces: vec![0, 1],
                edges: Vec::new(),
            }],
            ..Mesh::default()
        };
        let glb = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("a thread pool");
            let mut out = Vec::new();
            pool.install(|| GLB.write(&mesh, &WriteOptions::default(), &mut out))
                .expect("written");
            out
        };
        let one = glb(1);
        // Positions, normals and indices of 60,002 + 2 vertices (the
        // faces share two nodes) and 60,000 triangles, and the JSON.
        assert!(one.len() > 24 * 60_004 + 12 * 60_000);
        assert!(glb(3) == one, "three threads against one");
    }
}
