//! The vector drawing: feature and silhouette edges (or every triangle edge)
//! with hidden parts removed exactly. Each segment is tested against the
//! triangles whose screen boxes it crosses (a uniform grid finds them): a
//! triangle hides the part of the segment strictly inside its projection and
//! strictly in front of it, an interval of the segment's parameter since both
//! conditions are linear along it. What no triangle hides is drawn, in the
//! colour of the fragment (or subdomain) the edge belongs to.

use super::camera::{Camera, cross, dot};
use super::scene::{HIDDEN, Scene};
use super::section_fill::{CutFace, cut_faces};
use super::{Edges, RenderError, RenderOptions, RenderWarning, check, scene};
use crate::mesh::Mesh;
use rayon::prelude::*;
use std::collections::HashMap;
use std::fmt::Write as _;

/// Edges sharper than this (between triangle normals) are feature edges of a
/// mesh that names no model edges.
const SHARP_DEGREES: f64 = 30.0;

/// The segments to draw, as scene point pairs with the colour group of each.
pub fn edge_segments(
    mesh: &Mesh,
    scene: &Scene,
    camera: &Camera,
    mode: Edges,
) -> Vec<(u32, u32, u32)> {
    // Adjacency: every undirected triangle edge and the triangles using it.
    let mut adjacent: HashMap<(u32, u32), Vec<u32>> = HashMap::new();
    for (i, t) in scene.tris.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            adjacent
                .entry((a.min(b), a.max(b)))
                .or_default()
                .push(i as u32);
        }
    }
    let facing = |tri: u32| -> usize {
        let t = scene.tris[tri as usize];
        let n = cross(
            sub(scene.points[t[1] as usize], scene.points[t[0] as usize]),
            sub(scene.points[t[2] as usize], scene.points[t[0] as usize]),
        );
        usize::from(dot(n, camera.toward_eye) < 0.0)
    };
    let group_of = |tris: &[u32]| -> u32 {
        // The colour seen on the first triangle showing a side.
        tris.iter()
            .map(|&t| scene.side_group(t as usize, facing(t)))
            .find(|&g| g != HIDDEN)
            .unwrap_or(HIDDEN)
    };
    let mut keys: Vec<(u32, u32)> = Vec::new();
    match mode {
        Edges::All => keys.extend(adjacent.keys().copied()),
        Edges::None | Edges::Feature => {
            for edge in &mesh.edges {
                for w in edge.nodes.windows(2) {
                    let key = (w[0].min(w[1]), w[0].max(w[1]));
                    if adjacent.contains_key(&key) {
                        keys.push(key);
                    }
                }
            }
            let sharp_cos = SHARP_DEGREES.to_radians().cos();
            for (key, tris) in &adjacent {
                let silhouette = match tris.as_slice() {
                    [_] => true,
                    [a, b] => {
                        let (na, nb) = (normal(scene, *a), normal(scene, *b));
                        let sharp = mesh.edges.is_empty()
                            && dot(na, nb) < sharp_cos * (dot(na, na) * dot(nb, nb)).sqrt();
                        sharp || facing(*a) != facing(*b)
                    }
                    _ => true,
                };
                if silhouette {
                    keys.push(*key);
                }
            }
        }
    }
    keys.sort_unstable();
    keys.dedup();
    keys.into_iter()
        .filter_map(|k| {
            let g = group_of(&adjacent[&k]);
            (g != HIDDEN).then_some((k.0, k.1, g))
        })
        .collect()
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn normal(scene: &Scene, tri: u32) -> [f64; 3] {
    let t = scene.tris[tri as usize];
    cross(
        sub(scene.points[t[1] as usize], scene.points[t[0] as usize]),
        sub(scene.points[t[2] as usize], scene.points[t[0] as usize]),
    )
}

/// Screen boxes of triangles bucketed in a uniform grid (compressed rows).
struct Grid {
    cells_x: usize,
    cells_y: usize,
    cell_w: f64,
    cell_h: f64,
    start: Vec<u32>,
    items: Vec<u32>,
}

