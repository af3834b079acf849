//! glTF 2.0 (`.gltf` with data-URI or side-file buffers) and GLB. The default
//! scene's nodes are walked with their transforms (matrix or TRS; a mirroring
//! transform reverses triangle winding, as the specification says); each
//! node with a mesh is a group named by the node (else its mesh). Triangle,
//! line and point primitives (strips, loops and fans converted) are kept;
//! positions repeated across primitives are merged, since glTF repeats them
//! for normals and texture coordinates that the mesh IR does not hold.
//! geomc's own files carry `extras.kind`: `subdomain` nodes repeat fragment
//! triangles and are read as subdomain names only; `fragment` nodes give the
//! fragment's subdomain pair. serde_json rather than the gltf crate: the
//! reader needs error positions and no images.

use super::build::{Builder, FragmentInfo, NodeDedup};
use super::{ReadLimits, base64, check_named_file, error_at, error_at_byte};
use crate::diag::{Code, Diagnostic};
use serde_json::Value;
use std::path::Path;

type M4 = [[f64; 4]; 4];

const IDENTITY: M4 = [
    [1.0, 0.0, 0.0, 0.0],
    [0.0, 1.0, 0.0, 0.0],
    [0.0, 0.0, 1.0, 0.0],
    [0.0, 0.0, 0.0, 1.0],
];

pub fn read(bytes: &[u8], folder: &Path, limits: &ReadLimits) -> Result<Builder, Vec<Diagnostic>> {
    let (json_bytes, json_offset, bin) = if bytes.starts_with(b"glTF") {
        split_glb(bytes)?
    } else {
        (bytes, None, None)
    };
    let root: Value = serde_json::from_slice(json_bytes).map_err(|e| {
        let offset = offset_of(json_bytes, e.line(), e.column());
        vec![match json_offset {
            Some(base) => error_at_byte(
                Code::MeshSyntax,
                base + offset,
                format!("malformed glTF JSON: {e}"),
            ),
            None => error_at(
                Code::MeshSyntax,
                offset,
                offset + 1,
                format!("malformed glTF JSON: {e}"),
            ),
        }]
    })?;
    check_asset(&root).map_err(|d| vec![d])?;
    let mut r = Reader {
        root: &root,
        buffers: Vec::new(),
        b: Builder::new(),
        dedup: NodeDedup::default(),
        converted: 0,
        skipped_modes: 0,
        limits: *limits,
        elements: std::cell::Cell::new(0),
    };
    r.load_buffers(bin, folder).map_err(|d| vec![d])?;
    r.walk().map_err(|d| vec![d])?;
    Ok(r.finish())
}

/// The JSON chunk, its byte offset, and the BIN chunk of a GLB.
#[allow(clippy::type_complexity)]
fn split_glb(bytes: &[u8]) -> Result<(&[u8], Option<usize>, Option<&[u8]>), Vec<Diagnostic>> {
    let u32_at = |at: usize| -> Option<u32> { super::bytes_at(bytes, at).map(u32::from_le_bytes) };
    let fail = |at: usize, code: Code, msg: String| Err(vec![error_at_byte(code, at, msg)]);
    let Some(version) = u32_at(4) else {
        return fail(
            bytes.len(),
            Code::MeshTruncated,
            "the GLB header is cut short".into(),
        );
    };
    if version != 2 {
        return fail(
            4,
            Code::MeshUnsupportedVersion,
            format!("GLB version {version}: geomc reads glTF 2.0"),
        );
    }
    let total = u32_at(8).unwrap_or(0) as usize;
    if total != bytes.len() {
        return fail(
            8,
            if total > bytes.len() {
                Code::MeshTruncated
            } else {
                Code::MeshCountMismatch
            },
            format!(
                "the GLB header says {total} bytes, the file has {}",
                bytes.len()
            ),
        );
    }
    let (Some(json_len), Some(kind)) = (u32_at(12), u32_at(16)) else {
        return fail(
            bytes.len(),
            Code::MeshTruncated,
            "the GLB has no JSON chunk".into(),
        );
    };
    if kind != 0x4E4F_534A {
        return fail(
            16,
            Code::MeshSyntax,
            "the first GLB chunk is not JSON".into(),
        );
    }
    let json_end = 20 + json_len as usize;
    let Some(json) = bytes.get(20..json_end) else {
        return fail(
            12,
            Code::MeshTruncated,
            format!("the JSON chunk of {json_len} bytes runs past the end of the file"),
        );
    };
    let mut bin = None;
    if json_end + 8 <= bytes.len() {
        let len = u32_at(json_end).unwrap_or(0) as usize;
        let kind = u32_at(json_end + 4).unwrap_or(0);
        if kind == 0x004E_4942 {
            let start = json_end + 8;
            let Some(chunk) = bytes.get(start..start + len) else {
                return fail(
                    json_end,
                    Code::MeshTruncated,
                    format!("the BIN chunk of {len} bytes runs past the end of the file"),
                );
            };
            bin = Some(chunk);
        }
    }
    Ok((json, Some(20), bin))
}

