//! STL, ASCII or binary, told apart by content: a file whose size is exactly
//! 84 + 50 × (its triangle count) is binary even when its header starts with
//! `solid` (many exporters write that); otherwise `solid` starts ASCII. Each
//! ASCII `solid NAME` is a group; binary STL is one group, `surface`. Nodes
//! with identical coordinates are merged (STL repeats them per triangle).

use super::ReadFormat;
use super::build::{Builder, NodeDedup};
use super::error_at_byte;
use super::f32_nodes::F32Nodes;
use super::text::{Scanner, real, syntax};
use crate::diag::{Code, Diagnostic};
use std::io::{Read, Seek, SeekFrom};
use std::path::Path;

/// Whether the bytes are an STL file by content.
pub fn looks_like_stl(bytes: &[u8]) -> bool {
    binary_size_matches(bytes) || ascii_start(bytes)
}

fn binary_size_matches(bytes: &[u8]) -> bool {
    super::bytes_at(bytes, 80)
        .is_some_and(|n| 84 + 50 * u64::from(u32::from_le_bytes(n)) == bytes.len() as u64)
}

fn ascii_start(bytes: &[u8]) -> bool {
    let start = bytes
        .iter()
        .position(|b| !b.is_ascii_whitespace())
        .unwrap_or(0);
    let head = bytes.get(start..).unwrap_or_default();
    let head = head.get(..5).unwrap_or(head);
    head.eq_ignore_ascii_case(b"solid")
        && (bytes.len() < 84 || !bytes.get(..1000).unwrap_or(bytes).contains(&0))
}

pub fn read(bytes: &[u8]) -> Result<(Builder, Option<bool>), Vec<Diagnostic>> {
    if binary_size_matches(bytes) {
        return Ok((read_binary(bytes)?, Some(true)));
    }
    if ascii_start(bytes) {
        return Ok((read_ascii(bytes).map_err(|d| vec![d])?, Some(false)));
    }
    let Some(count) = super::bytes_at(bytes, 80) else {
        return Err(vec![error_at_byte(
            Code::MeshTruncated,
            bytes.len(),
            format!(
                "a binary STL needs an 84-byte header with the triangle count, the file has {} bytes",
                bytes.len()
            ),
        )]);
    };
    let n = u64::from(u32::from_le_bytes(count));
    Err(vec![
        error_at_byte(
            Code::StlSizeMismatch,
            80,
            format!(
                "the binary STL header says {n} triangles, which take {} bytes, but the file has {} bytes",
                84 + 50 * n,
                bytes.len()
            ),
        )
        .with_help("the file is truncated or has extra data: write it again from the tool that made it"),
    ])
}

/// Reads a binary STL from its file in pieces of a megabyte, so the file is
/// never held whole (its bytes would be half the peak memory). `None` when
/// the file is not a binary STL by its size or when its head says it is
/// another format (the caller then reads it the usual way).
pub(super) fn read_binary_file(
    path: &Path,
    forced: bool,
) -> Option<Result<Builder, Vec<Diagnostic>>> {
    let mut file = std::fs::File::open(path).ok()?;
    let size = file.metadata().ok()?.len();
    let mut head = vec![0u8; size.min(512) as usize];
    file.read_exact(&mut head).ok()?;
    let count = u64::from(u32::from_le_bytes(super::bytes_at(&head, 80)?));
    if 84 + 50 * count != size {
        return None;
    }
    if !forced {
        let text = String::from_utf8_lossy(&head);
        let t = text.trim_start();
        let other = matches!(
            super::detect(path, &head),
            Some(ReadFormat::Glb | ReadFormat::Msh | ReadFormat::FragXml | ReadFormat::Vtu)
        ) || t.starts_with("<?xml")
            || t.starts_with("<VTKFile");
        if other {
            return None;
        }
    }
    let n = count as usize;
    let mut r = BinaryStl::new(n);
    let failed = |e: std::io::Error| {
        vec![Diagnostic::new(
            Code::MeshReadFailed,
            None,
            format!("cannot read {}: {e}", path.display()),
        )]
    };
    let result = (|| {
        file.seek(SeekFrom::Start(84)).map_err(failed)?;
        const PIECE: usize = 20_000;
        let mut buf = vec![0u8; 50 * PIECE.min(n)];
        let mut done = 0;
        while done < n {
            let k = PIECE.min(n - done);
            let piece = buf.get_mut(..50 * k).unwrap_or_default();
            file.read_exact(piece).map_err(failed)?;
            r.records(piece, done)?;
            done += k;
        }
        Ok(())
    })();
    Some(result.map(|()| r.finish()))
}

fn read_binary(bytes: &[u8]) -> Result<Builder, Vec<Diagnostic>> {
    let records = bytes.get(84..).unwrap_or_default();
    let mut r = BinaryStl::new(records.len() / 50);
    r.records(records, 0)?;
    Ok(r.finish())
}

/// Records ahead whose node table slots are fetched while one is read.
const AHEAD: usize = 8;

/// A record's nine corner coordinates.
#[inline(always)]
fn corners(r: &[u8; 50]) -> [f32; 9] {
    let f = |at: usize| super::bytes_at::<4>(r, at).map_or(0.0, f32::from_le_bytes);
    std::array::from_fn(|j| f(12 + 4 * j))
}

