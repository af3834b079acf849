//! STL: triangles only. Binary (the default) is one unnamed triangle list, so
//! several groups are merged with a warning; ASCII writes one `solid NAME`
//! per group (fragment, region or face, see [`super::groups::surface_groups`]).
//! Edges, poly_lines and point sets cannot be carried and are reported.

use super::groups::{self, SurfaceGroup};
use super::{Encoding, MeshWriter, Warning, WriteError, WriteOptions, count, push_num32, warning};
use crate::mesh::Mesh;
use rayon::prelude::*;
use std::io::Write;

pub(crate) struct Stl;

impl MeshWriter for Stl {
    fn name(&self) -> &'static str {
        "stl"
    }

    fn extensions(&self) -> &'static [&'static str] {
        &["stl"]
    }

    fn write(
        &self,
        mesh: &Mesh,
        options: &WriteOptions,
        out: &mut dyn Write,
    ) -> Result<Vec<Warning>, WriteError> {
        groups::check(mesh)?;
        let groups: Vec<SurfaceGroup> = groups::surface_groups(mesh)
            .into_iter()
            .filter(|g| {
                g.faces
                    .iter()
                    .any(|&(f, _)| !mesh.faces[f as usize].triangles.is_empty())
            })
            .collect();
        let mut warnings = dropped(mesh);
        warnings.extend(groups::dropped_volumes("stl", mesh));
        match options.encoding.unwrap_or(Encoding::Binary) {
            Encoding::Binary => {
                if groups.len() > 1 {
                    warnings.push(warning(
                        "stl",
                        format!(
                            "binary STL has no groups: {} merged (write ASCII STL to keep them)",
                            group_count(&groups)
                        ),
                    ));
                }
                write_binary(mesh, &groups, out)?;
            }
            Encoding::Ascii => write_ascii(mesh, &groups, out)?,
        }
        Ok(warnings)
    }
}

/// "4 fragments", or "3 faces, 1 fragment" when kinds mix.
fn group_count(groups: &[SurfaceGroup]) -> String {
    let (mut fragments, mut regions, mut faces) = (0, 0, 0);
    for g in groups {
        match g.source {
            groups::Source::Fragment(_) => fragments += 1,
            groups::Source::Subdomain(_) => regions += 1,
            _ => faces += 1,
        }
    }
    let parts: Vec<String> = [
        (fragments, "fragment"),
        (regions, "region"),
        (faces, "face"),
    ]
    .into_iter()
    .filter(|(n, _)| *n > 0)
    .map(|(n, what)| count(n, what))
    .collect();
    parts.join(", ")
}

/// What STL cannot hold at all.
fn dropped(mesh: &Mesh) -> Vec<Warning> {
    let mut parts = Vec::new();
    if mesh.dimension == 2 && !mesh.fragments.is_empty() {
        parts.push(format!(
            "{} (edges)",
            count(mesh.fragments.len(), "fragment")
        ));
    }
    if !mesh.polylines.is_empty() {
        parts.push(count(mesh.polylines.len(), "poly_line"));
    }
    if !mesh.point_sets.is_empty() {
        parts.push(count(mesh.point_sets.len(), "point set"));
    }
    if parts.is_empty() {
        Vec::new()
    } else {
        vec![warning(
            "stl",
            format!("STL holds only triangles: {} not written", parts.join(", ")),
        )]
    }
}

fn facets<'a>(
    mesh: &'a Mesh,
    group: &'a SurfaceGroup,
) -> impl Iterator<Item = ([f32; 3], [[f32; 3]; 3])> + 'a {
    group
        .faces
        .iter()
        .flat_map(move |&(f, flip)| groups::oriented(mesh, f, flip))
        .map(move |tri| {
            let n = groups::unit(groups::triangle_normal(mesh, tri)).unwrap_or([0.0; 3]);
            let p = tri.map(|v| mesh.nodes[v as usize].map(|c| c as f32));
            (n.map(|c| c as f32), p)
        })
}