/// serde_json's 1-based line and column to a byte offset.
fn offset_of(text: &[u8], line: usize, column: usize) -> usize {
    let mut offset = 0;
    for _ in 1..line {
        match text
            .get(offset..)
            .and_then(|t| t.iter().position(|&b| b == b'\n'))
        {
            Some(i) => offset += i + 1,
            None => break,
        }
    }
    (offset + column.saturating_sub(1)).min(text.len())
}

struct Reader<'a> {
    root: &'a Value,
    buffers: Vec<std::borrow::Cow<'a, [u8]>>,
    b: Builder,
    dedup: NodeDedup,
    converted: usize,
    skipped_modes: usize,
    limits: ReadLimits,
    /// Accessor elements decoded so far (checked against `limits.max_elements`).
    elements: std::cell::Cell<u64>,
}

fn bad(path: &str, message: impl Into<String>) -> Diagnostic {
    Diagnostic::new(
        Code::GltfInvalid,
        None,
        format!("{path}: {}", message.into()),
    )
}

fn list<'v>(root: &'v Value, key: &str) -> &'v [Value] {
    root.get(key)
        .and_then(Value::as_array)
        .map_or(&[], Vec::as_slice)
}

fn uint(v: &Value, key: &str, path: &str) -> Result<Option<usize>, Diagnostic> {
    match v.get(key) {
        None => Ok(None),
        Some(x) => x.as_u64().map(|n| Some(n as usize)).ok_or_else(|| {
            bad(
                &format!("{path}.{key}"),
                format!("`{x}` is not a non-negative integer"),
            )
        }),
    }
}

/// A glTF document is a JSON object whose `asset.version` is 2.x: anything
/// else (an array, a glTF 1.0 file) would read as an empty or wrong mesh.
fn check_asset(root: &Value) -> Result<(), Diagnostic> {
    if !root.is_object() {
        return Err(bad("the document", "a JSON value that is not an object"));
    }
    match root
        .get("asset")
        .and_then(|a| a.get("version"))
        .and_then(Value::as_str)
    {
        Some(v) if v.starts_with("2.") => Ok(()),
        Some(v) => Err(Diagnostic::new(
            Code::MeshUnsupportedVersion,
            None,
            format!("glTF asset.version is `{v}`: geomc reads glTF 2.x"),
        )),
        None => Err(bad("asset", "no asset.version string (glTF requires it)")),
    }
}

/// `scheme:` before any `/` (RFC 3986), as in `file:`, `http:`; a one-letter
/// scheme is a Windows drive (`C:`), which is an absolute path too.
fn has_scheme(uri: &str) -> bool {
    match uri.split_once(':') {
        Some((scheme, _)) => {
            !scheme.is_empty()
                && scheme.starts_with(|c: char| c.is_ascii_alphabetic())
                && scheme
                    .chars()
                    .all(|c| c.is_ascii_alphanumeric() || matches!(c, '+' | '-' | '.'))
        }
        None => false,
    }
}

