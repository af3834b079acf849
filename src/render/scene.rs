//! The drawable scene: the mesh's triangles with, for each face, what each of
//! its two sides shows (a coloured surface, a section cap, or nothing), the
//! colour groups the legend names, per-corner light intensities, and the
//! optional section cut.

use super::camera::{Camera, cross, dot};
use super::{ColorBy, RenderOptions, Section, Shading};
use crate::mesh::Mesh;
use rayon::prelude::*;

/// A side that is never seen (inside a closed subdomain, no section).
pub const HIDDEN: u32 = u32::MAX;

#[derive(Debug, Clone, PartialEq)]
pub struct Group {
    pub name: String,
    pub color: [u8; 3],
    /// A section cap: drawn hatched, named `section: <subdomain>` in the legend.
    pub cap: bool,
}

#[derive(Debug, Clone, Default)]
pub struct Scene {
    /// Model coordinates: the mesh's nodes, then nodes made by the section.
    pub points: Vec<[f64; 3]>,
    pub tris: Vec<[u32; 3]>,
    pub tri_face: Vec<u32>,
    /// Per face: the group shown on its front (normal) side and on its back.
    pub face_sides: Vec<[u32; 2]>,
    /// Per triangle corner: an index into `light`.
    pub corner_slots: Vec<[u32; 3]>,
    /// Light intensity in [0, 1] seen on the front and on the back side.
    pub light: Vec<[f32; 2]>,
    pub groups: Vec<Group>,
}

/// Colours of the groups, cycled with a change of brightness past the end.
const PALETTE: [[u8; 3]; 12] = [
    [70, 130, 200],
    [230, 140, 40],
    [80, 170, 90],
    [210, 70, 70],
    [150, 110, 200],
    [150, 100, 70],
    [220, 120, 190],
    [130, 130, 130],
    [190, 190, 60],
    [60, 190, 200],
    [250, 200, 60],
    [120, 80, 160],
];

pub fn group_color(i: usize) -> [u8; 3] {
    let base = PALETTE[i % PALETTE.len()];
    let factor = [1.0, 0.7, 1.2, 0.55][(i / PALETTE.len()) % 4];
    base.map(|c| (c as f64 * factor).round().clamp(0.0, 255.0) as u8)
}

/// What colouring applies: `Auto` is fragments when any fragment has faces
/// (3D), else subdomains, else one group per face.
fn effective_color_by(mesh: &Mesh, wanted: ColorBy) -> ColorBy {
    match wanted {
        ColorBy::Auto => {
            if mesh.fragments.iter().any(|f| !f.faces.is_empty()) {
                ColorBy::Fragment
            } else if !mesh.subdomains.is_empty() {
                ColorBy::Subdomain
            } else {
                ColorBy::Face
            }
        }
        other => other,
    }
}

