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
use rayon::prelude::*;
use serde_json::{Value, json};
use std::collections::BTreeMap;
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
            write_glb(&json, &doc.buffer, out)?;
        } else {
            let uri = match bin_name(options) {
                Some(name) => percent_encode(&name),
                None => format!(
                    "data:application/octet-stream;base64,{}",
                    base64::encode(&doc.buffer)
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
                bytes: Document::of(mesh, self.name()).buffer,
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

/// The JSON parts and the binary buffer, built together.
struct Document {
    nodes: Vec<Value>,
    meshes: Vec<Value>,
    accessors: Vec<Value>,
    views: Vec<Value>,
    buffer: Vec<u8>,
    scene: Vec<usize>,
    warnings: Vec<Warning>,
}

impl Document {
    fn of(mesh: &Mesh, format: &'static str) -> Document {
        let mut d = Document {
            nodes: Vec::new(),
            meshes: Vec::new(),
            accessors: Vec::new(),
            views: Vec::new(),
            buffer: Vec::new(),
            scene: Vec::new(),
            warnings: Vec::new(),
        };
        let mut empty = Vec::new();
        // Groups go in windows of about a third of the mesh's triangles:
        // each (face, orientation) a window uses is expanded once, in
        // parallel, and a group is its faces' parts in order; memory holds
        // one window's parts, not the whole expanded mesh.
        let triangles_of = |g: &groups::SurfaceGroup| -> usize {
            g.faces
                .iter()
                .map(|&(f, _)| mesh.faces[f as usize].triangles.len())
                .sum()
        };
        let total: usize = mesh.faces.iter().map(|f| f.triangles.len()).sum();
        let budget = (total / 3).max(1 << 16);
        for (name, list) in [
            ("surfaces", groups::surface_groups(mesh)),
            ("subdomains", groups::subdomain_surfaces(mesh)),
        ] {
            let mut children = Vec::new();
            let mut start = 0;
            while start < list.len() {
                let mut end = start;
                let mut window = 0;
                while end < list.len()
                    && (end == start || window + triangles_of(&list[end]) <= budget)
                {
                    window += triangles_of(&list[end]);
                    end += 1;
                }
                let mut parts = Parts::of(mesh, &list[start..end]);
                for g in &list[start..end] {
                    let used: Vec<&Part> =
                        g.faces.iter().filter_map(|key| parts.get(key)).collect();
                    if used.iter().all(|p| p.triangles.is_empty()) {
                        empty.push(g.name.to_string());
                        parts.release(&g.faces);
                        continue;
                    }
                    let primitive = d.triangles(&used);
                    parts.release(&g.faces);
                    children.push(d.node(g.name, primitive, extras(mesh, g.source)));
                }
                start = end;
            }
            d.parent(name, children);
        }

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

    /// Records `self.buffer[offset..]` as a new buffer view; returns its index.
    fn view(&mut self, offset: usize, target: u32) -> usize {
        self.views.push(json!({
            "buffer": 0,
            "byteOffset": offset,
            "byteLength": self.buffer.len() - offset,
            "target": target,
        }));
        self.views.len() - 1
    }

    /// Writes the values straight into the buffer (no copy in between).
    fn vec3_accessor(
        &mut self,
        values: impl ExactSizeIterator<Item = [f32; 3]>,
        with_bounds: bool,
    ) -> usize {
        let count = values.len();
        let offset = self.buffer.len();
        self.buffer.reserve(count * 12);
        // The validator compares the bounds with the stored f32 values exactly.
        let mut lo = [f32::INFINITY; 3];
        let mut hi = [f32::NEG_INFINITY; 3];
        for v in values {
            let mut record = [0u8; 12];
            for k in 0..3 {
                record[4 * k..4 * k + 4].copy_from_slice(&v[k].to_le_bytes());
                lo[k] = lo[k].min(v[k]);
                hi[k] = hi[k].max(v[k]);
            }
            self.buffer.extend_from_slice(&record);
        }
        let view = self.view(offset, ARRAY_BUFFER);
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

    fn index_accessor(&mut self, indices: impl ExactSizeIterator<Item = u32>) -> usize {
        let count = indices.len();
        let offset = self.buffer.len();
        self.buffer.reserve(count * 4);
        for i in indices {
            self.buffer.extend_from_slice(&i.to_le_bytes());
        }
        let view = self.view(offset, ELEMENT_ARRAY_BUFFER);
        self.accessors.push(json!({
            "bufferView": view,
            "componentType": UNSIGNED_INT,
            "count": count,
            "type": "SCALAR",
        }));
        self.accessors.len() - 1
    }

    /// One TRIANGLES primitive over some faces' parts, in order.
    fn triangles(&mut self, parts: &[&Part]) -> Value {
        let vertices: usize = parts.iter().map(|p| p.positions.len()).sum();
        let triangles: usize = parts.iter().map(|p| p.triangles.len()).sum();
        // Positions, normals and indices in one reservation (three would
        // reallocate and copy the buffer twice).
        self.buffer.reserve(24 * vertices + 12 * triangles);
        let position = self.vec3_accessor(
            ExactLen(
                vertices,
                parts.iter().flat_map(|p| p.positions.iter().copied()),
            ),
            true,
        );
        let normal = self.vec3_accessor(
            ExactLen(
                vertices,
                parts.iter().flat_map(|p| p.normals.iter().copied()),
            ),
            false,
        );
        // Each part numbers its vertices from 0: shifted by the vertices before it.
        let mut base = 0u32;
        let shifted = parts.iter().flat_map(|p| {
            let offset = base;
            base += p.positions.len() as u32;
            p.triangles.as_flattened().iter().map(move |i| i + offset)
        });
        let indices = self.index_accessor(ExactLen(3 * triangles, shifted));
        json!({
            "attributes": {"POSITION": position, "NORMAL": normal},
            "indices": indices,
            "mode": 4,
        })
    }

    /// A LINES (mode 1) or POINTS (mode 0) primitive over some mesh nodes.
    fn indexed(&mut self, mesh: &Mesh, nodes: &[u32], indices: Option<&[u32]>, mode: u32) -> Value {
        let position = self.vec3_accessor(
            nodes
                .iter()
                .map(|&n| mesh.nodes[n as usize].map(|c| c as f32)),
            true,
        );
        let mut primitive = json!({"attributes": {"POSITION": position}, "mode": mode});
        if let Some(indices) = indices {
            primitive["indices"] = json!(self.index_accessor(indices.iter().copied()));
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
            let mut buffer = json!({"byteLength": self.buffer.len()});
            if let Some(uri) = uri {
                buffer["uri"] = json!(uri);
            }
            root["buffers"] = json!([buffer]);
        }
        // serde_json's maps are sorted: the same document gives the same bytes.
        serde_json::to_vec_pretty(&root).unwrap_or_default()
    }
}

/// One face's triangles with vertices of their own (see
/// [`groups::Expander`]), in glTF's `f32`, vertices numbered from 0.
struct Part {
    positions: Vec<[f32; 3]>,
    normals: Vec<[f32; 3]>,
    triangles: Vec<[u32; 3]>,
}

/// The parts groups use, each computed once and handed out until its last
/// user took it (then dropped, so they do not all stay alive).
struct Parts {
    parts: BTreeMap<(u32, bool), (Part, usize)>,
}

impl Parts {
    fn of(mesh: &Mesh, groups: &[groups::SurfaceGroup]) -> Parts {
        let mut uses: BTreeMap<(u32, bool), usize> = BTreeMap::new();
        for g in groups {
            for key in &g.faces {
                *uses.entry(*key).or_default() += 1;
            }
        }
        let keys: Vec<((u32, bool), usize)> = uses.into_iter().collect();
        // Faces in parallel, each thread with its own node table; the result
        // is the same for any thread count (a part depends on its face only).
        let parts = keys
            .par_iter()
            .map_init(
                || groups::Expander::new(mesh),
                |expander, &(key, n)| {
                    let ex = expander.expand(&[key]);
                    let f32s = |v: &Vec<[f64; 3]>| v.iter().map(|p| p.map(|c| c as f32)).collect();
                    let part = Part {
                        positions: f32s(&ex.positions),
                        normals: f32s(&ex.normals),
                        triangles: ex.triangles,
                    };
                    (key, (part, n))
                },
            )
            .collect();
        Parts { parts }
    }

    fn get(&self, key: &(u32, bool)) -> Option<&Part> {
        self.parts.get(key).map(|(part, _)| part)
    }

    /// A group is done with these parts: drop those no later group uses.
    fn release(&mut self, keys: &[(u32, bool)]) {
        for key in keys {
            if let Some((_, uses)) = self.parts.get_mut(key) {
                *uses -= 1;
                if *uses == 0 {
                    self.parts.remove(key);
                }
            }
        }
    }
}

/// An iterator with its length told (chains of parts are not `ExactSizeIterator`).
struct ExactLen<I>(usize, I);

impl<I: Iterator> Iterator for ExactLen<I> {
    type Item = I::Item;

    fn next(&mut self) -> Option<I::Item> {
        let item = self.1.next()?;
        self.0 = self.0.saturating_sub(1);
        Some(item)
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        (self.0, Some(self.0))
    }
}

impl<I: Iterator> ExactSizeIterator for ExactLen<I> {}

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
fn write_glb(json: &[u8], bin: &[u8], out: &mut dyn Write) -> Result<(), WriteError> {
    let pad = |n: usize| (4 - n % 4) % 4;
    let json_len = json.len() + pad(json.len());
    let bin_len = bin.len() + pad(bin.len());
    let mut total = 12 + 8 + json_len;
    if !bin.is_empty() {
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
    if !bin.is_empty() {
        out.write_all(&(bin_len as u32).to_le_bytes())?;
        out.write_all(b"BIN\0")?;
        out.write_all(bin)?;
        out.write_all(&[0u8; 3][..pad(bin.len())])?;
    }
    Ok(())
}