impl<'a> Reader<'a> {
    fn load_buffers(&mut self, bin: Option<&'a [u8]>, folder: &Path) -> Result<(), Diagnostic> {
        let mut total = 0u64;
        for (i, buf) in list(self.root, "buffers").iter().enumerate() {
            let path = format!("buffers[{i}]");
            let length = uint(buf, "byteLength", &path)?.unwrap_or(0);
            let data: std::borrow::Cow<[u8]> = match buf.get("uri").and_then(Value::as_str) {
                None => match bin {
                    Some(b) if i == 0 => std::borrow::Cow::Borrowed(b),
                    _ => {
                        return Err(bad(
                            &path,
                            "a buffer without a uri outside a GLB's first buffer",
                        ));
                    }
                },
                Some(uri) if uri.starts_with("data:") => {
                    let data = uri
                        .split_once(";base64,")
                        .map(|(_, d)| d)
                        .ok_or_else(|| bad(&path, "a data URI that is not base64"))?;
                    std::borrow::Cow::Owned(
                        base64::decode(data.as_bytes())
                            .ok_or_else(|| bad(&path, "the data URI is not valid base64"))?,
                    )
                }
                Some(uri) if has_scheme(uri) => {
                    return Err(bad(
                        &path,
                        format!(
                            "buffer uri `{uri}` is not a file beside the glTF: geomc reads only relative file names and data: URIs, never other schemes"
                        ),
                    ));
                }
                Some(uri) => {
                    let name = percent_decode(uri);
                    if name.contains("..") || Path::new(&name).is_absolute() {
                        return Err(bad(
                            &path,
                            format!("buffer file `{name}` is outside the glTF's folder"),
                        ));
                    }
                    let file = folder.join(&name);
                    check_named_file(
                        &file,
                        &format!("{path}: the buffer file"),
                        self.limits.max_file_size,
                    )?;
                    std::borrow::Cow::Owned(std::fs::read(&file).map_err(|e| {
                        Diagnostic::new(
                            Code::MeshReadFailed,
                            None,
                            format!("{path}: cannot read buffer file {}: {e}", file.display()),
                        )
                    })?)
                }
            };
            if data.len() < length {
                return Err(Diagnostic::new(
                    Code::MeshTruncated,
                    None,
                    format!(
                        "{path}: byteLength is {length}, the data has {} bytes",
                        data.len()
                    ),
                ));
            }
            total = total.saturating_add(data.len() as u64);
            if total > self.limits.max_file_size {
                return Err(Diagnostic::new(
                    Code::GltfBuffersTooLarge,
                    None,
                    format!(
                        "{path}: the buffers read so far hold {total} bytes, over the limit of {} bytes",
                        self.limits.max_file_size
                    ),
                )
                .with_help("raise the limit with --max-file-size BYTES"));
            }
            self.buffers.push(data);
        }
        Ok(())
    }

    /// Walks the default scene (or every root node when there is no scene).
    fn walk(&mut self) -> Result<(), Diagnostic> {
        let nodes = list(self.root, "nodes");
        let roots: Vec<usize> =
            match list(self.root, "scenes").get(uint(self.root, "scene", "scene")?.unwrap_or(0)) {
                Some(scene) => list(scene, "nodes")
                    .iter()
                    .filter_map(|v| v.as_u64().map(|n| n as usize))
                    .collect(),
                None => {
                    let mut child = vec![false; nodes.len()];
                    for n in nodes {
                        for c in list(n, "children") {
                            if let Some(c) = c.as_u64().and_then(|c| child.get_mut(c as usize)) {
                                *c = true;
                            }
                        }
                    }
                    child
                        .iter()
                        .enumerate()
                        .filter(|&(_, &c)| !c)
                        .map(|(i, _)| i)
                        .collect()
                }
            };
        let mut visited = vec![false; nodes.len()];
        let mut stack: Vec<(usize, M4)> = roots.into_iter().rev().map(|n| (n, IDENTITY)).collect();
        while let Some((index, parent)) = stack.pop() {
            let path = format!("nodes[{index}]");
            let node = nodes.get(index).ok_or_else(|| bad(&path, "no such node"))?;
            // `index` names an existing node (checked above), so `visited` has it.
            if visited
                .get_mut(index)
                .is_some_and(|v| std::mem::replace(v, true))
            {
                return Err(bad(
                    &path,
                    "the node is reached twice: the node hierarchy must be a forest",
                ));
            }
            let world = mul(&parent, &local_transform(node, &path)?);
            if let Some(mesh) = uint(node, "mesh", &path)? {
                self.mesh(node, mesh, &world)?;
            }
            for c in list(node, "children").iter().rev() {
                let c = c
                    .as_u64()
                    .ok_or_else(|| bad(&path, "a child that is not an index"))?;
                stack.push((c as usize, world));
            }
        }
        Ok(())
    }