pub fn build(mesh: &Mesh, options: &RenderOptions, camera: &Camera) -> Scene {
    let n_faces = mesh.faces.len();
    let color_by = effective_color_by(mesh, options.color_by);
    // The subdomain on each side: `outward` means the normal leaves it, so it
    // lies behind the front side.
    let mut behind: Vec<Option<u32>> = vec![None; n_faces];
    let mut in_front: Vec<Option<u32>> = vec![None; n_faces];
    for (s, sub) in mesh.subdomains.iter().enumerate() {
        for &(f, outward) in &sub.faces {
            let Some(slot) = (if outward {
                behind.get_mut(f as usize)
            } else {
                in_front.get_mut(f as usize)
            }) else {
                continue;
            };
            slot.get_or_insert(s as u32);
        }
    }
    let mut groups: Vec<Group> = Vec::new();
    let surface_group: Vec<[u32; 2]> = match color_by {
        ColorBy::Fragment => {
            let mut of_face = vec![HIDDEN; n_faces];
            for frag in &mesh.fragments {
                if frag.faces.is_empty() {
                    continue;
                }
                let g = groups.len() as u32;
                groups.push(Group {
                    name: frag.name.clone(),
                    color: group_color(g as usize),
                    cap: false,
                });
                for &f in &frag.faces {
                    if let Some(slot) = of_face.get_mut(f as usize) {
                        if *slot == HIDDEN {
                            *slot = g;
                        }
                    }
                }
            }
            for (f, slot) in of_face.iter_mut().enumerate() {
                if *slot == HIDDEN {
                    *slot = groups.len() as u32;
                    let g = groups.len();
                    groups.push(Group {
                        name: mesh.faces[f].name.clone(),
                        color: group_color(g),
                        cap: false,
                    });
                }
            }
            of_face.iter().map(|&g| [g, g]).collect()
        }
        ColorBy::Subdomain => {
            for (s, sub) in mesh.subdomains.iter().enumerate() {
                groups.push(Group {
                    name: sub.name.clone(),
                    color: group_color(s),
                    cap: false,
                });
            }
            let mut other = None;
            (0..n_faces)
                .map(|f| {
                    let mut pick = |first: Option<u32>, second: Option<u32>| {
                        first.or(second).unwrap_or_else(|| {
                            *other.get_or_insert_with(|| {
                                let g = groups.len();
                                groups.push(Group {
                                    name: "other faces".into(),
                                    color: group_color(g),
                                    cap: false,
                                });
                                g as u32
                            })
                        })
                    };
                    // Seen from the front, the colour of what lies behind.
                    [pick(behind[f], in_front[f]), pick(in_front[f], behind[f])]
                })
                .collect()
        }
        ColorBy::Face | ColorBy::Auto => {
            for (f, face) in mesh.faces.iter().enumerate() {
                groups.push(Group {
                    name: face.name.clone(),
                    color: group_color(f),
                    cap: false,
                });
            }
            (0..n_faces as u32).map(|f| [f, f]).collect()
        }
    };
    // Caps: one group per subdomain, added only when a section is asked for.
    let cap_base = groups.len() as u32;
    if options.section.is_some() {
        for (s, sub) in mesh.subdomains.iter().enumerate() {
            let c = group_color(s + 5);
            groups.push(Group {
                name: format!("section: {}", sub.name),
                color: c,
                cap: true,
            });
        }
    }
    let face_sides: Vec<[u32; 2]> = (0..n_faces)
        .map(|f| {
            // The front side is seen from the region in front of it.
            let side = |eye_region: Option<u32>, surface: u32| match eye_region {
                None => surface,
                Some(s) if options.section.is_some() => cap_base + s,
                Some(_) => HIDDEN,
            };
            [
                side(in_front[f], surface_group[f][0]),
                side(behind[f], surface_group[f][1]),
            ]
        })
        .collect();

    let mut scene = Scene {
        points: mesh.nodes.clone(),
        face_sides,
        groups,
        ..Scene::default()
    };
    let n_tris: usize = mesh.faces.iter().map(|f| f.triangles.len()).sum();
    scene.tris.reserve(n_tris);
    scene.tri_face.reserve(n_tris);
    for (f, face) in mesh.faces.iter().enumerate() {
        for t in &face.triangles {
            if t.iter().all(|&n| (n as usize) < mesh.nodes.len()) {
                scene.tris.push(*t);
                scene.tri_face.push(f as u32);
            }
        }
    }
    shade(&mut scene, mesh, options.shading, camera);
    if let Some(section) = options.section {
        cut(&mut scene, section);
    }
    scene
}

/// The light comes from the eye's side, a little from above and the left.
fn light_direction(camera: &Camera) -> [f64; 3] {
    let l: [f64; 3] =
        std::array::from_fn(|k| camera.toward_eye[k] + 0.45 * camera.up[k] - 0.3 * camera.right[k]);
    let n = dot(l, l).sqrt();
    l.map(|v| v / n)
}

fn intensity(normal: [f64; 3], light: [f64; 3]) -> [f32; 2] {
    let len = dot(normal, normal).sqrt();
    if len == 0.0 || !len.is_finite() {
        return [0.6, 0.6];
    }
    let c = dot(normal, light) / len;
    [
        (0.25 + 0.75 * c.max(0.0)) as f32,
        (0.25 + 0.75 * (-c).max(0.0)) as f32,
    ]
}

fn tri_normal(p: &[[f64; 3]], t: [u32; 3]) -> [f64; 3] {
    let (a, b, c) = (p[t[0] as usize], p[t[1] as usize], p[t[2] as usize]);
    cross(
        [b[0] - a[0], b[1] - a[1], b[2] - a[2]],
        [c[0] - a[0], c[1] - a[1], c[2] - a[2]],
    )
}

