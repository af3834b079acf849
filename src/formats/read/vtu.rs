//! VTK XML unstructured grids (`.vtu`): data arrays in ASCII, or inline
//! base64 binary with UInt32 or UInt64 headers, zlib-compressed or not.
//! Groups come from cell data: geomc's own `fragment_id`, else `face_id`,
//! `edge_id`, `polyline_id`, `point_set_id`, `volume_id` (named by its
//! FieldData), meshio's `gmsh:physical`, or the first integer cell array;
//! cells without one are group `vtu`. Vertices, lines, poly-lines,
//! triangles, strips, polygons and quads are kept (the last three split into
//! triangles), and so are tetrahedra, hexahedra, wedges and pyramids
//! (quadratic ones by their corners; wedges turned into Gmsh's corner
//! order); polyhedra are not kept, with a warning and counts.

use super::build::Builder;
use super::{base64, error_at};
use crate::diag::{Code, Diagnostic};
use crate::mesh::CellKind;
use crate::span::{SourceFile, Span};
use crate::syntax::{self, Element, Limits};
use std::collections::BTreeMap;
use std::io::Read;

/// Cell data arrays that name groups, best first.
const GROUP_ARRAYS: [&str; 6] = [
    "gmsh:physical",
    "group",
    "region",
    "CellEntityIds",
    "MaterialIds",
    "material",
];

/// geomc's own arrays, in the order a cell's group is looked for: (array,
/// label of unnamed groups, index of the array in the writer's FieldData).
const GEOMC_ARRAYS: [(&str, &str, i64); 6] = [
    ("fragment_id", "fragment", 0),
    ("face_id", "face", 3),
    ("edge_id", "edge", 4),
    ("polyline_id", "poly_line", 5),
    ("point_set_id", "point set", 6),
    ("volume_id", "volume", 7),
];

/// The volume cell kind of a VTK cell type, with its corner count first in
/// the cell's points (quadratic cells list their corners first).
fn volume_kind(t: i64) -> Option<CellKind> {
    Some(match t {
        10 | 24 => CellKind::Tetrahedron,
        12 | 25 | 29 => CellKind::Hexahedron,
        13 | 26 => CellKind::Wedge,
        14 | 27 => CellKind::Pyramid,
        _ => return None,
    })
}

pub fn read(bytes: &[u8]) -> Result<(Builder, Option<bool>), Vec<Diagnostic>> {
    let text = std::str::from_utf8(bytes).map_err(|e| {
        vec![
            error_at(
                Code::MeshSyntax,
                e.valid_up_to(),
                e.valid_up_to() + 1,
                "the file is not UTF-8 text: raw appended VTU data is not read",
            )
            .with_help("save the .vtu with inline (base64) or ASCII data arrays"),
        ]
    })?;
    let source = SourceFile::new("", text);
    let root = syntax::parse(&source, &Limits::default()).map_err(|d| vec![d])?;
    let r = Reader { source: &source };
    r.grid(&root).map_err(|d| vec![d])
}

struct Reader<'a> {
    source: &'a SourceFile,
}

/// A decoded data array.
enum Values {
    Real(Vec<f64>),
    Int(Vec<i64>),
}

fn err(e: &Element, code: Code, message: impl Into<String>) -> Diagnostic {
    Diagnostic::new(code, e.name_span, message)
}

fn child<'e>(e: &'e Element<'e>, name: &'e str) -> Result<&'e Element<'e>, Diagnostic> {
    e.children_named(name)
        .next()
        .ok_or_else(|| err(e, Code::MeshSyntax, format!("<{}> has no <{name}>", e.name)))
}

fn attr<'e>(e: &'e Element, name: &str) -> Option<&'e str> {
    e.attribute(name).map(|a| a.value.as_ref())
}