    fn mesh(&mut self, node: &Value, index: usize, world: &M4) -> Result<(), Diagnostic> {
        let path = format!("meshes[{index}]");
        let mesh = list(self.root, "meshes")
            .get(index)
            .ok_or_else(|| bad(&path, "no such mesh"))?;
        let name = node
            .get("name")
            .and_then(Value::as_str)
            .or_else(|| mesh.get("name").and_then(Value::as_str))
            .map_or_else(|| format!("mesh {index}"), str::to_string);
        let extras = node.get("extras");
        let kind = extras.and_then(|e| e.get("kind")).and_then(Value::as_str);
        match kind {
            Some("subdomain") => {
                // The subdomain's boundary repeats its fragments' triangles.
                let material = extras
                    .and_then(|e| e.get("material"))
                    .and_then(Value::as_str)
                    .map(str::to_string);
                self.subdomain(&name, material);
                return Ok(());
            }
            Some("fragment") => {
                let side = |key: &str| {
                    extras
                        .and_then(|e| e.get(key))
                        .and_then(Value::as_str)
                        .map(str::to_string)
                };
                if let (Some(sub), Some(other)) = (side("subdomain"), side("other")) {
                    self.subdomain(&sub, None);
                    let other = (other != "exterior").then_some(other);
                    if let Some(o) = &other {
                        self.subdomain(o, None);
                    }
                    self.b.fragments.push(FragmentInfo {
                        group: name.clone(),
                        subdomain: sub,
                        other,
                    });
                }
            }
            _ => {}
        }
        let flip = det3(world) < 0.0;
        let g = self.b.group(&name);
        for (k, prim) in list(mesh, "primitives").iter().enumerate() {
            let ppath = format!("{path}.primitives[{k}]");
            let pos = prim
                .get("attributes")
                .and_then(|a| a.get("POSITION"))
                .and_then(Value::as_u64)
                .ok_or_else(|| bad(&ppath, "no POSITION attribute"))?;
            let positions = self.floats(pos as usize, 3)?;
            let local: Vec<u32> = positions
                .chunks_exact(3)
                .filter_map(super::array)
                .map(|p| {
                    let q = apply(world, p);
                    self.dedup.node(&mut self.b.nodes, q)
                })
                .collect();
            let indices: Vec<u32> = match uint(prim, "indices", &ppath)? {
                Some(a) => {
                    let idx = self.indices(a)?;
                    if let Some(&bad_index) = idx.iter().find(|&&i| i as usize >= local.len()) {
                        return Err(Diagnostic::new(
                            Code::MeshIndexOutOfRange,
                            None,
                            format!(
                                "accessors[{a}]: index {bad_index} is out of range for {} positions",
                                local.len()
                            ),
                        ));
                    }
                    // Every index was checked against `local` just above.
                    idx.into_iter()
                        .filter_map(|i| local.get(i as usize).copied())
                        .collect()
                }
                None => local,
            };
            let mode = uint(prim, "mode", &ppath)?.unwrap_or(4);
            let Some(group) = self.b.groups.get_mut(g) else {
                continue;
            };
            match mode {
                0 => group.points.extend_from_slice(&indices),
                1 => group
                    .lines
                    .extend(indices.chunks_exact(2).filter_map(super::array::<u32, 2>)),
                2 | 3 => {
                    self.converted += 1;
                    group
                        .lines
                        .extend(indices.windows(2).filter_map(super::array::<u32, 2>));
                    if let (true, Some(&first), Some(&last)) = (
                        mode == 2 && indices.len() > 2,
                        indices.first(),
                        indices.last(),
                    ) {
                        group.lines.push([last, first]);
                    }
                }
                4 => group.triangles.extend(
                    indices
                        .chunks_exact(3)
                        .filter_map(super::array::<u32, 3>)
                        .map(|[a, b, c]| if flip { [a, c, b] } else { [a, b, c] }),
                ),
                5 | 6 => {
                    self.converted += 1;
                    let first = indices.first().copied().unwrap_or(0);
                    for (i, w) in indices.windows(3).enumerate() {
                        let Some([a, b, c]) = super::array::<u32, 3>(w) else {
                            continue;
                        };
                        let t = if mode == 5 {
                            if i % 2 == 0 { [a, b, c] } else { [b, a, c] }
                        } else {
                            [first, b, c]
                        };
                        group
                            .triangles
                            .push(if flip { [t[0], t[2], t[1]] } else { t });
                    }
                }
                _ => self.skipped_modes += 1,
            }
        }
        Ok(())
    }

    fn subdomain(&mut self, name: &str, material: Option<String>) {
        match self.b.subdomains.iter_mut().find(|(n, _)| n == name) {
            Some(entry) => {
                if material.is_some() {
                    entry.1 = material;
                }
            }
            None => self.b.subdomains.push((name.to_string(), material)),
        }
    }

