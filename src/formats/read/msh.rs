//! Gmsh MSH 2.2 and 4.1, ASCII or binary (little-endian, 8-byte sizes).
//! Elements are grouped by physical name: in 4.1 through their entity's
//! physical tags (`$Entities`), in 2.2 by their first tag; elements in no
//! physical group are grouped by entity (`surface 3`). Triangles (also the
//! corners of higher-order ones), lines, points and volume cells
//! (tetrahedra, hexahedra, prisms, pyramids; higher-order ones by their
//! corners) are kept; quadrangles are split into two triangles, with a
//! warning and counts. Sections geomc does not use
//! (`$NodeData`, `$Periodic`, …) are skipped.

use super::build::{Builder, FastMap};
use super::summed::extend_summed;
use super::text::{Scanner, Token, syntax};
use super::{error_at, error_at_byte};
use crate::diag::{Code, Diagnostic};
use crate::formats::mesh_facts::{
    FaceFacts, FacePiece, PIECE_TRIANGLES, finite_bounds, merge_bounds,
};
use crate::mesh::CellKind;
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::sync::atomic::{AtomicBool, Ordering};

pub fn read(bytes: &[u8]) -> Result<(Builder, Option<bool>), Vec<Diagnostic>> {
    let mut r = Reader {
        s: Scanner::new(bytes),
        binary: false,
        version: Version::V41,
        physical_names: BTreeMap::new(),
        entity_physicals: BTreeMap::new(),
        nodes: NodeIndex::default(),
        b: Builder::new(),
        kinds: BTreeMap::new(),
        multi_physical: 0,
        group_of: FastMap::default(),
        section: None,
    };
    r.read().map_err(|d| vec![d])?;
    let binary = r.binary;
    Ok((r.finish(), Some(binary)))
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Version {
    V22,
    V41,
}

/// Node tags to node indices. Tags that run on from the first one, one per
/// node in order (Gmsh and geomc number nodes 1, 2, 3, …), need no table:
/// a node's index is its tag's distance from the first. The first tag that
/// breaks the run moves the run into the table: a vector when tags are
/// dense, a map otherwise.
#[derive(Default)]
struct NodeIndex {
    /// While every node so far is in it: the first tag and the run's length.
    run: Option<(u64, u32)>,
    /// The run has been moved into the table (or never started).
    tabled: bool,
    dense: Vec<u32>,
    sparse: FastMap<u64, u32>,
}

const NONE: u32 = u32::MAX;

impl NodeIndex {
    fn insert(&mut self, tag: u64, index: u32, dense_limit: u64) -> bool {
        if !self.tabled {
            match &mut self.run {
                None if index == 0 => {
                    self.run = Some((tag, 1));
                    return true;
                }
                Some((first, len))
                    if index == *len && first.checked_add(u64::from(*len)) == Some(tag) =>
                {
                    *len += 1;
                    return true;
                }
                _ => self.move_run_to_table(dense_limit),
            }
        }
        self.table_insert(tag, index, dense_limit)
    }

    /// Whether a block's tags (8 bytes each) continue the run for nodes
    /// numbered from `next` on: each one more than the one before, the
    /// first one after the run's last (or any, for the first node).
    fn run_continues(&self, tags: &[u8], next: usize) -> bool {
        let Some(first) = super::bytes_at::<8>(tags, 0).map(u64::from_le_bytes) else {
            return false;
        };
        let n = tags.len() / 8;
        let fits = u32::try_from(next + n).is_ok() && first.checked_add(n as u64).is_some();
        let follows = match self.run {
            _ if self.tabled => false,
            None => next == 0,
            Some((start, len)) => {
                len as usize == next && start.checked_add(u64::from(len)) == Some(first)
            }
        };
        fits && follows
            && tags.par_chunks(8 << 12).enumerate().all(|(c, piece)| {
                let base = first + (c as u64) * 4096;
                // No early exit inside a piece, so the compiler vectorises it.
                piece.chunks_exact(8).enumerate().fold(true, |ok, (i, t)| {
                    ok & (u64::from_le_bytes(super::array(t).unwrap_or([0; 8])) == base + i as u64)
                })
            })
    }

    /// Adds a block's `n` nodes to the run (after [`NodeIndex::run_continues`]).
    fn extend_run(&mut self, tags: &[u8], n: usize) {
        let first = super::bytes_at::<8>(tags, 0).map_or(0, u64::from_le_bytes);
        let len = n as u32;
        self.run = match self.run {
            None => Some((first, len)),
            Some((start, old)) => Some((start, old + len)),
        };
    }

    fn move_run_to_table(&mut self, dense_limit: u64) {
        self.tabled = true;
        if let Some((first, len)) = self.run.take() {
            for i in 0..len {
                self.table_insert(first + u64::from(i), i, dense_limit);
            }
        }
    }

    fn table_insert(&mut self, tag: u64, index: u32, dense_limit: u64) -> bool {
        if tag < dense_limit {
            let t = tag as usize;
            if t >= self.dense.len() {
                self.dense.resize(t + 1, NONE);
            }
            self.dense
                .get_mut(t)
                .is_some_and(|slot| std::mem::replace(slot, index) == NONE)
        } else {
            self.sparse.insert(tag, index).is_none()
        }
    }

    fn get(&self, tag: u64) -> Option<u32> {
        if let Some((first, len)) = self.run {
            return tag
                .checked_sub(first)
                .filter(|&i| i < u64::from(len))
                .map(|i| i as u32);
        }
        match self.dense.get(tag as usize) {
            Some(&i) if i != NONE => Some(i),
            _ => self.sparse.get(&tag).copied(),
        }
    }
}

/// Nodes per parallel piece of a binary node block (96 kB of coordinates).
const NODE_PIECE: usize = 4096;

/// [`Reader::binary_triangles`] when the node tags run on from `first`
/// (`len` nodes): a node's index is its tag less `first`, so the corners
/// are found by a subtraction and a bound check on every tag at once
/// (no lookup call per tag: that was a fifth of reading the 2-million-triangle
/// bench file). `None`, with nothing added, when a tag is not a node's;
/// else the pieces summed up (`FaceFacts::piece`).
fn run_triangles(
    block: &[u8],
    first: u64,
    len: u64,
    triangles: &mut Vec<[u32; 3]>,
) -> Option<Vec<FacePiece>> {
    let unknown = AtomicBool::new(false);
    let index = |r: &[u8], at: usize| {
        let tag = super::bytes_at::<8>(r, at).map_or(0, u64::from_le_bytes);
        // Below `first` wraps past every index (`first + len` fits in u64).
        tag.wrapping_sub(first)
    };
    triangles_summed(triangles, block, &unknown, |r| {
        let [a, b, c] = [index(r, 8), index(r, 16), index(r, 24)];
        if (a >= len) | (b >= len) | (c >= len) {
            unknown.store(true, Ordering::Relaxed);
        }
        [a as u32, b as u32, c as u32]
    })
}

/// Appends the triangles `decode` makes of the 32-byte records of `block`,
/// each piece of them summed up for the face's facts while in cache.
/// `None`, with nothing added, when `unknown` was set (a tag that is not a
/// node's).
fn triangles_summed(
    triangles: &mut Vec<[u32; 3]>,
    block: &[u8],
    unknown: &AtomicBool,
    decode: impl Fn(&[u8]) -> [u32; 3] + Sync,
) -> Option<Vec<FacePiece>> {
    let base = triangles.len();
    let pieces = extend_summed(
        triangles,
        block,
        32,
        PIECE_TRIANGLES,
        decode,
        FaceFacts::piece,
    );
    if unknown.load(Ordering::Relaxed) {
        triangles.truncate(base);
        return None;
    }
    Some(pieces)
}

/// What an element type is, by Gmsh's numbering.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Point,
    Line,
    Triangle,
    Quad,
    Volume(CellKind),
}