impl Reader<'_> {
    fn grid(&self, root: &Element) -> Result<(Builder, Option<bool>), Diagnostic> {
        if root.name != "VTKFile" || attr(root, "type") != Some("UnstructuredGrid") {
            return Err(err(
                root,
                Code::MeshSyntax,
                "not a VTK unstructured grid (<VTKFile type=\"UnstructuredGrid\">)",
            ));
        }
        if attr(root, "byte_order").is_some_and(|o| o != "LittleEndian") {
            return Err(err(
                root,
                Code::MeshUnsupportedVersion,
                "big-endian VTU data is not read",
            ));
        }
        let header64 = attr(root, "header_type") == Some("UInt64");
        let compressed = match attr(root, "compressor") {
            None | Some("") => false,
            Some("vtkZLibDataCompressor") => true,
            Some(other) => {
                return Err(err(
                    root,
                    Code::MeshUnsupportedVersion,
                    format!("VTU compressor `{other}` is not read (zlib is)"),
                ));
            }
        };
        let grid = child(root, "UnstructuredGrid")?;
        let field_names = self.field_names(grid);
        let piece = child(grid, "Piece")?;
        let count = |name: &str| -> Result<usize, Diagnostic> {
            attr(piece, name)
                .and_then(|v| v.trim().parse().ok())
                .ok_or_else(|| err(piece, Code::MeshSyntax, format!("<Piece> needs a {name}")))
        };
        let n_points = count("NumberOfPoints")?;
        let n_cells = count("NumberOfCells")?;
        let ctx = Ctx {
            header64,
            compressed,
        };
        let points = child(piece, "Points")?;
        let pa = child(points, "DataArray")?;
        let coords = self.array(pa, &ctx)?;
        let Values::Real(coords) = to_real(coords) else {
            unreachable!()
        };
        if coords.len() != 3 * n_points {
            return Err(err(
                pa,
                Code::MeshCountMismatch,
                format!(
                    "the points array holds {} values, {} points need {}",
                    coords.len(),
                    n_points,
                    3 * n_points
                ),
            ));
        }
        if let Some(i) = coords.iter().position(|c| !c.is_finite()) {
            return Err(err(
                pa,
                Code::MeshNonFinite,
                format!("point {} has a coordinate that is not finite", i / 3),
            ));
        }
        let cells = child(piece, "Cells")?;
        let mut connectivity = None;
        let mut offsets = None;
        let mut types = None;
        for a in cells.children_named("DataArray") {
            let slot = match attr(a, "Name") {
                Some("connectivity") => &mut connectivity,
                Some("offsets") => &mut offsets,
                Some("types") => &mut types,
                _ => continue,
            };
            *slot = Some((a, ints(self.array(a, &ctx)?)));
        }
        let missing = |what: &str| {
            err(
                cells,
                Code::MeshSyntax,
                format!("<Cells> has no `{what}` array"),
            )
        };
        let (ca, connectivity) = connectivity.ok_or_else(|| missing("connectivity"))?;
        let (oa, offsets) = offsets.ok_or_else(|| missing("offsets"))?;
        let (ta, types) = types.ok_or_else(|| missing("types"))?;
        if offsets.len() != n_cells || types.len() != n_cells {
            return Err(err(
                oa,
                Code::MeshCountMismatch,
                format!(
                    "{} offsets and {} types for {n_cells} cells",
                    offsets.len(),
                    types.len()
                ),
            ));
        }
        // Cell data that names groups.
        let mut cell_data: BTreeMap<String, Vec<i64>> = BTreeMap::new();
        if let Some(cd) = piece.children_named("CellData").next() {
            for a in cd.children_named("DataArray") {
                let name = attr(a, "Name").unwrap_or("").to_string();
                let ty = attr(a, "type").unwrap_or("");
                if !ty.contains("Int") || attr(a, "NumberOfComponents").is_some_and(|c| c != "1") {
                    continue;
                }
                let v = ints(self.array(a, &ctx)?);
                if v.len() != n_cells {
                    return Err(err(
                        a,
                        Code::MeshCountMismatch,
                        format!(
                            "cell data `{name}` has {} values for {n_cells} cells",
                            v.len()
                        ),
                    ));
                }
                cell_data.insert(name, v);
            }
        }
        let geomc = cell_data.contains_key("face_id");
        let generic = GROUP_ARRAYS
            .iter()
            .find(|n| cell_data.contains_key(**n))
            .map(|n| n.to_string())
            .or_else(|| cell_data.keys().next().cloned());

        let mut b = Builder::new();
        b.nodes = coords.chunks_exact(3).filter_map(super::array).collect();
        let mut groups: BTreeMap<(usize, i64), usize> = BTreeMap::new();
        let mut dropped: BTreeMap<&str, usize> = BTreeMap::new();
        let mut reduced: BTreeMap<&str, usize> = BTreeMap::new();
        let mut split = 0usize;
        let mut start = 0usize;
        // `offsets`, `types` and every cell data array have n_cells entries (checked above).
        for (i, (&end, &t)) in offsets.iter().zip(&types).enumerate() {
            if end < start as i64 || end as usize > connectivity.len() {
                return Err(err(
                    oa,
                    Code::MeshCountMismatch,
                    format!(
                        "cell {i}'s offset {end} is outside the {} connectivity entries",
                        connectivity.len()
                    ),
                ));
            }
            let end = end as usize;
            let ids = connectivity.get(start..end).unwrap_or_default();
            start = end;
            let mut nodes = Vec::with_capacity(ids.len());
            for &v in ids {
                if v < 0 || v as usize >= n_points {
                    return Err(err(
                        ca,
                        Code::MeshIndexOutOfRange,
                        format!("cell {i} refers to point {v}, outside the {n_points} points"),
                    ));
                }
                nodes.push(v as u32);
            }
            // The group key: (which array, value).
            let key = if geomc {
                GEOMC_ARRAYS
                    .iter()
                    .enumerate()
                    .find_map(|(k, (name, _, _))| {
                        cell_data
                            .get(*name)
                            .and_then(|v| v.get(i).copied())
                            .filter(|&v| v >= 0)
                            .map(|v| (k, v))
                    })
                    .unwrap_or((usize::MAX, 0))
            } else if volume_kind(t).is_some() && generic.as_deref() == Some("gmsh:physical") {
                // Physical volumes are numbered apart from physical surfaces.
                (
                    VOLUME_KEY,
                    cell_data
                        .get("gmsh:physical")
                        .and_then(|v| v.get(i).copied())
                        .unwrap_or(0),
                )
            } else {
                match &generic {
                    Some(name) => (
                        0,
                        cell_data
                            .get(name)
                            .and_then(|v| v.get(i).copied())
                            .unwrap_or(0),
                    ),
                    None => (usize::MAX, 0),
                }
            };
            let g = match groups.get(&key) {
                Some(&g) => g,
                None => {
                    let name = group_name(key, geomc, generic.as_deref(), &field_names);
                    let g = b.group(&name);
                    groups.insert(key, g);
                    g
                }
            };
            let need = match t {
                _ if volume_kind(t).is_some() => volume_kind(t).map(CellKind::corners),
                1 => Some(1),
                3 | 21 => Some(2),
                5 | 22 => Some(3),
                9 | 23 | 28 => Some(4),
                _ => None,
            };
            if let Some(k) = need
                && nodes.len() < k
            {
                return Err(err(
                    ca,
                    Code::MeshCountMismatch,
                    format!(
                        "cell {i} of type {t} has {} points, it needs {k}",
                        nodes.len()
                    ),
                ));
            }
            let Some(group) = b.groups.get_mut(g) else {
                continue;
            };
            // Quads and quadratic cells: the first `need` nodes are the corners (checked above).
            let corners = match need {
                Some(k) if matches!(t, 9 | 21 | 22 | 23 | 28) => nodes.get(..k).unwrap_or(&nodes),
                _ => nodes.as_slice(),
            };
            match t {
                1 | 2 => group.points.extend_from_slice(&nodes),
                3 | 4 | 21 => {
                    group
                        .lines
                        .extend(corners.windows(2).filter_map(super::array::<u32, 2>));
                }
                5 | 22 => {
                    if let &[a, b, c, ..] = corners {
                        group.triangles.push([a, b, c]);
                    }
                }
                6 => {
                    split += 1;
                    for (k, w) in nodes.windows(3).enumerate() {
                        if let &[a, b, c] = w {
                            group
                                .triangles
                                .push(if k % 2 == 0 { [a, b, c] } else { [b, a, c] });
                        }
                    }
                }
                7 | 9 | 23 | 28 => {
                    split += 1;
                    // A fan from the first corner.
                    if let Some((&first, rest)) = corners.split_first() {
                        group.triangles.extend(
                            rest.windows(2)
                                .filter_map(super::array::<u32, 2>)
                                .map(|[a, c]| [first, a, c]),
                        );
                    }
                }
                _ if volume_kind(t).is_some() => {
                    if let Some(kind) = volume_kind(t) {
                        let order = kind.vtk_order();
                        let mut corners = [0u32; 8];
                        for (slot, &from) in corners.iter_mut().zip(order) {
                            *slot = nodes.get(from).copied().unwrap_or(0);
                        }
                        group.add_cell(kind, corners.get(..order.len()).unwrap_or_default());
                        if nodes.len() > kind.corners() {
                            *reduced.entry(kind.plural()).or_default() += 1;
                        }
                    }
                }
                42 => *dropped.entry("polyhedra").or_default() += 1,
                _ => {
                    return Err(err(
                        ta,
                        Code::MeshUnsupportedElement,
                        format!("cell {i} has VTK cell type {t}, which geomc does not read"),
                    ));
                }
            }
        }
        if !dropped.is_empty() {
            let list: Vec<String> = dropped.iter().map(|(k, n)| format!("{n} {k}")).collect();
            b.warn(
                Code::InputNotCarried,
                format!(
                    "polyhedral cells are not kept (MSH and geomc hold tetrahedra, hexahedra, wedges and pyramids): {}",
                    list.join(", ")
                ),
            );
        }
        if !reduced.is_empty() {
            let list: Vec<String> = reduced.iter().map(|(k, n)| format!("{n} {k}")).collect();
            b.warn(
                Code::ElementsConverted,
                format!(
                    "quadratic volume cells reduced to their corner nodes: {}",
                    list.join(", ")
                ),
            );
        }
        if split > 0 {
            b.warn(
                Code::ElementsConverted,
                format!("{split} strips, polygons or quads split into triangles"),
            );
        }
        let binary = Some(piece_binary(piece));
        Ok((b, binary))
    }

    /// FieldData arrays `Name="group name"` holding `[id, kind]`: kind is the
    /// index of the cell-data array the id belongs to (geomc's writer), or
    /// meshio's `[tag, dim]` for Gmsh physical names.
    fn field_names(&self, grid: &Element) -> BTreeMap<i64, BTreeMap<i64, String>> {
        let mut out: BTreeMap<i64, BTreeMap<i64, String>> = BTreeMap::new();
        let Some(fd) = grid.children_named("FieldData").next() else {
            return out;
        };
        for a in fd.children_named("DataArray") {
            let Some(name) = attr(a, "Name") else {
                continue;
            };
            let values: Vec<i64> = a
                .text
                .iter()
                .flat_map(|(t, _)| t.split_whitespace().map(str::to_string).collect::<Vec<_>>())
                .filter_map(|t| t.parse::<f64>().ok().map(|v| v as i64))
                .collect();
            if let [id, kind] = values[..] {
                out.entry(kind).or_default().insert(id, name.to_string());
            }
        }
        out
    }

    fn array(&self, a: &Element, ctx: &Ctx) -> Result<Values, Diagnostic> {
        let ty = attr(a, "type").unwrap_or("");
        let format = attr(a, "format").unwrap_or("ascii");
        let real = ty.starts_with("Float");
        let Some((text, span)) = a.text.first() else {
            return Ok(if real {
                Values::Real(Vec::new())
            } else {
                Values::Int(Vec::new())
            });
        };
        match format {
            "ascii" => self.ascii(text, *span, real),
            "binary" => {
                let bytes = decode_binary(text.as_bytes(), ctx)
                    .ok_or_else(|| err(a, Code::MeshSyntax, "the binary data array is not valid base64 or its block headers do not match its data"))?;
                from_bytes(&bytes, ty).ok_or_else(|| {
                    err(
                        a,
                        Code::MeshUnsupportedVersion,
                        format!("data array type `{ty}` is not read"),
                    )
                })
            }
            _ => Err(err(
                a,
                Code::MeshUnsupportedVersion,
                format!("data array format `{format}` is not read (ascii and inline binary are)"),
            )
            .with_help("save the .vtu with inline data arrays (meshio: binary=True, the default)")),
        }
    }

    fn ascii(&self, text: &str, span: Span, real: bool) -> Result<Values, Diagnostic> {
        // Positions: the text is trimmed; find it in the source for offsets.
        let raw = self.source.text.get(span.range()).unwrap_or("");
        let base = span.start as usize + raw.find(|c: char| !c.is_whitespace()).unwrap_or(0);
        let mut offset = 0usize;
        let mut reals = Vec::new();
        let mut ints_out = Vec::new();
        for token in text.split_ascii_whitespace() {
            let at = base + text[offset..].find(token).map_or(0, |i| i + offset);
            offset = at - base + token.len();
            if real {
                let v: f64 = token.parse().map_err(|_| {
                    error_at(
                        Code::MeshSyntax,
                        at,
                        at + token.len(),
                        format!("expected a number, found `{token}`"),
                    )
                })?;
                if !v.is_finite() {
                    return Err(error_at(
                        Code::MeshNonFinite,
                        at,
                        at + token.len(),
                        format!("`{token}` is not a finite number"),
                    ));
                }
                reals.push(v);
            } else {
                let v: i64 = token.parse().map_err(|_| {
                    error_at(
                        Code::MeshSyntax,
                        at,
                        at + token.len(),
                        format!("expected an integer, found `{token}`"),
                    )
                })?;
                ints_out.push(v);
            }
        }
        Ok(if real {
            Values::Real(reals)
        } else {
            Values::Int(ints_out)
        })
    }
}

