//! `--normals`: orients the triangles of every connected surface
//! consistently (breadth-first across edges shared by exactly two
//! triangles) and, when the surface is closed, outward (positive enclosed
//! volume). Writers then compute vertex normals from these triangles.

use crate::mesh::Mesh;
use std::collections::VecDeque;

#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Oriented {
    pub triangles: usize,
    pub flipped: usize,
    pub components: usize,
    pub closed: usize,
}

pub fn orient(mesh: &mut Mesh) -> Oriented {
    // Every triangle as (face, index), numbered globally.
    let mut tris: Vec<[u32; 3]> = mesh
        .faces
        .iter()
        .flat_map(|f| f.triangles.iter().copied())
        .collect();
    let n = tris.len();
    // Half-edges keyed by their undirected edge, then grouped by sorting.
    let mut half: Vec<(u64, u32)> = Vec::with_capacity(3 * n);
    for (i, t) in tris.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            if a != b {
                half.push(((u64::from(a.min(b)) << 32) | u64::from(a.max(b)), i as u32));
            }
        }
    }
    half.sort_unstable();
    // Neighbours across manifold edges; open edges mark their component open.
    let mut neighbours: Vec<[u32; 3]> = vec![[u32::MAX; 3]; n];
    let mut open = vec![false; n];
    let mut i = 0;
    while i < half.len() {
        let mut j = i;
        while j < half.len() && half[j].0 == half[i].0 {
            j += 1;
        }
        if j - i == 2 {
            let (a, b) = (half[i].1, half[i + 1].1);
            for (x, y) in [(a, b), (b, a)] {
                if let Some(slot) = neighbours[x as usize].iter_mut().find(|s| **s == u32::MAX) {
                    *slot = y;
                }
            }
        } else if j - i == 1 {
            open[half[i].1 as usize] = true;
        }
        i = j;
    }
    drop(half);
    let mut out = Oriented {
        triangles: n,
        ..Oriented::default()
    };
    let mut seen = vec![false; n];
    let mut flip = vec![false; n];
    let mut queue = VecDeque::new();
    for start in 0..n {
        if seen[start] {
            continue;
        }
        out.components += 1;
        seen[start] = true;
        queue.push_back(start as u32);
        let mut members = Vec::new();
        let mut closed = true;
        while let Some(t) = queue.pop_front() {
            members.push(t);
            closed &= !open[t as usize];
            let tri = tris[t as usize];
            for &nb in &neighbours[t as usize] {
                if nb == u32::MAX || seen[nb as usize] {
                    continue;
                }
                // Consistent: the shared edge runs the other way in the neighbour.
                if runs_same_way(tri, tris[nb as usize]) {
                    let m = &mut tris[nb as usize];
                    m.swap(1, 2);
                    flip[nb as usize] = !flip[nb as usize];
                }
                seen[nb as usize] = true;
                queue.push_back(nb);
            }
        }
        if closed {
            out.closed += 1;
            let volume: f64 = members
                .iter()
                .map(|&t| signed_volume(&mesh.nodes, tris[t as usize]))
                .sum();
            if volume < 0.0 {
                for &t in &members {
                    tris[t as usize].swap(1, 2);
                    flip[t as usize] = !flip[t as usize];
                }
            }
        }
    }
    out.flipped = flip.iter().filter(|&&f| f).count();
    let mut k = 0;
    for f in &mut mesh.faces {
        for t in &mut f.triangles {
            *t = tris[k];
            k += 1;
        }
    }
    out
}

/// Whether two triangles share an edge that both traverse in the same direction.
fn runs_same_way(a: [u32; 3], b: [u32; 3]) -> bool {
    (0..3).any(|i| {
        let (p, q) = (a[i], a[(i + 1) % 3]);
        (0..3).any(|j| b[j] == p && b[(j + 1) % 3] == q)
    })
}

fn signed_volume(nodes: &[[f64; 3]], [a, b, c]: [u32; 3]) -> f64 {
    let (p, q, r) = (nodes[a as usize], nodes[b as usize], nodes[c as usize]);
    (p[0] * (q[1] * r[2] - q[2] * r[1]) - p[1] * (q[0] * r[2] - q[2] * r[0])
        + p[2] * (q[0] * r[1] - q[1] * r[0]))
        / 6.0
}
