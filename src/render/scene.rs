//! The drawable scene: the mesh's triangles with, for each face, what each of
//! its two sides shows (a coloured surface, a section cap, or nothing), the
//! colour groups the legend names, per-corner light intensities, and the
//! optional section cut.

use super::camera::{Camera, dot};
use super::light::{intensities, intensity};
use super::smooth::{self, tri_normal};
use super::{ColorBy, RenderOptions, Section, Shading};
use crate::mesh::Mesh;
use rayon::prelude::*;
use std::borrow::Cow;

/// A side that is never seen (inside a closed subdomain, no section).
pub const HIDDEN: u32 = u32::MAX;

#[derive(Debug, Clone, PartialEq)]
pub struct Group {
    pub name: String,
    pub color: [u8; 3],
    /// A section cap: drawn hatched, named `section: <subdomain>` in the legend.
    pub cap: bool,
}

/// Borrows the mesh's nodes and triangles when it can: a large mesh is not copied.
#[derive(Debug, Clone, Default)]
pub struct Scene<'a> {
    /// Model coordinates: the mesh's nodes, then nodes made by the section.
    pub points: Cow<'a, [[f64; 3]]>,
    pub tris: Cow<'a, [[u32; 3]]>,
    /// Each triangle's face; empty when every triangle lies on `one_face`
    /// (a large one-face mesh then has no per-triangle array to fill).
    pub tri_face: Vec<u32>,
    pub one_face: Option<u32>,
    /// Per face: the group shown on its front (normal) side and on its back.
    pub face_sides: Vec<[u32; 2]>,
    /// The pair every face shares, when they all show the same groups (one
    /// face, or faces of one colour): the side lookups then skip `tri_face`.
    pub same_sides: Option<[u32; 2]>,
    /// Per triangle corner: an index into `light`.
    /// (The triangles themselves when smooth shading one face: a node's own slot.)
    pub corner_slots: Cow<'a, [[u32; 3]]>,
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

impl Scene<'_> {
    /// The group shown on triangle `tri`'s front (`back` 0) or back side, or [`HIDDEN`].
    #[inline]
    pub fn side_group(&self, tri: usize, back: usize) -> u32 {
        match self.same_sides {
            Some(sides) => sides[back],
            None => self.face_sides[self.face_of(tri) as usize][back],
        }
    }

    /// The light per node when every node is its own light slot (smooth
    /// shading of one face, no section): the corner slots are the
    /// triangles themselves.
    pub fn node_light(&self) -> Option<&[[f32; 2]]> {
        (std::ptr::eq(self.corner_slots.as_ptr(), self.tris.as_ptr())
            && self.corner_slots.len() == self.tris.len()
            && self.light.len() == self.points.len())
        .then_some(&self.light[..])
    }

    /// The face triangle `tri` lies on.
    #[inline]
    pub fn face_of(&self, tri: usize) -> u32 {
        match self.one_face {
            Some(f) => f,
            None => self.tri_face[tri],
        }
    }
}

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

pub fn build<'a>(mesh: &'a Mesh, options: &RenderOptions, camera: &Camera) -> Scene<'a> {
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
                    if let Some(slot) = of_face.get_mut(f as usize)
                        && *slot == HIDDEN
                    {
                        *slot = g;
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

    let same_sides = face_sides
        .first()
        .copied()
        .filter(|first| face_sides.iter().all(|s| s == first));
    let (tris, tri_face, one_face, spans) = triangles(mesh);
    let mut scene = Scene {
        same_sides,
        points: Cow::Borrowed(&mesh.nodes),
        tris,
        tri_face,
        one_face,
        face_sides,
        groups,
        ..Scene::default()
    };
    shade(&mut scene, options.shading, camera, spans.as_ref());
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

/// The triangles and, per chunk of them, the span of nodes they name.
type Borrowed<'a> = (
    Cow<'a, [[u32; 3]]>,
    Vec<u32>,
    Option<u32>,
    Option<smooth::NodeSpans<'a>>,
);

