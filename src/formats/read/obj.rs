//! Wavefront OBJ: `v` positions, `f` faces (polygons split into fans), `l`
//! polylines, `p` points. Objects (`o`) are the groups; in a file without
//! objects `g` groups are (`unnamed` before the first). Texture coordinates, input normals and materials are not
//! kept (normals are recomputed by every writer), which a warning says.
//! Hand-written rather than tobj so that every error has a line and column.

use super::build::Builder;
use super::error_at;
use super::text::{Scanner, Token, real, syntax};
use crate::diag::{Code, Diagnostic};

pub fn read(bytes: &[u8]) -> Result<Builder, Vec<Diagnostic>> {
    read_inner(bytes).map_err(|d| vec![d])
}

#[derive(Default)]
struct Ignored {
    texture: usize,
    normals: usize,
    materials: usize,
    other: usize,
    polygons: usize,
}

fn read_inner(bytes: &[u8]) -> Result<Builder, Diagnostic> {
    let mut s = Scanner::new(bytes);
    let mut b = Builder::new();
    b.nodes.reserve(bytes.len() / 60);
    let mut group: Option<usize> = None;
    let mut ignored = Ignored::default();
    let mut corners: Vec<u32> = Vec::new();
    let has_objects = bytes.starts_with(b"o ") || memchr::memmem::find(bytes, b"\no ").is_some();
    while let Some(t) = s.next_token() {
        if t.text.first() == Some(&b'#') {
            s.skip_line();
            continue;
        }
        match t.text {
            b"v" => {
                let mut p = [0.0; 3];
                for c in &mut p {
                    let t = s
                        .next_on_line()
                        .ok_or_else(|| short_line(&s, "three coordinates after `v`"))?;
                    *c = real(t, "a vertex coordinate")?;
                }
                b.nodes.push(p);
                s.skip_line(); // an optional weight or colour
            }
            b"f" | b"l" | b"p" => {
                corners.clear();
                while let Some(c) = s.next_on_line() {
                    corners.push(index(c, b.nodes.len())?);
                    check_extra_indices(c, ignored.texture, ignored.normals)?;
                }
                let need = match t.text {
                    b"f" => 3,
                    b"l" => 2,
                    _ => 1,
                };
                if corners.len() < need {
                    return Err(error_at(
                        Code::MeshCountMismatch,
                        t.start,
                        t.end(),
                        format!(
                            "`{}` with {} vertices: it needs at least {need}",
                            t.lossy(),
                            corners.len()
                        ),
                    ));
                }
                let g = *group.get_or_insert_with(|| b.group("unnamed"));
                let Some(target) = b.groups.get_mut(g) else {
                    continue;
                };
                match t.text {
                    b"f" => {
                        if corners.len() > 3 {
                            ignored.polygons += 1;
                        }
                        // A fan from the first corner (at least 3, checked above).
                        if let Some((&first, rest)) = corners.split_first() {
                            target.triangles.extend(
                                rest.windows(2)
                                    .filter_map(super::array::<u32, 2>)
                                    .map(|[a, c]| [first, a, c]),
                            );
                        }
                    }
                    b"l" => target
                        .lines
                        .extend(corners.windows(2).filter_map(super::array::<u32, 2>)),
                    _ => target.points.extend_from_slice(&corners),
                }
            }
            b"g" if has_objects => s.skip_line(),
            b"o" | b"g" => {
                let name = s.rest_of_line().lossy().trim().to_string();
                let name = if name.is_empty() {
                    "unnamed".to_string()
                } else {
                    name
                };
                group = Some(b.group(&name));
            }
            b"vt" => {
                ignored.texture += 1;
                s.skip_line();
            }
            b"vn" => {
                ignored.normals += 1;
                s.skip_line();
            }
            b"usemtl" | b"mtllib" => {
                ignored.materials += 1;
                s.skip_line();
            }
            b"s" | b"vp" => s.skip_line(),
            _ => {
                ignored.other += 1;
                s.skip_line();
            }
        }
    }
    let mut parts = Vec::new();
    if ignored.texture > 0 {
        parts.push(format!("{} texture coordinates", ignored.texture));
    }
    if ignored.normals > 0 {
        parts.push(format!(
            "{} normals (recomputed on writing)",
            ignored.normals
        ));
    }
    if ignored.materials > 0 {
        parts.push(format!("{} material statements", ignored.materials));
    }
    if ignored.other > 0 {
        parts.push(format!("{} statements of other kinds", ignored.other));
    }
    if !parts.is_empty() {
        b.warn(
            Code::InputNotCarried,
            format!(
                "OBJ data the mesh does not hold, not kept: {}",
                parts.join(", ")
            ),
        );
    }
    if ignored.polygons > 0 {
        b.warn(
            Code::ElementsConverted,
            format!(
                "{} polygons with more than 3 vertices split into triangles",
                ignored.polygons
            ),
        );
    }
    Ok(b)
}

fn short_line(s: &Scanner, what: &str) -> Diagnostic {
    let at = s.pos.min(s.bytes.len());
    error_at(
        Code::MeshCountMismatch,
        at.saturating_sub(1),
        at,
        format!("the line ends where {what} were expected"),
    )
}

/// The texture and normal indices of a corner (`7/2/3`) are not kept, but a
/// malformed or dangling one means the file is broken, so it is refused.
fn check_extra_indices(t: Token, textures: usize, normals: usize) -> Result<(), Diagnostic> {
    let mut parts = t.text.split(|&c| c == b'/').skip(1);
    for (count, what) in [(textures, "texture coordinate"), (normals, "normal")] {
        let Some(part) = parts.next().filter(|p| !p.is_empty()) else {
            continue;
        };
        let v = std::str::from_utf8(part)
            .ok()
            .and_then(|p| p.parse::<i64>().ok())
            .ok_or_else(|| syntax(t, &format!("a {what} index after `/`")))?;
        let resolved = if v > 0 { v - 1 } else { count as i64 + v };
        if v == 0 || resolved < 0 || resolved >= count as i64 {
            return Err(error_at(
                Code::MeshIndexOutOfRange,
                t.start,
                t.end(),
                format!(
                    "{what} index {v} is out of range: {count} {what}s are defined before this line"
                ),
            ));
        }
    }
    if parts.next().is_some() {
        return Err(syntax(t, "at most three `/`-separated indices"));
    }
    Ok(())
}

/// `7`, `7/2`, `7//3`, `7/2/3` or negative (relative to the end): the
/// position index, 0-based.
fn index(t: Token, n_nodes: usize) -> Result<u32, Diagnostic> {
    let first = t.text.split(|&c| c == b'/').next().unwrap_or(t.text);
    let head = Token {
        text: first,
        start: t.start,
    };
    let v =
        super::text::integer(head, "a vertex index").map_err(|_| syntax(t, "a vertex index"))?;
    let resolved = if v > 0 {
        v - 1
    } else if v < 0 {
        n_nodes as i64 + v
    } else {
        -1
    };
    if resolved < 0 || resolved >= n_nodes as i64 {
        return Err(error_at(
            Code::MeshIndexOutOfRange,
            t.start,
            t.start + first.len(),
            format!(
                "vertex index {v} is out of range: {n_nodes} vertices are defined before this line"
            ),
        )
        .with_help("OBJ indices start at 1 (negative ones count back from the last vertex)"));
    }
    Ok(resolved as u32)
}