/// (number of nodes, kind, name) of a Gmsh element type.
fn element_type(t: i64) -> Option<(usize, Kind, &'static str)> {
    Some(match t {
        1 => (2, Kind::Line, "line"),
        2 => (3, Kind::Triangle, "triangle"),
        3 => (4, Kind::Quad, "quadrangle"),
        4 => (4, Kind::Volume(CellKind::Tetrahedron), "tetrahedron"),
        5 => (8, Kind::Volume(CellKind::Hexahedron), "hexahedron"),
        6 => (6, Kind::Volume(CellKind::Wedge), "prism"),
        7 => (5, Kind::Volume(CellKind::Pyramid), "pyramid"),
        8 => (3, Kind::Line, "3-node line"),
        9 => (6, Kind::Triangle, "6-node triangle"),
        10 => (9, Kind::Quad, "9-node quadrangle"),
        11 => (
            10,
            Kind::Volume(CellKind::Tetrahedron),
            "10-node tetrahedron",
        ),
        12 => (27, Kind::Volume(CellKind::Hexahedron), "27-node hexahedron"),
        13 => (18, Kind::Volume(CellKind::Wedge), "18-node prism"),
        14 => (14, Kind::Volume(CellKind::Pyramid), "14-node pyramid"),
        15 => (1, Kind::Point, "point"),
        16 => (8, Kind::Quad, "8-node quadrangle"),
        17 => (20, Kind::Volume(CellKind::Hexahedron), "20-node hexahedron"),
        18 => (15, Kind::Volume(CellKind::Wedge), "15-node prism"),
        19 => (13, Kind::Volume(CellKind::Pyramid), "13-node pyramid"),
        20 => (9, Kind::Triangle, "9-node triangle"),
        21 => (10, Kind::Triangle, "10-node triangle"),
        26 => (4, Kind::Line, "4-node line"),
        27 => (5, Kind::Line, "5-node line"),
        28 => (6, Kind::Line, "6-node line"),
        29 => (
            20,
            Kind::Volume(CellKind::Tetrahedron),
            "20-node tetrahedron",
        ),
        _ => return None,
    })
}

struct Reader<'a> {
    s: Scanner<'a>,
    binary: bool,
    version: Version,
    physical_names: BTreeMap<(i32, i32), String>,
    /// (dim, entity tag) → its physical tags.
    entity_physicals: BTreeMap<(i32, i32), Vec<i32>>,
    nodes: NodeIndex,
    b: Builder,
    /// Element counts by what happened to them: (kind name, count).
    kinds: BTreeMap<&'static str, usize>,
    multi_physical: usize,
    /// (dim, physical or −entity) → group index, filled lazily.
    group_of: FastMap<(i32, i64), usize>,
    /// The current section's `$End…` marker and where its data starts: a
    /// count the data cannot satisfy means the file was cut short when the
    /// marker is missing. Looked for only then (see [`Reader::section_closed`]):
    /// a search on every section would read the whole file once more.
    section: Option<(String, usize)>,
}

