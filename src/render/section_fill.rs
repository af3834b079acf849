//! The cut face of `--section` as filled SVG polygons: each subdomain's
//! boundary triangles are cut by the plane, the cut segments are chained into
//! closed loops (a crossing point is named by the mesh edge it lies on, so the
//! chaining is exact), and the loops of one subdomain make one even–odd path,
//! so holes stay open.
//!
//! Visibility is exact without a depth test: everything beyond the plane is
//! cut away, so an eye on the cut-away side sees the whole cut face and an eye
//! on the kept side sees none of it (material lies in front of every point of
//! it). Lines behind the cut face are already removed by the hidden-line pass,
//! which keeps the cut surfaces' back sides as occluders.

use super::Section;
use super::camera::{Camera, dot};
use crate::mesh::Mesh;
use std::collections::BTreeMap;

/// One subdomain's cut face: closed loops of screen points.
#[derive(Debug, Clone, PartialEq)]
pub struct CutFace {
    pub subdomain: usize,
    pub loops: Vec<Vec<[f64; 2]>>,
}

impl CutFace {
    /// The even–odd area in square pixels (holes run the other way, so
    /// their signed areas subtract).
    pub fn area(&self) -> f64 {
        self.loops.iter().map(|lp| shoelace(lp)).sum::<f64>()
    }
}

fn shoelace(points: &[[f64; 2]]) -> f64 {
    let n = points.len();
    0.5 * (0..n)
        .map(|i| {
            let (a, b) = (points[i], points[(i + 1) % n]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum::<f64>()
}

/// The visible cut faces, one per subdomain the plane crosses.
pub fn cut_faces(mesh: &Mesh, section: Section, camera: &Camera) -> Vec<CutFace> {
    let axis = section.axis as usize;
    // The cut face's outward normal is +axis; seen only from that side.
    let mut normal = [0.0; 3];
    normal[axis] = 1.0;
    if dot(normal, camera.toward_eye) <= 1e-12 {
        return Vec::new();
    }
    let d = |n: u32| mesh.nodes[n as usize][axis] - section.value;
    let mut out = Vec::new();
    for (s, sub) in mesh.subdomains.iter().enumerate() {
        // Each crossed triangle gives a segment between two crossed edges.
        let mut next: BTreeMap<(u32, u32), Vec<(u32, u32)>> = BTreeMap::new();
        for &(f, _) in &sub.faces {
            let Some(face) = mesh.faces.get(f as usize) else {
                continue;
            };
            for t in &face.triangles {
                if t.iter().any(|&n| n as usize >= mesh.nodes.len()) {
                    continue;
                }
                let crossed: Vec<(u32, u32)> = (0..3)
                    .filter_map(|k| {
                        let (a, b) = (t[k], t[(k + 1) % 3]);
                        ((d(a) <= 0.0) != (d(b) <= 0.0)).then_some((a.min(b), a.max(b)))
                    })
                    .collect();
                if let [e0, e1] = crossed[..] {
                    next.entry(e0).or_default().push(e1);
                    next.entry(e1).or_default().push(e0);
                }
            }
        }
        let loops = chain(&next)
            .into_iter()
            .map(|lp| {
                lp.into_iter()
                    .map(|(lo, hi)| {
                        let (pa, pb) = (mesh.nodes[lo as usize], mesh.nodes[hi as usize]);
                        let u = d(lo) / (d(lo) - d(hi));
                        let mut p = [0.0; 3];
                        for c in 0..3 {
                            p[c] = pa[c] + u * (pb[c] - pa[c]);
                        }
                        p[axis] = section.value;
                        let q = camera.project(p);
                        [q[0], q[1]]
                    })
                    .collect()
            })
            .collect::<Vec<Vec<[f64; 2]>>>();
        let loops = orient_by_nesting(loops);
        if !loops.is_empty() {
            out.push(CutFace {
                subdomain: s,
                loops,
            });
        }
    }
    out
}

/// Turns loops nested an even number of times counter-clockwise (positive
/// area) and the others clockwise, so the signed areas add up to the
/// even–odd area.
fn orient_by_nesting(mut loops: Vec<Vec<[f64; 2]>>) -> Vec<Vec<[f64; 2]>> {
    let depth: Vec<usize> = loops
        .iter()
        .enumerate()
        .map(|(i, lp)| {
            let p = lp[0];
            loops
                .iter()
                .enumerate()
                .filter(|&(j, other)| j != i && inside(other, p))
                .count()
        })
        .collect();
    for (lp, depth) in loops.iter_mut().zip(depth) {
        if (shoelace(lp) > 0.0) != (depth % 2 == 0) {
            lp.reverse();
        }
    }
    loops
}

/// Even–odd crossing test.
fn inside(lp: &[[f64; 2]], p: [f64; 2]) -> bool {
    let mut odd = false;
    for i in 0..lp.len() {
        let (a, b) = (lp[i], lp[(i + 1) % lp.len()]);
        if (a[1] > p[1]) != (b[1] > p[1]) {
            let x = a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
            if x > p[0] {
                odd = !odd;
            }
        }
    }
    odd
}

/// Closed loops through a graph where every node has two neighbours; nodes of
/// any other degree (an open or non-manifold shell) end their chain, and
/// chains that do not close are dropped.
fn chain(next: &BTreeMap<(u32, u32), Vec<(u32, u32)>>) -> Vec<Vec<(u32, u32)>> {
    let mut used: BTreeMap<(u32, u32), bool> = next.keys().map(|&k| (k, false)).collect();
    let mut loops = Vec::new();
    for (&start, around) in next {
        if used[&start] || around.len() != 2 {
            continue;
        }
        let mut lp = vec![start];
        used.insert(start, true);
        let (mut prev, mut at) = (start, around[0]);
        let closed = loop {
            if at == start {
                break true;
            }
            let Some(n) = next.get(&at).filter(|n| n.len() == 2) else {
                break false;
            };
            if used[&at] {
                break false;
            }
            used.insert(at, true);
            lp.push(at);
            let step = if n[0] == prev { n[1] } else { n[0] };
            (prev, at) = (at, step);
        };
        if closed && lp.len() >= 3 {
            loops.push(lp);
        }
    }
    loops
}