    /// The bytes an accessor reads: (data, element stride, count, component type).
    fn accessor(&self, index: usize) -> Result<(&[u8], usize, usize, u64, &str), Diagnostic> {
        let path = format!("accessors[{index}]");
        let acc = list(self.root, "accessors")
            .get(index)
            .ok_or_else(|| bad(&path, "no such accessor"))?;
        if acc.get("sparse").is_some() {
            return Err(bad(&path, "sparse accessors are not read"));
        }
        let count = uint(acc, "count", &path)?.unwrap_or(0);
        let ctype = acc
            .get("componentType")
            .and_then(Value::as_u64)
            .unwrap_or(0);
        let ty = acc.get("type").and_then(Value::as_str).unwrap_or("");
        let components = match ty {
            "SCALAR" => 1,
            "VEC2" => 2,
            "VEC3" => 3,
            "VEC4" => 4,
            _ => return Err(bad(&path, format!("type `{ty}` is not read"))),
        };
        let size = match ctype {
            5120 | 5121 => 1,
            5122 | 5123 => 2,
            5125 | 5126 => 4,
            _ => {
                return Err(bad(
                    &path,
                    format!("componentType {ctype} is not a glTF component type"),
                ));
            }
        };
        let element = components * size;
        let Some(view_index) = uint(acc, "bufferView", &path)? else {
            return Err(bad(
                &path,
                "accessors without a bufferView (all zeros) are not read",
            ));
        };
        let vpath = format!("bufferViews[{view_index}]");
        let view = list(self.root, "bufferViews")
            .get(view_index)
            .ok_or_else(|| bad(&vpath, "no such buffer view"))?;
        let buffer = uint(view, "buffer", &vpath)?.unwrap_or(0);
        let data = self
            .buffers
            .get(buffer)
            .ok_or_else(|| bad(&vpath, format!("buffer {buffer} does not exist")))?;
        let view_offset = uint(view, "byteOffset", &vpath)?.unwrap_or(0);
        let view_length = uint(view, "byteLength", &vpath)?.unwrap_or(0);
        let stride = uint(view, "byteStride", &vpath)?
            .unwrap_or(element)
            .max(element);
        let offset = uint(acc, "byteOffset", &path)?.unwrap_or(0);
        let need = if count == 0 {
            0
        } else {
            offset
                .saturating_add(stride.saturating_mul(count - 1))
                .saturating_add(element)
        };
        let view_end = view_offset.saturating_add(view_length);
        if need > view_length || view_end > data.len() {
            return Err(Diagnostic::new(
                Code::MeshCountMismatch,
                None,
                format!(
                    "{path}: {count} elements need {need} bytes of buffer view {view_index}, which has {view_length} (its buffer {})",
                    data.len()
                ),
            ));
        }
        let Some(elements) = data.get(view_offset + offset..view_end) else {
            return Err(bad(&path, "the accessor starts past its buffer view's end"));
        };
        // A count the data cannot hold was refused above (E523). An accessor
        // shared by many primitives is decoded once per use: the sum, not the
        // file, bounds the memory.
        let decoded = self.elements.get().saturating_add(count as u64);
        if decoded > self.limits.max_elements {
            return Err(Diagnostic::new(
                Code::GltfTooManyElements,
                None,
                format!(
                    "{path}: decoding its {count} elements would bring the accessor elements read to {decoded}, over the limit of {}",
                    self.limits.max_elements
                ),
            )
            .with_help("raise the limit with --max-mesh-elements N"));
        }
        self.elements.set(decoded);
        Ok((elements, stride, count, ctype, ty))
    }

    fn floats(&self, index: usize, components: usize) -> Result<Vec<f64>, Diagnostic> {
        let (data, stride, count, ctype, _) = self.accessor(index)?;
        if ctype != 5126 {
            return Err(bad(
                &format!("accessors[{index}]"),
                "positions must be 32-bit floats",
            ));
        }
        let mut out = Vec::with_capacity(count * components);
        for i in 0..count {
            for c in 0..components {
                let at = i * stride + 4 * c;
                // `accessor` checked that every element lies inside `data`.
                let v = f32::from_le_bytes(super::bytes_at(data, at).unwrap_or([0; 4]));
                if !v.is_finite() {
                    return Err(Diagnostic::new(
                        Code::MeshNonFinite,
                        None,
                        format!(
                            "accessors[{index}]: element {i} has a coordinate `{v}`, not a finite number"
                        ),
                    ));
                }
                out.push(f64::from(v));
            }
        }
        Ok(out)
    }