impl<'a> Reader<'a> {
    fn read(&mut self) -> Result<(), Diagnostic> {
        self.header()?;
        let mut seen_nodes = false;
        while let Some(t) = self.s.next_token() {
            if t.text.first() != Some(&b'$') {
                return Err(syntax(t, "a section such as `$Nodes`"));
            }
            let name = t.lossy().get(1..).unwrap_or_default().to_string();
            self.section = Some((format!("$End{name}"), self.s.pos));
            self.section_start();
            match name.as_str() {
                "PhysicalNames" => self.physical_names()?,
                "Entities" if self.version == Version::V41 => self.entities()?,
                "Nodes" => {
                    match self.version {
                        Version::V41 => self.nodes41()?,
                        Version::V22 => self.nodes22()?,
                    }
                    seen_nodes = true;
                }
                "Elements" => {
                    if !seen_nodes {
                        return Err(error_at(
                            Code::MeshSyntax,
                            t.start,
                            t.end(),
                            "`$Elements` comes before `$Nodes`",
                        ));
                    }
                    match self.version {
                        Version::V41 => self.elements41()?,
                        Version::V22 => self.elements22()?,
                    }
                }
                _ => {
                    self.skip_section(&name, t)?;
                    continue;
                }
            }
            self.end(&name)?;
        }
        Ok(())
    }

    fn header(&mut self) -> Result<(), Diagnostic> {
        self.s.keyword("$MeshFormat")?;
        let v = self.s.expect("the MSH version")?;
        self.version = match v.text {
            b"4.1" => Version::V41,
            b"2.2" | b"2.1" | b"2" | b"2.0" => Version::V22,
            _ => {
                return Err(error_at(
                    Code::MeshUnsupportedVersion,
                    v.start,
                    v.end(),
                    format!(
                        "MSH version {} is not read: geomc reads 2.2 and 4.1",
                        v.lossy()
                    ),
                )
                .with_help("save the mesh from Gmsh as version 4.1 or 2.2 (Mesh.MshFileVersion)"));
            }
        };
        let ft = self.s.expect("the file type (0 ASCII, 1 binary)")?;
        self.binary = match ft.text {
            b"0" => false,
            b"1" => true,
            _ => return Err(syntax(ft, "0 (ASCII) or 1 (binary)")),
        };
        let ds = self.s.expect("the data size")?;
        if self.binary && ds.text != b"8" {
            return Err(error_at(
                Code::MeshUnsupportedVersion,
                ds.start,
                ds.end(),
                format!(
                    "binary MSH with {}-byte sizes: geomc reads 8-byte sizes",
                    ds.lossy()
                ),
            ));
        }
        if self.binary {
            self.section_start();
            let at = self.here();
            let one = self.raw_i32()?;
            if one != 1 {
                return Err(error_at_byte(
                    Code::MeshUnsupportedVersion,
                    at,
                    "the binary MSH is big-endian (its check integer is not 1 in little-endian): geomc reads little-endian files",
                ));
            }
        }
        self.s.keyword("$EndMeshFormat")?;
        Ok(())
    }

    /// Whether the current section's `$End…` marker follows its start (true
    /// outside any section).
    fn section_closed(&self) -> bool {
        let Some((end, from)) = &self.section else {
            return true;
        };
        let rest = self.s.bytes.get(*from..).unwrap_or_default();
        memchr::memmem::find(rest, end.as_bytes()).is_some()
    }

    /// After a section's name line: skips the one line end before binary data.
    fn section_start(&mut self) {
        let b = self.s.bytes;
        while matches!(b.get(self.s.pos), Some(b' ' | b'\r')) {
            self.s.pos += 1;
        }
        if b.get(self.s.pos) == Some(&b'\n') {
            self.s.pos += 1;
        }
    }

    fn end(&mut self, name: &str) -> Result<(), Diagnostic> {
        self.s.keyword(&format!("$End{name}")).map(|_| ())
    }

    fn skip_section(&mut self, name: &str, start: Token) -> Result<(), Diagnostic> {
        let end = format!("$End{name}");
        let rest = self.s.bytes.get(self.s.pos..).unwrap_or_default();
        match memchr::memmem::find(rest, end.as_bytes()) {
            Some(i) => {
                self.s.pos += i + end.len();
                Ok(())
            }
            None => Err(error_at(
                Code::MeshTruncated,
                start.start,
                start.end(),
                format!("section `${name}` has no `{end}`"),
            )),
        }
    }

    // ---- values: ASCII tokens or little-endian binary ----

    fn err(&self, code: Code, at: usize, len: usize, message: String) -> Diagnostic {
        if self.binary {
            error_at_byte(code, at, message)
        } else {
            error_at(code, at, at + len, message)
        }
    }

    fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8], Diagnostic> {
        let b = self.s.bytes;
        let Some(out) = b.get(self.s.pos..).and_then(|rest| rest.get(..n)) else {
            return Err(error_at_byte(
                Code::MeshTruncated,
                b.len(),
                format!("the file ends where {what} was expected"),
            )
            .with_help(
                "the file is truncated: write it again, or check that the copy is complete",
            ));
        };
        self.s.pos += n;
        Ok(out)
    }

    /// The offset of the next value (in ASCII, past the whitespace before it).
    fn here(&mut self) -> usize {
        if !self.binary {
            let b = self.s.bytes;
            while b.get(self.s.pos).is_some_and(u8::is_ascii_whitespace) {
                self.s.pos += 1;
            }
        }
        self.s.pos
    }

    fn raw_i32(&mut self) -> Result<i32, Diagnostic> {
        let b = self.take(4, "a 4-byte integer")?;
        Ok(i32::from_le_bytes(super::array(b).unwrap_or([0; 4])))
    }

    /// An `int` (tags, dimensions, types).
    fn int(&mut self, what: &str) -> Result<i64, Diagnostic> {
        if self.binary {
            Ok(i64::from(self.raw_i32()?))
        } else {
            self.s.integer(what)
        }
    }

    /// A `size_t` in 4.1 (counts, node and element tags).
    fn size(&mut self, what: &str) -> Result<u64, Diagnostic> {
        if self.binary {
            let b = self.take(8, what)?;
            let mut a = [0u8; 8];
            a.copy_from_slice(b);
            Ok(u64::from_le_bytes(a))
        } else {
            self.s.unsigned(what)
        }
    }

    fn real(&mut self, what: &str) -> Result<f64, Diagnostic> {
        if self.binary {
            let at = self.here();
            let b = self.take(8, what)?;
            let mut a = [0u8; 8];
            a.copy_from_slice(b);
            let v = f64::from_le_bytes(a);
            if !v.is_finite() {
                return Err(error_at_byte(
                    Code::MeshNonFinite,
                    at,
                    format!("{what} is {v}, not a finite number"),
                ));
            }
            Ok(v)
        } else {
            self.s.real(what)
        }
    }

    /// Refuses a count that the rest of the file cannot hold, before any
    /// allocation: each item takes at least `min_bytes`.
    fn plausible(
        &self,
        n: u64,
        min_bytes: u64,
        what: &str,
        at: usize,
    ) -> Result<usize, Diagnostic> {
        let left = (self.s.bytes.len() - self.s.pos.min(self.s.bytes.len())) as u64;
        if n.saturating_mul(min_bytes) > left + 1 {
            let closed = self.section_closed();
            let code = if closed {
                Code::MeshCountMismatch
            } else {
                Code::MeshTruncated
            };
            let message = if closed {
                format!(
                    "the file says {n} {what}, but only {left} bytes follow: the count does not match the data"
                )
            } else {
                format!("the file says {n} {what}, but ends {left} bytes later: it is truncated")
            };
            return Err(self.err(code, at, 1, message));
        }
        Ok(n as usize)
    }

    // ---- sections ----

    fn physical_names(&mut self) -> Result<(), Diagnostic> {
        let at = self.here();
        let n = self.s.unsigned("the number of physical names")?;
        let n = self.plausible(n, 6, "physical names", at)?;
        for _ in 0..n {
            let dim = self.s.integer("a physical group's dimension")? as i32;
            let tag = self.s.integer("a physical group's tag")? as i32;
            let name = self.s.rest_of_line().lossy();
            let name = name.trim().trim_matches('"').to_string();
            self.physical_names.insert((dim, tag), name);
        }
        Ok(())
    }

    fn entities(&mut self) -> Result<(), Diagnostic> {
        let mut counts = [0u64; 4];
        for c in &mut counts {
            *c = self.size("an entity count")?;
        }
        for (dim, &n) in counts.iter().enumerate() {
            let at = self.here();
            let n = self.plausible(n, 8, "entities", at)?;
            for _ in 0..n {
                let tag = self.int("an entity tag")? as i32;
                let reals = if dim == 0 { 3 } else { 6 };
                for _ in 0..reals {
                    self.real("an entity bounding-box coordinate")?;
                }
                let at = self.here();
                let np = self.size("the number of physical tags")?;
                let np = self.plausible(np, 1, "physical tags", at)?;
                let mut physicals = Vec::with_capacity(np);
                for _ in 0..np {
                    physicals.push(self.int("a physical tag")? as i32);
                }
                if dim > 0 {
                    let at = self.here();
                    let nb = self.size("the number of bounding entities")?;
                    let nb = self.plausible(nb, 1, "bounding entities", at)?;
                    for _ in 0..nb {
                        self.int("a bounding entity tag")?;
                    }
                }
                self.entity_physicals.insert((dim as i32, tag), physicals);
            }
        }
        Ok(())
    }

    fn add_node(
        &mut self,
        tag: u64,
        at: usize,
        p: [f64; 3],
        dense_limit: u64,
    ) -> Result<(), Diagnostic> {
        let index = self.b.nodes.len() as u32;
        if !self.nodes.insert(tag, index, dense_limit) {
            return Err(self.err(
                Code::MeshCountMismatch,
                at,
                1,
                format!("node tag {tag} is given twice"),
            ));
        }
        self.b.nodes.push(p);
        Ok(())
    }

    fn nodes41(&mut self) -> Result<(), Diagnostic> {
        let blocks = self.size("the number of node blocks")?;
        let at = self.here();
        let total = self.size("the number of nodes")?;
        let _min = self.size("the smallest node tag")?;
        let max = self.size("the largest node tag")?;
        let per_node = if self.binary { 32 } else { 8 };
        let total = self.plausible(total, per_node, "nodes", at)?;
        let dense_limit = max.min(4 * total as u64 + 1024) + 1;
        self.b.nodes.reserve(total);
        let at = self.here();
        let blocks = self.plausible(blocks, 8, "node blocks", at)?;
        let mut tags: Vec<(u64, usize)> = Vec::new();
        let mut read = 0usize;
        for _ in 0..blocks {
            let _dim = self.int("a node block's entity dimension")?;
            let _tag = self.int("a node block's entity tag")?;
            let parametric = self.int("the parametric flag")?;
            let at = self.here();
            let n = self.size("the number of nodes in a block")?;
            let n = self.plausible(n, per_node, "nodes in a block", at)?;
            let extra = if parametric != 0 {
                _dim.clamp(0, 3) as usize
            } else {
                0
            };
            if self.binary && extra == 0 && self.binary_node_block(n, dense_limit)? {
                read += n;
                continue;
            }
            tags.clear();
            for _ in 0..n {
                let at = self.here();
                tags.push((self.size("a node tag")?, at));
            }
            for &(tag, at) in &tags {
                let p = [
                    self.real("a node coordinate")?,
                    self.real("a node coordinate")?,
                    self.real("a node coordinate")?,
                ];
                for _ in 0..extra {
                    self.real("a parametric coordinate")?;
                }
                self.add_node(tag, at, p, dense_limit)?;
            }
            read += n;
        }
        if read != total {
            return Err(self.err(
                Code::MeshCountMismatch,
                self.s.pos,
                1,
                format!("`$Nodes` says {total} nodes, its blocks hold {read}"),
            ));
        }
        Ok(())
    }

    /// A binary block of `n` nodes (their tags, then their coordinates) read
    /// straight from the bytes when the file holds all of it, with no list of
    /// tags (else `false`: the value-by-value path finds the end and says
    /// where). The same checks in the same order as that path: a node's
    /// coordinates, then its tag.
    fn binary_node_block(&mut self, n: usize, dense_limit: u64) -> Result<bool, Diagnostic> {
        let bytes = self.s.bytes;
        let start = self.s.pos;
        let Some((tags, coordinates)) = n
            .checked_mul(32)
            .and_then(|len| bytes.get(start..)?.get(..len))
            .and_then(|block| block.split_at_checked(8 * n))
        else {
            return Ok(false);
        };
        let first_coordinate = start + 8 * n;
        if self.run_on_block(tags, coordinates) {
            self.s.pos = start + 32 * n;
            return Ok(true);
        }
        for (i, (record, tag)) in coordinates
            .chunks_exact(24)
            .zip(tags.chunks_exact(8))
            .enumerate()
        {
            let mut p = [0.0; 3];
            for (k, (slot, c)) in p.iter_mut().zip(record.chunks_exact(8)).enumerate() {
                let v = f64::from_le_bytes(super::array(c).unwrap_or([0; 8]));
                if !v.is_finite() {
                    return Err(error_at_byte(
                        Code::MeshNonFinite,
                        first_coordinate + 24 * i + 8 * k,
                        format!("a node coordinate is {v}, not a finite number"),
                    ));
                }
                *slot = v;
            }
            let tag = u64::from_le_bytes(super::array(tag).unwrap_or([0; 8]));
            self.add_node(tag, start + 8 * i, p, dense_limit)?;
        }
        self.s.pos = start + 32 * n;
        Ok(true)
    }

    /// The common block at once: tags that run on from the nodes before
    /// (1, 2, 3, …) and finite coordinates, copied in parallel pieces (in
    /// order). `false`, with nothing added, for any other block: the
    /// node-by-node loop then reads it and gives the first error.
    fn run_on_block(&mut self, tags: &[u8], coordinates: &[u8]) -> bool {
        let n = tags.len() / 8;
        let next = self.b.nodes.len();
        if n == 0 || !self.nodes.run_continues(tags, next) {
            return false;
        }
        let value =
            |r: &[u8], at: usize| f64::from_le_bytes(super::bytes_at::<8>(r, at).unwrap_or([0; 8]));
        // Each piece's bounds found while it is in cache (`None`: a
        // coordinate that is not finite).
        let pieces = extend_summed(
            &mut self.b.nodes,
            coordinates,
            24,
            NODE_PIECE,
            |r| [value(r, 0), value(r, 8), value(r, 16)],
            finite_bounds,
        );
        if pieces.iter().any(Option::is_none) {
            self.b.nodes.truncate(next);
            return false;
        }
        let bounds = pieces.into_iter().fold(None, merge_bounds);
        self.b.known.add_nodes(next, n, bounds);
        self.nodes.extend_run(tags, n);
        true
    }

    /// A binary block of `n` elements of `k` nodes read at once, when the
    /// file holds all of it (else `false`, as [`Self::binary_node_block`]).
    fn binary_elements(
        &mut self,
        n: usize,
        k: usize,
        kind: Kind,
        name: &'static str,
        group: usize,
    ) -> Result<bool, Diagnostic> {
        let bytes = self.s.bytes;
        let start = self.s.pos;
        let per = 8 * (k + 1);
        let Some(block) = n
            .checked_mul(per)
            .and_then(|len| bytes.get(start..)?.get(..len))
        else {
            return Ok(false);
        };
        if kind == Kind::Triangle && k == 3 && self.binary_triangles(block, group) {
            self.s.pos = start + block.len();
            return Ok(true);
        }
        let mut corners: Vec<u32> = Vec::with_capacity(k);
        for (i, record) in block.chunks_exact(per).enumerate() {
            corners.clear();
            // The element's own tag (the first 8 bytes) is not kept.
            for (j, t) in record
                .get(8..)
                .unwrap_or_default()
                .chunks_exact(8)
                .enumerate()
            {
                let tag = u64::from_le_bytes(super::array(t).unwrap_or([0; 8]));
                corners.push(self.node(tag, start + per * i + 8 * (j + 1))?);
            }
            self.add_element(kind, name, &corners, group);
        }
        self.s.pos = start + block.len();
        Ok(true)
    }

    /// Linear triangles (most of a surface mesh) straight into their group's
    /// reserved room, their node tags looked up in parallel pieces (the same
    /// triangles in the same order on any thread count; no zero fill first).
    /// `false`, with nothing added, when a tag is unknown: the general path
    /// then says which and where.
    fn binary_triangles(&mut self, block: &[u8], group: usize) -> bool {
        let nodes = &self.nodes;
        let Some(g) = self.b.groups.get_mut(group) else {
            return false;
        };
        let base = g.triangles.len();
        let pieces = if let Some((first, len)) = nodes.run {
            run_triangles(block, first, u64::from(len), &mut g.triangles)
        } else {
            let tag = |r: &[u8], at: usize| {
                super::bytes_at::<8>(r, at).and_then(|b| nodes.get(u64::from_le_bytes(b)))
            };
            let unknown = AtomicBool::new(false);
            triangles_summed(&mut g.triangles, block, &unknown, |r| {
                match (tag(r, 8), tag(r, 16), tag(r, 24)) {
                    (Some(a), Some(b), Some(c)) => [a, b, c],
                    _ => {
                        unknown.store(true, Ordering::Relaxed);
                        [0; 3]
                    }
                }
            })
        };
        let Some(pieces) = pieces else {
            return false;
        };
        // The pieces start at the face's first triangle only when the
        // group had none before: else the facts are found after reading.
        if base == 0 {
            let facts = FaceFacts::from_pieces(g.triangles.len(), pieces);
            self.b.known.faces.insert(group, facts);
        }
        true
    }

    fn nodes22(&mut self) -> Result<(), Diagnostic> {
        let at = self.here();
        let n = self.s.unsigned("the number of nodes")?;
        let per_node = if self.binary { 28 } else { 8 };
        let n = self.plausible(n, per_node, "nodes", at)?;
        self.b.nodes.reserve(n);
        let dense_limit = 4 * n as u64 + 1024;
        if self.binary {
            self.section_start();
        }
        for _ in 0..n {
            let at = self.here();
            let tag = self.int("a node tag")?;
            if tag < 0 {
                return Err(self.err(
                    Code::MeshIndexOutOfRange,
                    at,
                    1,
                    format!("node tag {tag} is negative"),
                ));
            }
            let p = [
                self.real("a node coordinate")?,
                self.real("a node coordinate")?,
                self.real("a node coordinate")?,
            ];
            self.add_node(tag as u64, at, p, dense_limit)?;
        }
        Ok(())
    }

    fn node(&self, tag: u64, at: usize) -> Result<u32, Diagnostic> {
        self.nodes.get(tag).ok_or_else(|| {
            self.err(
                Code::MeshIndexOutOfRange,
                at,
                1,
                format!("an element refers to node {tag}, which `$Nodes` does not define"),
            )
        })
    }

    fn element_kind(&self, t: i64, at: usize) -> Result<(usize, Kind, &'static str), Diagnostic> {
        element_type(t).ok_or_else(|| {
            self.err(
                Code::MeshUnsupportedElement,
                at,
                1,
                format!("element type {t} is not one geomc knows (Gmsh types 1–21, 26–29)"),
            )
            .with_help("points, lines, triangles, quadrangles and the volume cells are read; save the mesh with those")
        })
    }

    /// The group of an element: its physical group, else its entity.
    fn group_for(&mut self, dim: i32, physical: Option<i32>, entity: i32) -> usize {
        let key = match physical {
            Some(p) => (dim, i64::from(p)),
            None => (dim, -1 - i64::from(entity)),
        };
        if let Some(&g) = self.group_of.get(&key) {
            return g;
        }
        let name = match physical {
            Some(p) => self
                .physical_names
                .get(&(dim, p))
                .cloned()
                .unwrap_or_else(|| format!("physical {dim}:{p}")),
            None => format!(
                "{} {entity}",
                ["point", "curve", "surface", "volume"]
                    .get(dim.clamp(0, 3) as usize)
                    .unwrap_or(&"volume")
            ),
        };
        let g = self.b.group(&name);
        self.group_of.insert(key, g);
        g
    }

    fn add_element(&mut self, kind: Kind, name: &'static str, corners: &[u32], group: usize) {
        let Some(g) = self.b.groups.get_mut(group) else {
            return;
        };
        // The element's node count per type is checked where it is read.
        match (kind, corners) {
            (Kind::Point, &[a, ..]) => g.points.push(a),
            (Kind::Line, &[a, b, ..]) => g.lines.push([a, b]),
            (Kind::Triangle, &[a, b, c, ..]) => g.triangles.push([a, b, c]),
            (Kind::Quad, &[a, b, c, d, ..]) => {
                g.triangles.push([a, b, c]);
                g.triangles.push([a, c, d]);
            }
            (Kind::Volume(k), c) => g.add_cell(k, c),
            _ => {}
        }
        let high_order = match kind {
            Kind::Line => corners.len() > 2,
            Kind::Triangle => corners.len() > 3,
            Kind::Quad => corners.len() > 4,
            Kind::Volume(k) => corners.len() > k.corners(),
            Kind::Point => false,
        };
        if kind == Kind::Quad || high_order {
            *self.kinds.entry(name).or_default() += 1;
        }
    }

    fn elements41(&mut self) -> Result<(), Diagnostic> {
        let blocks = self.size("the number of element blocks")?;
        let at = self.here();
        let total = self.size("the number of elements")?;
        self.size("the smallest element tag")?;
        self.size("the largest element tag")?;
        let per = if self.binary { 16 } else { 4 };
        let total = self.plausible(total, per, "elements", at)?;
        let at = self.here();
        let blocks = self.plausible(blocks, 8, "element blocks", at)?;
        let mut read = 0usize;
        let mut corners: Vec<u32> = Vec::new();
        for _ in 0..blocks {
            let dim = self.int("an element block's dimension")? as i32;
            let entity = self.int("an element block's entity tag")? as i32;
            let at = self.here();
            let t = self.int("an element type")?;
            let (k, kind, name) = self.element_kind(t, at)?;
            let at = self.here();
            let n = self.size("the number of elements in a block")?;
            let n = self.plausible(n, per * k as u64 / 2, "elements in a block", at)?;
            let physicals = self
                .entity_physicals
                .get(&(dim, entity))
                .cloned()
                .unwrap_or_default();
            if physicals.len() > 1 {
                self.multi_physical += n;
            }
            let group = self.group_for(dim, physicals.first().copied(), entity);
            if let Kind::Triangle | Kind::Quad = kind
                && let Some(g) = self.b.groups.get_mut(group)
            {
                g.triangles
                    .reserve(n * if kind == Kind::Quad { 2 } else { 1 });
            }
            if self.binary && self.binary_elements(n, k, kind, name, group)? {
                read += n;
                continue;
            }
            for _ in 0..n {
                self.size("an element tag")?;
                corners.clear();
                for _ in 0..k {
                    let at = self.here();
                    let tag = self.size("an element's node tag")?;
                    corners.push(self.node(tag, at)?);
                }
                self.add_element(kind, name, &corners, group);
            }
            read += n;
        }
        if read != total {
            return Err(self.err(
                Code::MeshCountMismatch,
                self.s.pos,
                1,
                format!("`$Elements` says {total} elements, its blocks hold {read}"),
            ));
        }
        Ok(())
    }

    fn elements22(&mut self) -> Result<(), Diagnostic> {
        let at = self.here();
        let total = self.s.unsigned("the number of elements")?;
        let per = if self.binary { 12 } else { 6 };
        let total = self.plausible(total, per, "elements", at)?;
        let mut corners: Vec<u32> = Vec::new();
        let mut tags: Vec<i64> = Vec::new();
        if self.binary {
            self.section_start();
            let mut read = 0usize;
            while read < total {
                let at = self.here();
                let t = self.int("an element type")?;
                let (k, kind, name) = self.element_kind(t, at)?;
                let at = self.here();
                let n = self.int("the number of elements in a block")?;
                let nt = self.int("the number of tags")?;
                if n <= 0 || n as usize > total - read || !(0..=64).contains(&nt) {
                    return Err(self.err(
                        Code::MeshCountMismatch,
                        at,
                        1,
                        format!("an element block of {n} elements with {nt} tags does not fit the {total} elements announced"),
                    ));
                }
                for _ in 0..n {
                    self.int("an element tag")?;
                    tags.clear();
                    for _ in 0..nt {
                        tags.push(self.int("an element's tag")?);
                    }
                    corners.clear();
                    for _ in 0..k {
                        let at = self.here();
                        let tag = self.int("an element's node")?;
                        corners.push(self.node(tag.max(0) as u64, at)?);
                    }
                    self.element22(kind, name, &tags, &corners);
                }
                read += n as usize;
            }
            return Ok(());
        }
        for _ in 0..total {
            self.s.integer("an element tag")?;
            let tt = self.s.expect("an element type")?;
            let t = super::text::integer(tt, "an element type")?;
            let (k, kind, name) = self.element_kind(t, tt.start)?;
            let nt = self.s.unsigned("the number of tags")?;
            tags.clear();
            for _ in 0..nt.min(64) {
                tags.push(self.s.integer("an element's tag")?);
            }
            corners.clear();
            for _ in 0..k {
                let tok = self.s.expect("an element's node")?;
                let tag = super::text::unsigned(tok, "an element's node")?;
                corners.push(self.node(tag, tok.start)?);
            }
            self.element22(kind, name, &tags, &corners);
        }
        Ok(())
    }

    fn element22(&mut self, kind: Kind, name: &'static str, tags: &[i64], corners: &[u32]) {
        let dim = match kind {
            Kind::Point => 0,
            Kind::Line => 1,
            Kind::Triangle | Kind::Quad => 2,
            Kind::Volume(_) => 3,
        };
        let physical = tags.first().copied().filter(|&p| p != 0).map(|p| p as i32);
        let entity = tags.get(1).copied().unwrap_or(0) as i32;
        let group = self.group_for(dim, physical, entity);
        self.add_element(kind, name, corners, group);
    }

    fn finish(mut self) -> Builder {
        let mut quads = 0;
        let mut high = Vec::new();
        for (&name, &n) in &self.kinds {
            let kind = (1..=29)
                .filter_map(element_type)
                .find(|e| e.2 == name)
                .map(|e| e.1);
            match kind {
                Some(Kind::Quad) => {
                    quads += n;
                    if name != "quadrangle" {
                        high.push(format!("{n} {name}s"));
                    }
                }
                _ => high.push(format!("{n} {name}s")),
            }
        }
        if quads > 0 {
            self.b.warn(
                Code::ElementsConverted,
                format!("{quads} quadrangles split into two triangles each"),
            );
        }
        if !high.is_empty() {
            self.b.warn(
                Code::ElementsConverted,
                format!(
                    "higher-order elements reduced to their corner nodes: {}",
                    high.join(", ")
                ),
            );
        }
        if self.multi_physical > 0 {
            self.b.warn(
                Code::InputNotCarried,
                format!(
                    "{} elements belong to several physical groups: each is kept in its first group only",
                    self.multi_physical
                ),
            );
        }
        self.b
    }
}