impl Grid {
    fn cell_range(&self, lo: [f64; 2], hi: [f64; 2]) -> (usize, usize, usize, usize) {
        let cx = |x: f64| ((x / self.cell_w).floor().max(0.0) as usize).min(self.cells_x - 1);
        let cy = |y: f64| ((y / self.cell_h).floor().max(0.0) as usize).min(self.cells_y - 1);
        (cx(lo[0]), cx(hi[0]), cy(lo[1]), cy(hi[1]))
    }

    fn build(p: &[[f64; 3]], tris: &[[u32; 3]], width: f64, height: f64) -> Grid {
        let side = ((tris.len() as f64).sqrt() / 2.0).clamp(1.0, 256.0) as usize;
        let mut grid = Grid {
            cells_x: side,
            cells_y: side,
            cell_w: width / side as f64,
            cell_h: height / side as f64,
            start: vec![0; side * side + 1],
            items: Vec::new(),
        };
        let ranges: Vec<(usize, usize, usize, usize)> = tris
            .iter()
            .map(|t| {
                let (lo, hi) = bbox(p, t);
                grid.cell_range(lo, hi)
            })
            .collect();
        for &(x0, x1, y0, y1) in &ranges {
            for y in y0..=y1 {
                for x in x0..=x1 {
                    grid.start[y * side + x + 1] += 1;
                }
            }
        }
        for i in 0..side * side {
            grid.start[i + 1] += grid.start[i];
        }
        let mut fill = grid.start.clone();
        grid.items = vec![0; grid.start[side * side] as usize];
        for (i, &(x0, x1, y0, y1)) in ranges.iter().enumerate() {
            for y in y0..=y1 {
                for x in x0..=x1 {
                    let c = y * side + x;
                    grid.items[fill[c] as usize] = i as u32;
                    fill[c] += 1;
                }
            }
        }
        grid
    }
}

fn bbox(p: &[[f64; 3]], t: &[u32; 3]) -> ([f64; 2], [f64; 2]) {
    let (a, b, c) = (p[t[0] as usize], p[t[1] as usize], p[t[2] as usize]);
    (
        [a[0].min(b[0]).min(c[0]), a[1].min(b[1]).min(c[1])],
        [a[0].max(b[0]).max(c[0]), a[1].max(b[1]).max(c[1])],
    )
}

/// The parameter interval of segment `a`→`b` (screen x, y, depth) that
/// triangle `t` hides, if any.
fn hidden_interval(
    a: [f64; 3],
    b: [f64; 3],
    t: [[f64; 3]; 3],
    depth_eps: f64,
) -> Option<(f64, f64)> {
    let area =
        (t[1][0] - t[0][0]) * (t[2][1] - t[0][1]) - (t[1][1] - t[0][1]) * (t[2][0] - t[0][0]);
    if area.abs() < 1e-12 {
        return None;
    }
    let (mut lo, mut hi) = (0.0f64, 1.0f64);
    // Keep t where f(0) + t (f(1) − f(0)) > eps.
    let mut clip = |f0: f64, f1: f64, eps: f64| {
        let d = f1 - f0;
        if d.abs() < 1e-300 {
            if f0 <= eps {
                hi = -1.0;
            }
        } else {
            let t0 = (eps - f0) / d;
            if d > 0.0 {
                lo = lo.max(t0)
            } else {
                hi = hi.min(t0)
            }
        }
    };
    let sign = area.signum();
    for k in 0..3 {
        let (p, q) = (t[k], t[(k + 1) % 3]);
        let len = ((q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2)).sqrt();
        // Signed distance in pixels from the edge's line, positive inside.
        let e = |s: [f64; 3]| {
            sign * ((q[0] - p[0]) * (s[1] - p[1]) - (q[1] - p[1]) * (s[0] - p[0])) / len
        };
        clip(e(a), e(b), 1e-6);
    }
    // The triangle's depth plane at the segment's points, against the segment's depth.
    let w = |s: [f64; 3]| {
        let w1 = ((s[0] - t[0][0]) * (t[2][1] - t[0][1]) - (s[1] - t[0][1]) * (t[2][0] - t[0][0]))
            / area;
        let w2 = ((t[1][0] - t[0][0]) * (s[1] - t[0][1]) - (t[1][1] - t[0][1]) * (s[0] - t[0][0]))
            / area;
        s[2] - (t[0][2] + w1 * (t[1][2] - t[0][2]) + w2 * (t[2][2] - t[0][2]))
    };
    clip(w(a), w(b), depth_eps);
    (hi - lo > 1e-9).then_some((lo, hi))
}

