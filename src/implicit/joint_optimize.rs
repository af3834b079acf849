//! Paper 001's `optiterations` for the joint mesher (`interfaces`): the
//! patches between labels are smoothed like a lone solid's surface
//! (`optimize`), each vertex kept on the surface it lies on.
//!
//! A vertex moves only when every triangle around it belongs to one patch
//! (one pair of labels, not a box cap) and those triangles are nearly flat
//! around it (normals within 35°): vertices on junction curves (where three
//! labels meet, the rim of a pin leaving a block), on creases (a box's
//! edges) and on caps stay, so the patches keep conforming. It moves
//! towards the centroid of its neighbours within its tangent plane (at
//! most half a cell per round), then Newton steps along the gradient of
//! the function deciding its patch bring it back to f = 0; moves that turn
//! a triangle over or fold it onto a neighbour are undone. Before each
//! round, edges inside a patch are flipped where that raises the smaller
//! minimum angle of their two nearly coplanar triangles (edges on junction
//! curves, shared with another patch, never are). Everything runs in a
//! fixed order: the same result for any thread count.

use super::interfaces::{Interfaces, Solid};
use super::optimize::{Field, edge_key, flip_edges, undo_folds};
use super::polygonize::Surface;
use super::tape::Tape;
use std::collections::HashSet;

type P = [f64; 3];

/// Crease threshold between triangles around a vertex (cos 35°).
const CREASE_COS: f64 = 0.82;