fn write_binary(
    mesh: &Mesh,
    groups: &[SurfaceGroup],
    out: &mut dyn Write,
) -> Result<(), WriteError> {
    let n: usize = groups
        .iter()
        .flat_map(|g| &g.faces)
        .map(|&(f, _)| mesh.faces[f as usize].triangles.len())
        .sum();
    let n = u32::try_from(n).map_err(|_| {
        WriteError::Unsupported(format!(
            "binary STL holds at most 2^32-1 triangles, not {n}"
        ))
    })?;
    // The header must not start with "solid": readers would take the file for ASCII.
    let mut header = [b' '; 80];
    let text = b"geomc binary STL";
    header[..text.len()].copy_from_slice(text);
    out.write_all(&header)?;
    out.write_all(&n.to_le_bytes())?;
    // Records are built in pieces of a face's triangles, a window of pieces
    // at a time in parallel, and written in order: the bytes do not depend
    // on the thread count, and memory holds one window, not the file.
    const PIECE: usize = 1 << 13;
    const WINDOW: usize = 32;
    let pieces: Vec<(u32, bool, usize)> = groups
        .iter()
        .flat_map(|g| &g.faces)
        .flat_map(|&(f, flip)| {
            let len = mesh.faces[f as usize].triangles.len();
            (0..len).step_by(PIECE).map(move |start| (f, flip, start))
        })
        .collect();
    for window in pieces.chunks(WINDOW) {
        let bytes: Vec<Vec<u8>> = window
            .par_iter()
            .map(|&(f, flip, start)| {
                let triangles = &mesh.faces[f as usize].triangles;
                let end = (start + PIECE).min(triangles.len());
                let mut bytes = Vec::with_capacity(50 * (end - start));
                for &[a, b, c] in &triangles[start..end] {
                    let tri = if flip { [a, c, b] } else { [a, b, c] };
                    bytes.extend_from_slice(&record(mesh, tri));
                }
                bytes
            })
            .collect();
        for piece in bytes {
            out.write_all(&piece)?;
        }
    }
    Ok(())
}

/// One 50-byte binary record: unit normal, corners (f32), no attributes.
fn record(mesh: &Mesh, tri: [u32; 3]) -> [u8; 50] {
    let n = groups::unit(groups::triangle_normal(mesh, tri)).unwrap_or([0.0; 3]);
    let mut record = [0u8; 50];
    let values = n
        .into_iter()
        .chain(tri.into_iter().flat_map(|v| mesh.nodes[v as usize]));
    for (k, c) in values.enumerate() {
        record[4 * k..4 * k + 4].copy_from_slice(&(c as f32).to_le_bytes());
    }
    record
}

/// STL names are one word: whitespace becomes `_`.
fn solid_name(name: &str) -> String {
    let s: String = name
        .chars()
        .map(|c| if c.is_whitespace() { '_' } else { c })
        .collect();
    if s.is_empty() {
        "unnamed".to_string()
    } else {
        s
    }
}

fn write_ascii(
    mesh: &Mesh,
    groups: &[SurfaceGroup],
    out: &mut dyn Write,
) -> Result<(), WriteError> {
    // Text gathered in large pieces, numbers formatted in place.
    const PIECE: usize = 1 << 16;
    let mut text = String::with_capacity(PIECE + 512);
    let vector = |text: &mut String, prefix: &str, v: [f32; 3]| {
        text.push_str(prefix);
        for (k, c) in v.into_iter().enumerate() {
            if k > 0 {
                text.push(' ');
            }
            push_num32(text, c);
        }
        text.push('\n');
    };
    for g in groups {
        let name = solid_name(g.name);
        text.push_str(&format!("solid {name}\n"));
        for (n, points) in facets(mesh, g) {
            vector(&mut text, "  facet normal ", n);
            text.push_str("    outer loop\n");
            for p in points {
                vector(&mut text, "      vertex ", p);
            }
            text.push_str("    endloop\n  endfacet\n");
            if text.len() >= PIECE {
                out.write_all(text.as_bytes())?;
                text.clear();
            }
        }
        text.push_str(&format!("endsolid {name}\n"));
    }
    out.write_all(text.as_bytes())?;
    Ok(())
}