struct Ctx {
    header64: bool,
    compressed: bool,
}

fn piece_binary(piece: &Element) -> bool {
    piece
        .children
        .iter()
        .flat_map(|c| c.children_named("DataArray"))
        .any(|a| attr(a, "format") == Some("binary"))
}

fn to_real(v: Values) -> Values {
    match v {
        Values::Int(i) => Values::Real(i.into_iter().map(|x| x as f64).collect()),
        r => r,
    }
}

fn ints(v: Values) -> Vec<i64> {
    match v {
        Values::Int(i) => i,
        Values::Real(r) => r.into_iter().map(|x| x as i64).collect(),
    }
}

/// The group key of volume cells grouped by `gmsh:physical`.
const VOLUME_KEY: usize = usize::MAX - 1;

fn group_name(
    key: (usize, i64),
    geomc: bool,
    generic: Option<&str>,
    names: &BTreeMap<i64, BTreeMap<i64, String>>,
) -> String {
    if key.0 == usize::MAX {
        return "vtu".to_string();
    }
    if geomc && let Some(&(_, label, kind)) = GEOMC_ARRAYS.get(key.0) {
        if let Some(name) = names.get(&kind).and_then(|m| m.get(&key.1)) {
            return name.clone();
        }
        return format!("{label} {}", key.1);
    }
    let array = generic.unwrap_or("group");
    if key.0 == VOLUME_KEY {
        if let Some(name) = names.get(&3).and_then(|m| m.get(&key.1)) {
            return name.clone();
        }
        return format!("{array} 3:{}", key.1);
    }
    if array == "gmsh:physical" {
        // meshio keeps Gmsh physical names as [tag, dim].
        for dim in [2, 1, 0, 3] {
            if let Some(name) = names.get(&dim).and_then(|m| m.get(&key.1)) {
                return name.clone();
            }
        }
    }
    format!("{array} {}", key.1)
}