/// A binary STL read record by record (from memory, or in pieces from a file).
pub(super) struct BinaryStl {
    b: Builder,
    nodes: F32Nodes,
    triangles: Vec<[u32; 3]>,
    attributes: usize,
}

impl BinaryStl {
    /// For `n` triangles.
    pub(super) fn new(n: usize) -> BinaryStl {
        let mut b = Builder::new();
        // About half as many nodes as triangles in a closed surface.
        b.nodes.reserve(n / 2 + 16);
        BinaryStl {
            b,
            nodes: F32Nodes::with_capacity(n / 2 + 16),
            triangles: Vec::with_capacity(n),
            attributes: 0,
        }
    }

    /// Reads whole 50-byte records; `first` is the index of the first one.
    pub(super) fn records(&mut self, records: &[u8], first: usize) -> Result<(), Vec<Diagnostic>> {
        for (k, record) in records.chunks_exact(50).enumerate() {
            let Some(r) = record.first_chunk::<50>() else {
                continue;
            };
            // The node table's slots of a record a few ahead, asked for now.
            if let Some(ahead) = records
                .get(50 * (k + AHEAD)..)
                .and_then(|a| a.first_chunk::<50>())
            {
                let [a, b, c, d, e, f, g, h, i] = corners(ahead);
                for p in [[a, b, c], [d, e, f], [g, h, i]] {
                    self.nodes.prefetch(p);
                }
            }
            let coords = corners(r);
            if let Some(j) = coords.iter().position(|v| !v.is_finite()) {
                let i = first + k;
                return Err(vec![error_at_byte(
                    Code::MeshNonFinite,
                    84 + 50 * i + 12 + 4 * j,
                    format!(
                        "triangle {} has a coordinate `{}`, not a finite number",
                        i + 1,
                        coords.get(j).copied().unwrap_or(f32::NAN)
                    ),
                )]);
            }
            let mut tri = [0u32; 3];
            for (slot, p) in tri.iter_mut().zip(coords.chunks_exact(3)) {
                let p = [p.first(), p.get(1), p.get(2)].map(|v| v.copied().unwrap_or(0.0));
                *slot = self.nodes.node(&mut self.b.nodes, p);
            }
            if r.get(48..).is_some_and(|a| a.iter().any(|&x| x != 0)) {
                self.attributes += 1;
            }
            self.triangles.push(tri);
        }
        Ok(())
    }

    pub(super) fn finish(self) -> Builder {
        let BinaryStl {
            mut b,
            nodes,
            triangles,
            attributes,
        } = self;
        drop(nodes);
        if attributes > 0 {
            b.warn(
                Code::InputNotCarried,
                format!("{attributes} triangles carry attribute bytes (often colours): not kept"),
            );
        }
        let g = b.group("surface");
        if let Some(group) = b.groups.get_mut(g) {
            group.triangles = triangles;
        }
        b
    }
}

fn read_ascii(bytes: &[u8]) -> Result<Builder, Diagnostic> {
    let mut s = Scanner::new(bytes);
    let mut b = Builder::new();
    let mut dedup = NodeDedup::with_capacity(bytes.len() / 200 + 16);
    while let Some(t) = s.next_token() {
        if !t.text.eq_ignore_ascii_case(b"solid") {
            return Err(syntax(t, "`solid`"));
        }
        let name = s.rest_of_line().lossy().trim().to_string();
        let name = if name.is_empty() {
            "unnamed".to_string()
        } else {
            name
        };
        let g = b.group(&name);
        loop {
            let t = s.expect("`facet` or `endsolid`")?;
            if t.text.eq_ignore_ascii_case(b"endsolid") {
                s.rest_of_line();
                break;
            }
            if !t.text.eq_ignore_ascii_case(b"facet") {
                return Err(syntax(t, "`facet` or `endsolid`"));
            }
            // `normal nx ny nz`: read for syntax, recomputed from the corners.
            keyword(&mut s, "normal")?;
            for _ in 0..3 {
                s.real("a normal component")?;
            }
            keyword(&mut s, "outer")?;
            keyword(&mut s, "loop")?;
            let mut tri = [0u32; 3];
            for slot in &mut tri {
                keyword(&mut s, "vertex")?;
                let mut p = [0.0; 3];
                for c in &mut p {
                    let t = s.expect("a vertex coordinate")?;
                    *c = real(t, "a vertex coordinate")?;
                }
                *slot = dedup.node(&mut b.nodes, p);
            }
            let t = s.expect("`endloop`")?;
            if !t.text.eq_ignore_ascii_case(b"endloop") {
                return Err(if t.text.eq_ignore_ascii_case(b"vertex") {
                    super::error_at(
                        Code::MeshUnsupportedElement,
                        t.start,
                        t.end(),
                        "a facet with more than 3 vertices: STL facets are triangles",
                    )
                } else {
                    syntax(t, "`endloop`")
                });
            }
            keyword(&mut s, "endfacet")?;
            if let Some(group) = b.groups.get_mut(g) {
                group.triangles.push(tri);
            }
        }
    }
    Ok(b)
}

fn keyword(s: &mut Scanner, word: &str) -> Result<(), Diagnostic> {
    let t = s.expect(&format!("`{word}`"))?;
    if t.text.eq_ignore_ascii_case(word.as_bytes()) {
        Ok(())
    } else {
        Err(syntax(t, &format!("`{word}`")))
    }
}