    fn indices(&self, index: usize) -> Result<Vec<u32>, Diagnostic> {
        let (data, stride, count, ctype, ty) = self.accessor(index)?;
        if ty != "SCALAR" {
            return Err(bad(
                &format!("accessors[{index}]"),
                "indices must be scalars",
            ));
        }
        Ok((0..count)
            .map(|i| {
                let at = i * stride;
                // `accessor` checked that every element lies inside `data`.
                match ctype {
                    5121 | 5120 => u32::from(data.get(at).copied().unwrap_or(0)),
                    5123 | 5122 => u32::from(u16::from_le_bytes(
                        super::bytes_at(data, at).unwrap_or([0; 2]),
                    )),
                    _ => u32::from_le_bytes(super::bytes_at(data, at).unwrap_or([0; 4])),
                }
            })
            .collect())
    }

    fn finish(mut self) -> Builder {
        if self.converted > 0 {
            self.b.warn(
                Code::ElementsConverted,
                format!(
                    "{} strip, loop or fan primitives converted to separate lines and triangles",
                    self.converted
                ),
            );
        }
        if self.skipped_modes > 0 {
            self.b.warn(
                Code::InputNotCarried,
                format!(
                    "{} primitives of an unknown mode not kept",
                    self.skipped_modes
                ),
            );
        }
        self.b
    }
}

fn percent_decode(s: &str) -> String {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while let Some(&c) = b.get(i) {
        if c == b'%' {
            let hex = s
                .get(i + 1..i + 3)
                .and_then(|h| u8::from_str_radix(h, 16).ok());
            if let Some(v) = hex {
                out.push(v);
                i += 3;
                continue;
            }
        }
        out.push(c);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

fn numbers<const N: usize>(
    node: &Value,
    key: &str,
    path: &str,
) -> Result<Option<[f64; N]>, Diagnostic> {
    let Some(v) = node.get(key) else {
        return Ok(None);
    };
    let arr = v
        .as_array()
        .filter(|a| a.len() == N)
        .ok_or_else(|| bad(&format!("{path}.{key}"), format!("expected {N} numbers")))?;
    let mut out = [0.0; N];
    for (o, x) in out.iter_mut().zip(arr) {
        *o = x.as_f64().filter(|v| v.is_finite()).ok_or_else(|| {
            bad(
                &format!("{path}.{key}"),
                format!("`{x}` is not a finite number"),
            )
        })?;
    }
    Ok(Some(out))
}

/// A node's matrix (column-major in the file) or T·R·S.
#[allow(clippy::indexing_slicing)] // fixed-size arrays, loop bounds are their lengths
fn local_transform(node: &Value, path: &str) -> Result<M4, Diagnostic> {
    if let Some(m) = numbers::<16>(node, "matrix", path)? {
        let mut out = [[0.0; 4]; 4];
        for (c, col) in m.chunks_exact(4).enumerate() {
            for (r, v) in col.iter().enumerate() {
                out[r][c] = *v;
            }
        }
        return Ok(out);
    }
    let t = numbers::<3>(node, "translation", path)?.unwrap_or([0.0; 3]);
    let q = numbers::<4>(node, "rotation", path)?.unwrap_or([0.0, 0.0, 0.0, 1.0]);
    let s = numbers::<3>(node, "scale", path)?.unwrap_or([1.0; 3]);
    let [x, y, z, w] = q;
    let r = [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - z * w),
            2.0 * (x * z + y * w),
        ],
        [
            2.0 * (x * y + z * w),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - x * w),
        ],
        [
            2.0 * (x * z - y * w),
            2.0 * (y * z + x * w),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ];
    let mut out = IDENTITY;
    for i in 0..3 {
        for j in 0..3 {
            out[i][j] = r[i][j] * s[j];
        }
        out[i][3] = t[i];
    }
    Ok(out)
}

#[allow(clippy::indexing_slicing)] // fixed-size arrays, loop bounds are their lengths
fn mul(a: &M4, b: &M4) -> M4 {
    let mut out = [[0.0; 4]; 4];
    for i in 0..4 {
        for j in 0..4 {
            out[i][j] = (0..4).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    out
}

fn apply(m: &M4, p: [f64; 3]) -> [f64; 3] {
    let [r0, r1, r2, _] = m;
    [r0, r1, r2].map(|r| r[0] * p[0] + r[1] * p[1] + r[2] * p[2] + r[3])
}

fn det3(m: &M4) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
}