/// Inline binary: base64 of (header, data), or with a compressor base64 of
/// the block header followed by base64 of the compressed blocks.
fn decode_binary(text: &[u8], ctx: &Ctx) -> Option<Vec<u8>> {
    let word = if ctx.header64 { 8 } else { 4 };
    let read_word = |b: &[u8], i: usize| -> Option<usize> {
        let s = b.get(i * word..(i + 1) * word)?;
        Some(if word == 8 {
            u64::from_le_bytes(s.try_into().ok()?) as usize
        } else {
            u32::from_le_bytes(s.try_into().ok()?) as usize
        })
    };
    if !ctx.compressed {
        let all = base64::decode(text)?;
        let n = read_word(&all, 0)?;
        return all.get(word..word + n).map(<[u8]>::to_vec);
    }
    // The header is its own base64 run: decode just enough of it.
    let clean: Vec<u8> = text
        .iter()
        .copied()
        .filter(|c| !c.is_ascii_whitespace())
        .collect();
    let first = base64::decode(clean.get(..clean.len().min(64))?)?;
    let blocks = read_word(&first, 0)?;
    let header_bytes = (3 + blocks) * word;
    let header_chars = header_bytes.div_ceil(3) * 4;
    let header = base64::decode(clean.get(..header_chars)?)?;
    let sizes: Vec<usize> = (0..blocks)
        .map(|i| read_word(&header, 3 + i))
        .collect::<Option<_>>()?;
    let data = base64::decode(clean.get(header_chars..)?)?;
    let mut out = Vec::new();
    let mut at = 0usize;
    for size in sizes {
        let block = data.get(at..at + size)?;
        at += size;
        let mut z = flate2::read::ZlibDecoder::new(block);
        z.read_to_end(&mut out).ok()?;
    }
    Some(out)
}

fn from_bytes(b: &[u8], ty: &str) -> Option<Values> {
    macro_rules! conv {
        ($t:ty, $n:literal, $wrap:ident, $to:ty) => {
            Values::$wrap(
                b.chunks_exact($n)
                    .map(|c| <$t>::from_le_bytes(c.try_into().unwrap_or([0; $n])) as $to)
                    .collect(),
            )
        };
    }
    Some(match ty {
        "Float32" => conv!(f32, 4, Real, f64),
        "Float64" => conv!(f64, 8, Real, f64),
        "Int8" => conv!(i8, 1, Int, i64),
        "UInt8" => conv!(u8, 1, Int, i64),
        "Int16" => conv!(i16, 2, Int, i64),
        "UInt16" => conv!(u16, 2, Int, i64),
        "Int32" => conv!(i32, 4, Int, i64),
        "UInt32" => conv!(u32, 4, Int, i64),
        "Int64" => conv!(i64, 8, Int, i64),
        "UInt64" => conv!(u64, 8, Int, i64),
        _ => return None,
    })
}