#[cfg(test)]
mod tests {
    use super::NodeIndex;

    /// A binary MSH 4.1 file of two faces, one in first-use order and one
    /// not, each over several pieces: the facts found while reading its
    /// blocks are those a pass over the mesh after reading finds.
    #[test]
    fn facts_found_while_reading_equal_a_pass_after_it() {
        use crate::formats::groups::nodes_scan;
        use crate::formats::mesh_facts::FaceFacts;
        use crate::formats::{Encoding, MeshFacts, MeshWriter, WriteOptions};
        use crate::mesh::{Mesh, MeshFace};
        let n = 50_000u32;
        let nodes: Vec<[f64; 3]> = (0..n)
            .map(|i| {
                let x = f64::from(i);
                [3.0 * x.sin(), (0.01 * x).cos() - 2.0, 1e-4 * x]
            })
            .collect();
        let face = |name: &str, triangles: Vec<[u32; 3]>| MeshFace {
            name: name.into(),
            triangles,
            boundary: Vec::new(),
        };
        let strip: Vec<[u32; 3]> = (0..30_000).map(|i| [i, i + 1, i + 2]).collect();
        let ahead: Vec<[u32; 3]> = (30_000..n - 2).map(|i| [i + 2, i, i + 1]).collect();
        let mesh = Mesh {
            dimension: 3,
            nodes,
            faces: vec![face("a", strip), face("b", ahead)],
            ..Mesh::default()
        };
        let options = WriteOptions {
            encoding: Some(Encoding::Binary),
            ..WriteOptions::default()
        };
        let mut bytes = Vec::new();
        crate::formats::msh::Msh
            .write(&mesh, &options, &mut bytes)
            .expect("written");
        let (builder, _) = super::read(&bytes).expect("read");
        assert_eq!(builder.known.faces.len(), 2);
        let (_, bounds) = nodes_scan(&mesh.nodes);
        assert_eq!(builder.known.nodes, Some((n as usize, bounds)));
        let (loaded, facts) = builder.finish_with(true).expect("finished");
        let facts = facts.expect("facts");
        assert_eq!(loaded.mesh.nodes, mesh.nodes);
        let scanned: Vec<FaceFacts> = loaded
            .mesh
            .faces
            .iter()
            .map(|f| FaceFacts::of(&f.triangles))
            .collect();
        assert_eq!(
            Ok(facts.clone()),
            MeshFacts::of(&loaded.mesh.nodes, scanned)
        );
        assert_eq!(facts.faces[0].order.identity(), Some(30_002));
        assert_eq!(facts.faces[1].order.identity(), None);
        assert_eq!(facts.faces[1].largest(), n - 1);
        assert_eq!(facts.bounds.map(|(lo, _)| lo[2]), Some(0.0));
    }

