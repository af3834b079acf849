//! Wavefront OBJ: every mesh node once as `v`, then one object (`o`) per
//! surface group (fragment in 3D, region in 2D, else face) with a `g` per face
//! inside it, triangles as `f v//vn` with normals smooth within a face; line
//! groups (2D fragments, edges, poly_lines) as `o` + `l`; point sets as `o` +
//! `p`. OBJ has no volumes: 3D subdomains are carried only by the fragment
//! names, which a warning says.

use super::groups::{self, Source};
use super::{MeshWriter, Warning, WriteError, WriteOptions, count, push_num, warning};
use crate::mesh::Mesh;
use std::fmt::Write as _;
use std::io::Write;

pub(crate) struct Obj;

impl MeshWriter for Obj {
    fn name(&self) -> &'static str {
        "obj"
    }

    fn extensions(&self) -> &'static [&'static str] {
        &["obj"]
    }

    fn write(
        &self,
        mesh: &Mesh,
        options: &WriteOptions,
        out: &mut dyn Write,
    ) -> Result<Vec<Warning>, WriteError> {
        groups::check(mesh)?;
        let mut warnings: Vec<Warning> = groups::dropped_volumes("obj", mesh).into_iter().collect();
        if options.encoding.is_some() {
            warnings.push(warning(
                "obj",
                "OBJ is text only: the encoding option is ignored",
            ));
        }
        if mesh.dimension == 3 && !mesh.subdomains.is_empty() {
            warnings.push(warning(
                "obj",
                format!(
                    "OBJ has no volumes: {} carried only as the sides of the fragment objects",
                    count(mesh.subdomains.len(), "subdomain")
                ),
            ));
        }

        // Text gathered in large pieces, numbers formatted in place.
        let mut text = String::with_capacity(PIECE + 512);
        let _ = writeln!(text, "# geomc mesh: {} nodes", mesh.nodes.len());
        for p in &mesh.nodes {
            vector(&mut text, "v ", *p);
            spill(&mut text, out)?;
        }

        // Normals are numbered across the whole file, in the order written.
        let mut next_normal = 1usize;
        let mut expander = groups::Expander::new(mesh);
        for g in groups::surface_groups(mesh) {
            let _ = writeln!(text, "o {}", obj_name(g.name));
            for &(face, flip) in &g.faces {
                let ex = expander.expand(&[(face, flip)]);
                if ex.triangles.is_empty() {
                    continue;
                }
                if !matches!(g.source, Source::Face(_)) {
                    let _ = writeln!(text, "g {}", obj_name(&mesh.faces[face as usize].name));
                }
                for n in &ex.normals {
                    vector(&mut text, "vn ", *n);
                    spill(&mut text, out)?;
                }
                for t in ex.triangles.iter() {
                    text.push('f');
                    for &local in t {
                        let local = local as usize;
                        let _ = write!(text, " {}//{}", ex.node(local) + 1, next_normal + local);
                    }
                    text.push('\n');
                    spill(&mut text, out)?;
                }
                next_normal += ex.normals.len();
            }
        }
        out.write_all(text.as_bytes())?;
        for g in groups::line_groups(mesh) {
            if g.segments.is_empty() {
                continue;
            }
            writeln!(out, "o {}", obj_name(g.name))?;
            // One `l` per polyline run: consecutive segments that share a node.
            let mut run: Vec<u32> = Vec::new();
            for [a, b] in g.segments {
                if run.last() != Some(&a) {
                    flush_line(out, &run)?;
                    run = vec![a];
                }
                run.push(b);
            }
            flush_line(out, &run)?;
        }
        for p in &mesh.point_sets {
            if p.nodes.is_empty() {
                continue;
            }
            writeln!(out, "o {}", obj_name(&p.name))?;
            let list: Vec<String> = p.nodes.iter().map(|n| (n + 1).to_string()).collect();
            writeln!(out, "p {}", list.join(" "))?;
        }
        Ok(warnings)
    }
}

const PIECE: usize = 1 << 16;

/// Hands the gathered text to `out` once it is a large piece.
fn spill(text: &mut String, out: &mut dyn Write) -> Result<(), WriteError> {
    if text.len() >= PIECE {
        out.write_all(text.as_bytes())?;
        text.clear();
    }
    Ok(())
}

/// `PREFIX x y z` and a newline.
fn vector(text: &mut String, prefix: &str, v: [f64; 3]) {
    text.push_str(prefix);
    for (k, c) in v.into_iter().enumerate() {
        if k > 0 {
            text.push(' ');
        }
        push_num(text, c);
    }
    text.push('\n');
}

fn flush_line(out: &mut dyn Write, run: &[u32]) -> Result<(), WriteError> {
    if run.len() >= 2 {
        let list: Vec<String> = run.iter().map(|n| (n + 1).to_string()).collect();
        writeln!(out, "l {}", list.join(" "))?;
    }
    Ok(())
}

/// OBJ names end at whitespace: it becomes `_`.
fn obj_name(name: &str) -> String {
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