/// Light per corner: flat gives each triangle one slot; smooth averages the
/// area-weighted normals of a node within one face (creases between faces
/// stay sharp).
fn shade(scene: &mut Scene, mesh: &Mesh, shading: Shading, camera: &Camera) {
    let light = light_direction(camera);
    match shading {
        Shading::Flat => {
            scene.light = scene
                .tris
                .iter()
                .map(|&t| intensity(tri_normal(&scene.points, t), light))
                .collect();
            scene.corner_slots = (0..scene.tris.len() as u32).map(|i| [i, i, i]).collect();
        }
        Shading::Smooth => {
            // Normals computed where they are summed: a stored array of them
            // costs more in memory traffic than the cross products.
            let mut slot_of = vec![u32::MAX; mesh.nodes.len()];
            let mut sums: Vec<[f64; 3]> = Vec::new();
            scene.corner_slots = Vec::with_capacity(scene.tris.len());
            let mut start = 0;
            while start < scene.tris.len() {
                let face = scene.tri_face[start];
                let mut end = start;
                while end < scene.tris.len() && scene.tri_face[end] == face {
                    end += 1;
                }
                for &t in &scene.tris[start..end] {
                    let n = tri_normal(&scene.points, t);
                    let mut slots = [0u32; 3];
                    for (k, &node) in t.iter().enumerate() {
                        let s = &mut slot_of[node as usize];
                        if *s == u32::MAX {
                            *s = sums.len() as u32;
                            sums.push([0.0; 3]);
                        }
                        let sum = &mut sums[*s as usize];
                        sum[0] += n[0];
                        sum[1] += n[1];
                        sum[2] += n[2];
                        slots[k] = *s;
                    }
                    scene.corner_slots.push(slots);
                }
                for &t in &scene.tris[start..end] {
                    for node in t {
                        slot_of[node as usize] = u32::MAX;
                    }
                }
                start = end;
            }
            scene.light = sums.par_iter().map(|&n| intensity(n, light)).collect();
        }
    }
}

/// Removes the part of every triangle on the far side of the section plane
/// (coordinate > value), splitting the triangles it crosses.
fn cut(scene: &mut Scene, section: Section) {
    let axis = section.axis as usize;
    let value = section.value;
    let old_tris = std::mem::take(&mut scene.tris);
    let old_faces = std::mem::take(&mut scene.tri_face);
    let old_slots = std::mem::take(&mut scene.corner_slots);
    // Points made on a crossed edge, shared by the triangles on both sides of it.
    let mut made: std::collections::HashMap<(u32, u32), u32> = std::collections::HashMap::new();
    for ((t, f), s) in old_tris.into_iter().zip(old_faces).zip(old_slots) {
        let d = t.map(|n| scene.points[n as usize][axis] - value);
        let kept = d.iter().filter(|&&v| v <= 0.0).count();
        if kept == 3 {
            scene.tris.push(t);
            scene.tri_face.push(f);
            scene.corner_slots.push(s);
            continue;
        }
        if kept == 0 {
            continue;
        }
        // Sutherland–Hodgman against one plane: at most a quadrilateral.
        let mut poly: Vec<(u32, u32)> = Vec::with_capacity(4);
        for k in 0..3 {
            let (a, b) = (k, (k + 1) % 3);
            if d[a] <= 0.0 {
                poly.push((t[a], s[a]));
            }
            if (d[a] <= 0.0) != (d[b] <= 0.0) {
                // Computed from the edge's lower node, so both sides agree.
                let (lo, hi) = if t[a] < t[b] { (a, b) } else { (b, a) };
                let u = d[lo] / (d[lo] - d[hi]);
                let points = &mut scene.points;
                let node = *made.entry((t[lo], t[hi])).or_insert_with(|| {
                    let (pa, pb) = (points[t[lo] as usize], points[t[hi] as usize]);
                    let mut p = [0.0; 3];
                    for c in 0..3 {
                        p[c] = pa[c] + u * (pb[c] - pa[c]);
                    }
                    p[axis] = value;
                    points.push(p);
                    (points.len() - 1) as u32
                });
                let (la, lb) = (scene.light[s[lo] as usize], scene.light[s[hi] as usize]);
                let uf = u as f32;
                scene
                    .light
                    .push([la[0] + uf * (lb[0] - la[0]), la[1] + uf * (lb[1] - la[1])]);
                poly.push((node, (scene.light.len() - 1) as u32));
            }
        }
        for k in 1..poly.len().saturating_sub(1) {
            scene.tris.push([poly[0].0, poly[k].0, poly[k + 1].0]);
            scene
                .corner_slots
                .push([poly[0].1, poly[k].1, poly[k + 1].1]);
            scene.tri_face.push(f);
        }
    }
}
