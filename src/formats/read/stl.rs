//! STL, ASCII or binary, told apart by content: a file whose size is exactly
//! 84 + 50 × (its triangle count) is binary even when its header starts with
//! `solid` (many exporters write that); otherwise `solid` starts ASCII. Each
//! ASCII `solid NAME` is a group; binary STL is one group, `surface`. Nodes
//! with identical coordinates are merged (STL repeats them per triangle).

use super::build::{Builder, NodeDedup};
use super::error_at_byte;
use super::text::{Scanner, real, syntax};
use crate::diag::{Code, Diagnostic};

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

fn read_binary(bytes: &[u8]) -> Result<Builder, Vec<Diagnostic>> {
    let records = bytes.get(84..).unwrap_or_default();
    let n = records.len() / 50;
    let mut b = Builder::new();
    // About half as many nodes as triangles in a closed surface.
    let mut dedup = NodeDedup::with_capacity(n / 2 + 16);
    b.nodes.reserve(n / 2 + 16);
    let mut triangles = Vec::with_capacity(n);
    let mut attributes = 0usize;
    for (i, record) in records.chunks_exact(50).enumerate() {
        let mut tri = [0u32; 3];
        for (k, slot) in tri.iter_mut().enumerate() {
            let mut p = [0.0f64; 3];
            for (c, value) in p.iter_mut().enumerate() {
                let at = 12 + 12 * k + 4 * c;
                // A record is 50 bytes: `at + 4` is at most 48.
                let v = f32::from_le_bytes(super::bytes_at(record, at).unwrap_or([0; 4]));
                if !v.is_finite() {
                    return Err(vec![error_at_byte(
                        Code::MeshNonFinite,
                        84 + 50 * i + at,
                        format!(
                            "triangle {} has a coordinate `{v}`, not a finite number",
                            i + 1
                        ),
                    )]);
                }
                *value = f64::from(v);
            }
            *slot = dedup.node(&mut b.nodes, p);
        }
        if record.get(48..).is_some_and(|a| a.iter().any(|&x| x != 0)) {
            attributes += 1;
        }
        triangles.push(tri);
    }
    drop(dedup);
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
    Ok(b)
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