/// The mesh's triangles grouped by face in face order, with their face; those
/// naming a node the mesh lacks are left out. Borrowed, with no per-triangle
/// face array, when one face holds them all; the node spans that check made
/// are kept for the smooth-shading sums (one pass over the triangles, not two).
fn triangles(mesh: &Mesh) -> Borrowed<'_> {
    let n = mesh.nodes.len();
    let valid = |t: &[u32; 3]| t.iter().all(|&i| (i as usize) < n);
    let mut filled = (mesh.faces.iter().enumerate()).filter(|(_, f)| !f.triangles.is_empty());
    if let (Some((f, face)), None) = (filled.next(), filled.next()) {
        let spans = smooth::node_spans(&face.triangles);
        if spans.all_below(&face.triangles, n) {
            return (
                Cow::Borrowed(&face.triangles),
                Vec::new(),
                Some(f as u32),
                Some(spans),
            );
        }
    }
    let total: usize = mesh.faces.iter().map(|f| f.triangles.len()).sum();
    let mut tris = Vec::with_capacity(total);
    let mut tri_face = Vec::with_capacity(total);
    for (f, face) in mesh.faces.iter().enumerate() {
        for t in face.triangles.iter().filter(|t| valid(t)) {
            tris.push(*t);
            tri_face.push(f as u32);
        }
    }
    (Cow::Owned(tris), tri_face, None, None)
}

/// Light per corner: flat gives each triangle one slot; smooth averages the
/// area-weighted normals of a node within one face (creases between faces
/// stay sharp).
fn shade(scene: &mut Scene, shading: Shading, camera: &Camera, spans: Option<&smooth::NodeSpans>) {
    let light = light_direction(camera);
    match shading {
        Shading::Flat => {
            let points = &scene.points;
            scene.light = (scene.tris.par_iter())
                .map(|&t| intensity(tri_normal(points, t), light))
                .collect();
            scene.corner_slots = Cow::Owned(
                (0..scene.tris.len() as u32)
                    .into_par_iter()
                    .map(|i| [i, i, i])
                    .collect(),
            );
        }
        Shading::Smooth => {
            // SAFETY: `intensities` writes every slot it is given.
            let (slots, light) = unsafe {
                smooth::per_slot(
                    &scene.points,
                    &scene.tris,
                    &scene.tri_face,
                    spans,
                    |s, o| intensities(s, light, o),
                )
            };
            scene.corner_slots = match slots {
                Some(slots) => Cow::Owned(slots),
                None => scene.tris.clone(),
            };
            scene.light = light;
        }
    }
}

/// Removes the part of every triangle on the far side of the section plane
/// (coordinate > value), splitting the triangles it crosses.
fn cut(scene: &mut Scene<'_>, section: Section) {
    let axis = section.axis as usize;
    let value = section.value;
    let old_tris = std::mem::take(&mut scene.tris);
    let old_faces = std::mem::take(&mut scene.tri_face);
    let old_slots = std::mem::take(&mut scene.corner_slots);
    let mut tris = Vec::with_capacity(old_tris.len());
    let mut slots = Vec::with_capacity(old_tris.len());
    // Points made on a crossed edge, shared by the triangles on both sides of it.
    let mut made: std::collections::HashMap<(u32, u32), u32> = std::collections::HashMap::new();
    let one_face = scene.one_face;
    for (i, (&t, &s)) in old_tris.iter().zip(old_slots.iter()).enumerate() {
        let f = one_face.unwrap_or_else(|| old_faces[i]);
        let d = t.map(|n| scene.points[n as usize][axis] - value);
        let kept = d.iter().filter(|&&v| v <= 0.0).count();
        if kept == 3 {
            tris.push(t);
            if one_face.is_none() {
                scene.tri_face.push(f);
            }
            slots.push(s);
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
                    let points = points.to_mut();
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
            tris.push([poly[0].0, poly[k].0, poly[k + 1].0]);
            slots.push([poly[0].1, poly[k].1, poly[k + 1].1]);
            if one_face.is_none() {
                scene.tri_face.push(f);
            }
        }
    }
    scene.tris = Cow::Owned(tris);
    scene.corner_slots = Cow::Owned(slots);
}
