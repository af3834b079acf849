//! glTF 2.0, as `.gltf` (JSON; the buffer in a side file `NAME.bin` when the
//! file name is known, else embedded as a base64 data URI) or `.glb` (one
//! binary file). The scene has up to four parent nodes: `surfaces` (a node and
//! mesh per fragment in 3D, per region in 2D, per face outside those),
//! `subdomains` (3D: each subdomain's whole boundary, outward), `lines`
//! (LINES: 2D fragments, edges, poly_lines) and `point_sets` (POINTS).
//! Triangles carry vertex normals, smooth within a face and flat across its
//! edges; each node's `extras` say what it is and, for a fragment, its
//! subdomain pair. Floats are `f32`, as glTF requires.

use super::groups::{self, Source};
use super::{MeshWriter, SideFile, Warning, WriteError, WriteOptions, base64, count, warning};
use crate::mesh::Mesh;
use serde_json::{Value, json};
use std::borrow::Cow;
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
        groups::check(mesh)?;
        let doc = Document::of(mesh, self.name());
        let mut warnings = doc.warnings.clone();
        warnings.extend(groups::dropped_volumes(self.name(), mesh));
        if options.encoding.is_some() {
            warnings.push(warning(
                self.name(),
                "glTF has one encoding: the encoding option is ignored",
            ));
        }
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

    fn side_files(&self, mesh: &Mesh, options: &WriteOptions) -> Result<Vec<SideFile>, WriteError> {
        if self.glb {
            return Ok(Vec::new());
        }
        groups::check(mesh)?;
        Ok(match bin_name(options) {
            Some(name) => vec![SideFile {
                name,
                bytes: Document::of(mesh, self.name()).buffer_bytes(),
            }],
            None => Vec::new(),
        })
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
/// triangles, an expansion's vectors) and converted while it is written: no
/// copy of the whole buffer is built before the output.
enum Piece<'a> {
    /// Vectors written as three little-endian `f32`.
    Vec3(&'a [[f64; 3]]),
    /// Vectors made for this output (an expansion's positions and normals),
    /// kept as the `f32` they are written as, packed into the front of their
    /// own `f64` storage ([`pack_f32`]): `values` of them.
    PackedF32 { words: Vec<[f64; 3]>, values: usize },
    /// Triangle corners written as little-endian `u32`.
    Triangles(Cow<'a, [[u32; 3]]>),
    /// Indices written as little-endian `u32`.
    Indices(Vec<u32>),
}

impl Piece<'_> {
    fn byte_len(&self) -> usize {
        match self {
            Piece::Vec3(v) => 12 * v.len(),
            Piece::PackedF32 { values, .. } => 4 * values,
            Piece::Triangles(t) => 12 * t.len(),
            Piece::Indices(i) => 4 * i.len(),
        }
    }

    /// Converts and writes the piece in blocks of `BLOCK` values.
    fn write(&self, block: &mut Vec<u8>, out: &mut dyn Write) -> std::io::Result<()> {
        match self {
            Piece::Vec3(v) => {
                write_blocks(v.as_flattened(), block, out, |c| (c as f32).to_le_bytes())
            }
            Piece::PackedF32 { words, values } => {
                let words = words.as_flattened();
                let (pairs, odd) = (values / 2, values % 2 == 1);
                let whole = words.get(..pairs).unwrap_or_default();
                write_blocks(whole, block, out, |w| w.to_bits().to_le_bytes())?;
                match words.get(pairs) {
                    Some(last) if odd => out.write_all(&last.to_bits().to_le_bytes()[..4]),
                    _ => Ok(()),
                }
            }
            Piece::Triangles(t) => write_blocks(t.as_flattened(), block, out, u32::to_le_bytes),
            Piece::Indices(i) => write_blocks(i, block, out, u32::to_le_bytes),
        }
    }
}

/// Values per block converted before a write (256 kB of output).
const BLOCK: usize = 1 << 16;

fn write_blocks<T: Copy, const N: usize>(
    values: &[T],
    block: &mut Vec<u8>,
    out: &mut dyn Write,
    bytes: impl Fn(T) -> [u8; N],
) -> std::io::Result<()> {
    for chunk in values.chunks(4 * BLOCK / N) {
        block.clear();
        block.resize(N * chunk.len(), 0);
        for (slot, &v) in block.chunks_exact_mut(N).zip(chunk) {
            slot.copy_from_slice(&bytes(v));
        }
        out.write_all(block)?;
    }
    Ok(())
}

/// Vectors' coordinates as `f32`, packed two a word into the front of
/// their own `f64` storage (the first of a pair in the low half): the first
/// words' little-endian bytes are the `f32` values' bytes in order. Word `k`
/// takes values `2k` and `2k + 1`, which no earlier word overwrote.
fn pack_f32(mut v: Vec<[f64; 3]>) -> Piece<'static> {
    let flat = v.as_flattened_mut();
    let values = flat.len();
    for k in 0..values.div_ceil(2) {
        let c = |i: usize| flat.get(i).map_or(0, |&c| (c as f32).to_bits());
        let word = u64::from(c(2 * k)) | (u64::from(c(2 * k + 1)) << 32);
        if let Some(w) = flat.get_mut(k) {
            *w = f64::from_bits(word);
        }
    }
    Piece::PackedF32 { words: v, values }
}