fn sub(a: P, b: P) -> P {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot(a: P, b: P) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: P, b: P) -> P {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn unit(a: P) -> P {
    let l = dot(a, a).sqrt();
    if l > 0.0 { a.map(|v| v / l) } else { a }
}

/// Triangles with a smaller angle are ignored when finding creases.
const SLIVER_DEGREES: f64 = 5.0;

/// No patch yet / more than one patch around a vertex.
const NONE: u32 = u32::MAX;
const MANY: u32 = u32::MAX - 1;

/// Smooths `joint` in place with `iterations` rounds; `deciding(a, b)` is
/// the index of the solid whose f = 0 is the surface between labels a and b.
pub fn optimize_joint(
    joint: &mut Interfaces,
    solids: &[Solid],
    deciding: impl Fn(u32, u32) -> Option<usize>,
    spacing: f64,
    iterations: u32,
) {
    if iterations == 0 || joint.patches.is_empty() {
        return;
    }
    let nv = joint.positions.len();
    // The one patch around each vertex (NONE, or MANY when several).
    let mut owner = vec![NONE; nv];
    for (pi, patch) in joint.patches.iter().enumerate() {
        for t in &patch.triangles {
            for &v in t {
                let o = &mut owner[v as usize];
                *o = match *o {
                    NONE => pi as u32,
                    x if x == pi as u32 => x,
                    _ => MANY,
                };
            }
        }
    }
    let triangles: Vec<[u32; 3]> = joint
        .patches
        .iter()
        .flat_map(|p| p.triangles.iter().copied())
        .collect();
    let mut surface = Surface {
        positions: std::mem::take(&mut joint.positions),
        triangles,
        ..Surface::default()
    };
    let movable = movable_vertices(&surface, &owner, joint, &deciding);
    let tapes: Vec<Tape> = solids.iter().map(|s| Tape::new(&s.ssa)).collect();
    for _ in 0..iterations {
        let mut positions = std::mem::take(&mut surface.positions);
        for p in 0..joint.patches.len() {
            positions = flip_patch(joint, p, positions);
        }
        surface.positions = positions;
        surface.triangles = joint
            .patches
            .iter()
            .flat_map(|p| p.triangles.iter().copied())
            .collect();
        smooth_round(&mut surface, &movable, &tapes, spacing);
    }
    joint.positions = surface.positions;
}

/// Angle-improving flips inside one patch (not a cap): its edges on other
/// patches (junction curves) are never flipped, and no flip makes an edge
/// another patch has.
fn flip_patch(joint: &mut Interfaces, p: usize, positions: Vec<P>) -> Vec<P> {
    if joint.patches[p].cap {
        return positions;
    }
    let mut taken: HashSet<(u32, u32)> = HashSet::new();
    for (q, patch) in joint.patches.iter().enumerate() {
        if q == p {
            continue;
        }
        for t in &patch.triangles {
            for k in 0..3 {
                taken.insert(edge_key(t[k], t[(k + 1) % 3]));
            }
        }
    }
    let mut s = Surface {
        positions,
        triangles: std::mem::take(&mut joint.patches[p].triangles),
        ..Surface::default()
    };
    flip_edges(&mut s, &taken);
    joint.patches[p].triangles = s.triangles;
    s.positions
}

/// For each vertex, the solid it is kept on when it may move.
fn movable_vertices(
    surface: &Surface,
    owner: &[u32],
    joint: &Interfaces,
    deciding: &impl Fn(u32, u32) -> Option<usize>,
) -> Vec<Option<usize>> {
    let nv = surface.positions.len();
    let mut first: Vec<Option<P>> = vec![None; nv];
    let mut flat = vec![true; nv];
    for t in &surface.triangles {
        let p = t.map(|i| surface.positions[i as usize]);
        // A sliver's normal says nothing about the surface (its nodes are
        // nearly collinear): it neither marks a crease nor pins a vertex.
        if super::optimize::min_angle(p[0], p[1], p[2]) < SLIVER_DEGREES {
            continue;
        }
        let n = unit(cross(sub(p[1], p[0]), sub(p[2], p[0])));
        for &v in t {
            let v = v as usize;
            match first[v] {
                None => first[v] = Some(n),
                Some(m) => {
                    if dot(m, n) < CREASE_COS {
                        flat[v] = false;
                    }
                }
            }
        }
    }
    (0..nv)
        .map(|v| {
            let o = owner[v];
            if o == NONE || o == MANY || !flat[v] {
                return None;
            }
            let patch = &joint.patches[o as usize];
            if patch.cap {
                return None;
            }
            deciding(patch.pair.0, patch.pair.1)
        })
        .collect()
}

/// One round of tangential smoothing with re-projection.
#[allow(clippy::needless_range_loop)] // v indexes several per-vertex arrays
fn smooth_round(surface: &mut Surface, movable: &[Option<usize>], tapes: &[Tape], spacing: f64) {
    let nv = surface.positions.len();
    let mut sum = vec![[0.0; 3]; nv];
    let mut count = vec![0u32; nv];
    let mut normal = vec![[0.0; 3]; nv];
    for t in &surface.triangles {
        let p = t.map(|i| surface.positions[i as usize]);
        let n = cross(sub(p[1], p[0]), sub(p[2], p[0]));
        for k in 0..3 {
            let (v, w) = (t[k] as usize, t[(k + 1) % 3] as usize);
            for (x, y) in [(v, w), (w, v)] {
                for a in 0..3 {
                    sum[x][a] += surface.positions[y][a];
                }
                count[x] += 1;
            }
            for a in 0..3 {
                normal[v][a] += n[a];
            }
        }
    }
    let before = surface.positions.clone();
    let normals: Vec<P> = surface
        .triangles
        .iter()
        .map(|t| {
            let p = t.map(|i| surface.positions[i as usize]);
            cross(sub(p[1], p[0]), sub(p[2], p[0]))
        })
        .collect();
    // Batched per solid, in vertex order.
    for (s, tape) in tapes.iter().enumerate() {
        let mut moved: Vec<usize> = Vec::new();
        let mut pts: Vec<P> = Vec::new();
        for v in 0..nv {
            if movable[v] != Some(s) || count[v] == 0 {
                continue;
            }
            let p = surface.positions[v];
            let c = sum[v].map(|x| x / count[v] as f64);
            let n = unit(normal[v]);
            let d = sub(c, p);
            let t = sub(d, n.map(|x| x * dot(d, n)));
            let len = dot(t, t).sqrt().max(1e-300);
            let scale = (0.5 * spacing / len).min(1.0);
            moved.push(v);
            pts.push([0, 1, 2].map(|a| p[a] + t[a] * scale));
        }
        if moved.is_empty() {
            continue;
        }
        let field = Field {
            tape,
            h: spacing * 1e-4,
            reach: spacing,
        };
        field.project(&mut pts, 3);
        for (m, &v) in moved.iter().enumerate() {
            let q = pts[m];
            let far = dot(sub(q, before[v]), sub(q, before[v])) > spacing * spacing;
            if q.iter().all(|x| x.is_finite()) && !far {
                surface.positions[v] = q;
            }
        }
    }
    undo_folds(surface, &before, &normals);
}