    #[test]
    fn node_tags_that_run_on_need_no_table_and_a_break_moves_them_into_it() {
        let mut index = NodeIndex::default();
        assert_eq!(index.get(5), None);
        for (i, tag) in [5, 6, 7].into_iter().enumerate() {
            assert!(index.insert(tag, i as u32, 100));
        }
        assert!(index.dense.is_empty() && index.sparse.is_empty());
        assert_eq!(
            (index.get(4), index.get(5), index.get(7), index.get(8)),
            (None, Some(0), Some(2), None)
        );
        // A tag before the run breaks it; the run's tags keep their nodes.
        assert!(index.insert(2, 3, 100));
        assert!(index.run.is_none());
        assert_eq!(
            (index.get(2), index.get(5), index.get(7)),
            (Some(3), Some(0), Some(2))
        );
        // A tag of the run given again is a duplicate, in the vector and in the map.
        assert!(!index.insert(6, 4, 100));
        assert!(index.insert(1_000, 4, 100));
        assert_eq!(index.get(1_000), Some(4));
        // (After a refused duplicate the reader stops: what the table then
        // holds for that tag does not matter.)
        assert!(!index.insert(1_000, 5, 100));
    }

    #[test]
    fn a_repeated_first_tag_breaks_the_run_as_a_duplicate() {
        let mut index = NodeIndex::default();
        assert!(index.insert(u64::MAX, 0, 10));
        // The next tag would overflow: not in the run, and not a duplicate.
        assert!(index.insert(0, 1, 10));
        assert_eq!((index.get(u64::MAX), index.get(0)), (Some(0), Some(1)));
        assert!(!index.insert(u64::MAX, 2, 10));
    }
}