/// The JSON parts and the binary buffer's pieces, built together.
struct Document<'a> {
    nodes: Vec<Value>,
    meshes: Vec<Value>,
    accessors: Vec<Value>,
    views: Vec<Value>,
    pieces: Vec<Piece<'a>>,
    /// The buffer's length so far: the sum of the pieces' lengths.
    buffer_len: usize,
    scene: Vec<usize>,
    warnings: Vec<Warning>,
}

impl<'a> Document<'a> {
    fn of(mesh: &'a Mesh, format: &'static str) -> Document<'a> {
        let mut d = Document {
            nodes: Vec::new(),
            meshes: Vec::new(),
            accessors: Vec::new(),
            views: Vec::new(),
            pieces: Vec::new(),
            buffer_len: 0,
            scene: Vec::new(),
            warnings: Vec::new(),
        };
        let mut empty = Vec::new();
        let mut expander = groups::Expander::new(mesh);

        let mut children = Vec::new();
        for g in groups::surface_groups(mesh) {
            let ex = expander.expand(&g.faces);
            if ex.triangles.is_empty() {
                empty.push(g.name.to_string());
                continue;
            }
            let primitive = d.triangles(ex);
            children.push(d.node(g.name, primitive, extras(mesh, g.source)));
        }
        d.parent("surfaces", children);

        let mut children = Vec::new();
        for g in groups::subdomain_surfaces(mesh) {
            let ex = expander.expand(&g.faces);
            if ex.triangles.is_empty() {
                empty.push(g.name.to_string());
                continue;
            }
            let primitive = d.triangles(ex);
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
    fn view(&mut self, piece: Piece<'a>, target: u32) -> usize {
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

    fn vec3_accessor(&mut self, values: Cow<'a, [[f64; 3]]>, with_bounds: bool) -> usize {
        let count = values.len();
        // The validator compares the bounds with the stored f32 values exactly.
        let mut lo = [f32::INFINITY; 3];
        let mut hi = [f32::NEG_INFINITY; 3];
        if with_bounds {
            for v in values.iter() {
                for k in 0..3 {
                    let c = v[k] as f32;
                    lo[k] = lo[k].min(c);
                    hi[k] = hi[k].max(c);
                }
            }
        }
        let piece = match values {
            Cow::Borrowed(v) => Piece::Vec3(v),
            // Converted now (the same `as f32` the write would do) into the
            // front of the same storage: the document holds every group's
            // vectors until the buffer is written, and a second vector for
            // the `f32` values cost fresh pages (page faults) and a pass.
            Cow::Owned(v) => pack_f32(v),
        };
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

    fn index_accessor(&mut self, piece: Piece<'a>) -> usize {
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

    fn triangles(&mut self, ex: groups::Expanded<'a>) -> Value {
        let position = self.vec3_accessor(ex.positions, true);
        let normal = self.vec3_accessor(Cow::Owned(ex.normals), false);
        let indices = self.index_accessor(Piece::Triangles(ex.triangles));
        json!({
            "attributes": {"POSITION": position, "NORMAL": normal},
            "indices": indices,
            "mode": 4,
        })
    }

    /// A LINES (mode 1) or POINTS (mode 0) primitive over some mesh nodes.
    fn indexed(&mut self, mesh: &Mesh, nodes: &[u32], indices: Option<&[u32]>, mode: u32) -> Value {
        let points = nodes.iter().map(|&n| mesh.nodes[n as usize]).collect();
        let position = self.vec3_accessor(Cow::Owned(points), true);
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
        let mut block = Vec::with_capacity(4 * BLOCK);
        for piece in &self.pieces {
            piece.write(&mut block, out)?;
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
    let pad = |n: usize| (4 - n % 4) % 4;
    let json_len = json.len() + pad(json.len());
    let bin = doc.buffer_len;
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
        doc.write_buffer(out)?;
        out.write_all(&[0u8; 3][..pad(bin)])?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The packed piece writes the same bytes as converting each value.
    #[test]
    fn packed_f32_values_write_as_converted_ones() {
        for count in [0usize, 1, 2, 3, 5, 70_000] {
            let v: Vec<[f64; 3]> = (0..count)
                .map(|i| {
                    let x = i as f64;
                    [x * 0.1, -x / 3.0, 1e-40 * x]
                })
                .collect();
            let expected: Vec<u8> = v
                .as_flattened()
                .iter()
                .flat_map(|&c| (c as f32).to_le_bytes())
                .collect();
            let piece = pack_f32(v);
            assert_eq!(piece.byte_len(), expected.len());
            let mut out = Vec::new();
            piece.write(&mut Vec::new(), &mut out).expect("to memory");
            assert_eq!(out, expected, "{count} vectors");
        }
    }
}