/// A visible part of a segment: its colour group and screen end points.
type Piece = (u32, [f64; 2], [f64; 2]);

/// The SVG text and what it holds.
#[derive(Debug, Clone)]
pub struct SvgDrawing {
    pub text: String,
    /// Visible pieces drawn (one `M … L …` each).
    pub segments: usize,
    /// `--section`: the cut face of each subdomain, filled under the lines.
    pub cut_faces: Vec<CutFace>,
    pub warnings: Vec<RenderWarning>,
}

pub fn render_svg(mesh: &Mesh, options: &RenderOptions) -> Result<SvgDrawing, RenderError> {
    let mut options = options.clone();
    options.antialias = 1;
    check(mesh, &options)?;
    let camera = super::camera_for(mesh, &options);
    let scene = scene::build(mesh, &options, &camera);
    let warnings: Vec<RenderWarning> = super::section_warning(&scene, &options)
        .into_iter()
        .collect();
    let p: Vec<[f64; 3]> = scene
        .points
        .par_iter()
        .map(|&q| camera.project(q))
        .collect();
    let (zlo, zhi) = p
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), q| {
            (l.min(q[2]), h.max(q[2]))
        });
    let depth_eps = 1e-7 * (zhi - zlo).max(1e-300) + 1e-12;
    let (w, h) = (options.width as f64, options.height as f64);
    let grid = Grid::build(&p, &scene.tris, w, h);
    let segments = edge_segments(
        mesh,
        &scene,
        &camera,
        if options.edges == Edges::None {
            Edges::Feature
        } else {
            options.edges
        },
    );
    let pieces: Vec<Vec<Piece>> = segments
        .par_iter()
        .map_init(
            || vec![false; scene.tris.len()],
            |stamp, &(na, nb, group)| {
                let (a, b) = (p[na as usize], p[nb as usize]);
                let lo = [a[0].min(b[0]), a[1].min(b[1])];
                let hi = [a[0].max(b[0]), a[1].max(b[1])];
                let (x0, x1, y0, y1) = grid.cell_range(lo, hi);
                let mut hidden: Vec<(f64, f64)> = Vec::new();
                for cy in y0..=y1 {
                    for cx in x0..=x1 {
                        let c = cy * grid.cells_x + cx;
                        for &tri in &grid.items[grid.start[c] as usize..grid.start[c + 1] as usize]
                        {
                            if stamp[tri as usize] {
                                continue;
                            }
                            stamp[tri as usize] = true;
                            let t = scene.tris[tri as usize];
                            if t.contains(&na) && t.contains(&nb) {
                                continue;
                            }
                            let (tlo, thi) = bbox(&p, &t);
                            if thi[0] < lo[0] || tlo[0] > hi[0] || thi[1] < lo[1] || tlo[1] > hi[1]
                            {
                                continue;
                            }
                            if let Some(iv) =
                                hidden_interval(a, b, t.map(|n| p[n as usize]), depth_eps)
                            {
                                hidden.push(iv);
                            }
                        }
                    }
                }
                // Reset the stamps this segment set, so the next one starts clean.
                for cy in y0..=y1 {
                    for cx in x0..=x1 {
                        let c = cy * grid.cells_x + cx;
                        for &tri in &grid.items[grid.start[c] as usize..grid.start[c + 1] as usize]
                        {
                            stamp[tri as usize] = false;
                        }
                    }
                }
                hidden.sort_by(|x, y| x.0.total_cmp(&y.0));
                let mut visible = Vec::new();
                let mut t = 0.0;
                let length = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
                let mut emit = |t0: f64, t1: f64| {
                    if (t1 - t0) * length > 0.05 {
                        let at = |u: f64| [a[0] + u * (b[0] - a[0]), a[1] + u * (b[1] - a[1])];
                        visible.push((group, at(t0), at(t1)));
                    }
                };
                for (h0, h1) in hidden {
                    if h0 > t {
                        emit(t, h0);
                    }
                    t = t.max(h1);
                }
                if t < 1.0 {
                    emit(t, 1.0);
                }
                visible
            },
        )
        .collect();
    let mut by_group: Vec<String> = vec![String::new(); scene.groups.len()];
    let mut count = 0;
    // Pieces that coincide on paper (a back edge right behind a front one
    // seen straight on) are drawn once.
    let mut seen = std::collections::HashSet::new();
    for (g, a, b) in pieces.iter().flatten() {
        let (pa, pb) = (
            format!("{} {}", num(a[0]), num(a[1])),
            format!("{} {}", num(b[0]), num(b[1])),
        );
        if !seen.insert(if pa <= pb {
            (pa.clone(), pb.clone())
        } else {
            (pb.clone(), pa.clone())
        }) {
            continue;
        }
        let d = &mut by_group[*g as usize];
        let _ = write!(d, "M{pa}L{pb}");
        count += 1;
    }
    let mut out = String::new();
    let _ = writeln!(out, r#"<?xml version="1.0" encoding="UTF-8"?>"#);
    let _ = writeln!(
        out,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{}" height="{}" viewBox="0 0 {} {}">"#,
        options.width, options.height, options.width, options.height
    );
    let bg = options.background;
    if bg[3] > 0 {
        let _ = writeln!(
            out,
            r##"<rect width="100%" height="100%" fill="#{:02x}{:02x}{:02x}" fill-opacity="{}"/>"##,
            bg[0],
            bg[1],
            bg[2],
            num(bg[3] as f64 / 255.0)
        );
    }
    let cut_faces = options
        .section
        .map(|section| cut_faces(mesh, section, &camera))
        .unwrap_or_default();
    write_cut_faces(&mut out, &cut_faces, &scene);
    let _ = writeln!(
        out,
        r#"<g fill="none" stroke-width="1.5" stroke-linecap="round">"#
    );
    for (g, d) in by_group.iter().enumerate() {
        if !d.is_empty() {
            let c = scene.groups[g].color;
            let _ = writeln!(
                out,
                r##"<path stroke="#{:02x}{:02x}{:02x}" d="{d}"/>"##,
                c[0], c[1], c[2]
            );
        }
    }
    let _ = writeln!(out, "</g>");
    if options.legend {
        let _ = writeln!(out, r#"<g font-family="monospace" font-size="12">"#);
        for (i, g) in scene.groups.iter().enumerate() {
            let y = 8 + 16 * i;
            let c = g.color;
            let _ = writeln!(
                out,
                r##"<rect x="8" y="{y}" width="12" height="12" fill="#{:02x}{:02x}{:02x}"/><text x="26" y="{}">{}</text>"##,
                c[0],
                c[1],
                c[2],
                y + 10,
                escape(&g.name)
            );
        }
        let _ = writeln!(out, "</g>");
    }
    let _ = writeln!(out, "</svg>");
    Ok(SvgDrawing {
        text: out,
        segments: count,
        cut_faces,
        warnings,
    })
}

/// One even–odd path per subdomain's cut face, in its section colour.
fn write_cut_faces(out: &mut String, faces: &[CutFace], scene: &Scene) {
    if faces.is_empty() {
        return;
    }
    // The cap groups follow the surface groups, one per subdomain in order.
    let caps: Vec<[u8; 3]> = scene
        .groups
        .iter()
        .filter(|g| g.cap)
        .map(|g| g.color)
        .collect();
    let _ = writeln!(out, r#"<g fill-rule="evenodd" stroke="none">"#);
    for face in faces {
        let c = caps.get(face.subdomain).copied().unwrap_or([160, 160, 160]);
        let mut d = String::new();
        for lp in &face.loops {
            for (i, p) in lp.iter().enumerate() {
                let _ = write!(
                    d,
                    "{}{} {}",
                    if i == 0 { 'M' } else { 'L' },
                    num(p[0]),
                    num(p[1])
                );
            }
            d.push('Z');
        }
        let _ = writeln!(
            out,
            r##"<path class="section" fill="#{:02x}{:02x}{:02x}" d="{d}"/>"##,
            c[0], c[1], c[2]
        );
    }
    let _ = writeln!(out, "</g>");
}

fn num(v: f64) -> String {
    let r = (v * 100.0).round() / 100.0;
    if r == 0.0 { "0".into() } else { format!("{r}") }
}

fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}
