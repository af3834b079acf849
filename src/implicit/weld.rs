//! Crossings on grid samples (issue 5): when the surface passes through a
//! sample (f exactly at the level there, or within the snap tolerance of
//! it), every crossed edge at that sample gets a vertex at the same point,
//! and the triangles between them have zero area. This pass makes such
//! vertices one mesh node, drops the triangles that collapse, and keeps the
//! result a closed, oriented 2-manifold:
//!
//! - only vertices joined by a mesh edge are merged (transitively), so two
//!   sheets that merely touch at a sample stay two sheets;
//! - a pair of triangles that become the same triangle with opposite
//!   orientations (a fin) is dropped;
//! - a merge that would leave an edge used other than once in each
//!   direction is undone for the samples at that edge's ends;
//! - a node whose triangles form more than one fan (a pinch point, two
//!   sheets meeting at one point) is split into one node per fan.
//!
//! Nodes no triangle uses any more are removed; the rest keep their order,
//! so the output is as deterministic as the input.

use super::polygonize::Surface;
use std::collections::HashMap;

/// Edge crossings closer than this (as a fraction of the edge) to a sample
/// are placed on it.
pub const SNAP: f64 = 1e-6;

/// No sample: a vertex inside an edge (or a cycle centre).
pub const NONE: u64 = u64::MAX;

fn find(parent: &mut [u32], mut x: u32) -> u32 {
    while parent[x as usize] != x {
        let up = parent[parent[x as usize] as usize];
        parent[x as usize] = up;
        x = up;
    }
    x
}

/// Merges the vertices that sit on one sample; `at_sample[v]` is the
/// sample a vertex lies on ([`NONE`] when it lies inside its edge; vertices
/// past the end of the slice lie on none).
pub fn weld_at_samples(surface: &mut Surface, at_sample: &[u64]) {
    let sample = |v: u32| at_sample.get(v as usize).copied().unwrap_or(NONE);
    if at_sample.iter().all(|&s| s == NONE) {
        return;
    }
    let n = surface.positions.len();
    let mut parent: Vec<u32> = (0..n as u32).collect();
    for t in &surface.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            if sample(a) != NONE && sample(a) == sample(b) {
                let (ra, rb) = (find(&mut parent, a), find(&mut parent, b));
                // The smaller id represents the group (deterministic).
                let (lo, hi) = (ra.min(rb), ra.max(rb));
                parent[hi as usize] = lo;
            }
        }
    }
    let merged: Vec<u32> = (0..n as u32).map(|v| find(&mut parent, v)).collect();
    if merged.iter().enumerate().all(|(v, &r)| v as u32 == r) {
        return;
    }
    // Groups whose merge is undone (by their representative).
    let mut undone = vec![false; n];
    let triangles = loop {
        let map = |v: u32| {
            let r = merged[v as usize];
            if undone[r as usize] { v } else { r }
        };
        let tris = collapse(&surface.triangles, map);
        let bad = bad_edges(&tris);
        if bad.is_empty() {
            break tris;
        }
        for (a, b) in bad {
            undone[a as usize] = true;
            undone[b as usize] = true;
        }
    };
    let mut positions = surface.positions.clone();
    let triangles = split_pinches(triangles, &mut positions);
    let (positions, triangles) = compact(positions, triangles);
    surface.positions = positions;
    surface.triangles = triangles;
}

/// The triangles with vertices mapped, without those that repeat a vertex
/// and without pairs that became one triangle with both orientations.
fn collapse(triangles: &[[u32; 3]], map: impl Fn(u32) -> u32) -> Vec<[u32; 3]> {
    let mapped: Vec<[u32; 3]> = triangles
        .iter()
        .map(|t| t.map(&map))
        .filter(|t| t[0] != t[1] && t[1] != t[2] && t[0] != t[2])
        .collect();
    // Key: the vertex set; value: indices with each orientation.
    let canon = |t: &[u32; 3]| {
        let mut s = *t;
        s.sort_unstable();
        let even = [t[0], t[1], t[2]] == [s[0], s[1], s[2]]
            || [t[1], t[2], t[0]] == [s[0], s[1], s[2]]
            || [t[2], t[0], t[1]] == [s[0], s[1], s[2]];
        (s, even)
    };
    let mut seen: HashMap<[u32; 3], [Vec<usize>; 2]> = HashMap::new();
    for (i, t) in mapped.iter().enumerate() {
        let (s, even) = canon(t);
        seen.entry(s).or_default()[even as usize].push(i);
    }
    let mut drop = vec![false; mapped.len()];
    for [odd, even] in seen.values() {
        for (&a, &b) in odd.iter().zip(even) {
            drop[a] = true;
            drop[b] = true;
        }
    }
    mapped
        .into_iter()
        .zip(drop)
        .filter(|(_, d)| !d)
        .map(|(t, _)| t)
        .collect()
}

/// Edges not used exactly once in each direction.
fn bad_edges(triangles: &[[u32; 3]]) -> Vec<(u32, u32)> {
    let mut directed: HashMap<(u32, u32), u32> = HashMap::new();
    for t in triangles {
        for k in 0..3 {
            *directed.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
        }
    }
    let mut bad: Vec<(u32, u32)> = directed
        .iter()
        .filter(|&(&(a, b), &n)| n != 1 || directed.get(&(b, a)) != Some(&1))
        .map(|(&e, _)| e)
        .collect();
    bad.sort_unstable();
    bad
}

/// Gives each extra fan of triangles around a node a copy of the node.
fn split_pinches(mut triangles: Vec<[u32; 3]>, positions: &mut Vec<[f64; 3]>) -> Vec<[u32; 3]> {
    // (triangle, corner) per node, in triangle order.
    let mut corners: Vec<Vec<(usize, usize)>> = vec![Vec::new(); positions.len()];
    for (i, t) in triangles.iter().enumerate() {
        for (k, &v) in t.iter().enumerate() {
            corners[v as usize].push((i, k));
        }
    }
    for (v, around) in corners.iter().enumerate() {
        if around.len() < 3 {
            continue;
        }
        // The corner whose triangle leaves v towards each neighbour.
        let by_next: HashMap<u32, usize> = around
            .iter()
            .enumerate()
            .map(|(m, &(i, k))| (triangles[i][(k + 1) % 3], m))
            .collect();
        let mut fan = vec![usize::MAX; around.len()];
        let mut fans = 0;
        for start in 0..around.len() {
            if fan[start] != usize::MAX {
                continue;
            }
            let mut m = start;
            while fan[m] == usize::MAX {
                fan[m] = fans;
                let (i, k) = around[m];
                // The next triangle around v shares the edge (v, prev).
                let prev = triangles[i][(k + 2) % 3];
                match by_next.get(&prev) {
                    Some(&next) => m = next,
                    None => break,
                }
            }
            fans += 1;
        }
        if fans < 2 {
            continue;
        }
        let copies: Vec<u32> = (1..fans)
            .map(|_| {
                positions.push(positions[v]);
                (positions.len() - 1) as u32
            })
            .collect();
        for (m, &(i, k)) in around.iter().enumerate() {
            if fan[m] > 0 {
                triangles[i][k] = copies[fan[m] - 1];
            }
        }
    }
    triangles
}

/// Drops unused nodes, keeping the order of the rest.
fn compact(positions: Vec<[f64; 3]>, triangles: Vec<[u32; 3]>) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let mut used = vec![false; positions.len()];
    for t in &triangles {
        for &v in t {
            used[v as usize] = true;
        }
    }
    let mut new_id = vec![u32::MAX; positions.len()];
    let mut kept = Vec::with_capacity(positions.len());
    for (v, p) in positions.into_iter().enumerate() {
        if used[v] {
            new_id[v] = kept.len() as u32;
            kept.push(p);
        }
    }
    let triangles = triangles
        .into_iter()
        .map(|t| t.map(|v| new_id[v as usize]))
        .collect();
    (kept, triangles)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An octahedron whose +x tip is split into four coincident vertices
    /// (one per incident triangle edge pair), as crossings on one sample are.
    #[test]
    fn coincident_tip_vertices_become_one_node() {
        // 0..4 the square, 4 the -x tip, 5..9 four copies of the +x tip.
        let mut positions = vec![
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.0, -1.0, 0.0],
            [0.0, 0.0, -1.0],
            [-1.0, 0.0, 0.0],
        ];
        positions.extend([[1.0, 0.0, 0.0]; 4]);
        let mut triangles = Vec::new();
        for q in 0..4u32 {
            let (a, b) = (q, (q + 1) % 4);
            triangles.push([4, b, a]);
            // The +x cap as a quad strip of zero-width triangles.
            let (ta, tb) = (5 + q, 5 + (q + 1) % 4);
            triangles.push([a, b, tb]);
            triangles.push([a, tb, ta]);
        }
        // The four tip copies close a zero-area square: two triangles.
        triangles.push([5, 6, 7]);
        triangles.push([5, 7, 8]);
        let mut s = Surface {
            positions,
            triangles,
            ..Surface::default()
        };
        let at: Vec<u64> = (0..9).map(|v| if v >= 5 { 42 } else { NONE }).collect();
        weld_at_samples(&mut s, &at);
        assert_eq!(s.positions.len(), 6);
        assert_eq!(s.triangles.len(), 8, "an octahedron: {:?}", s.triangles);
        assert!(bad_edges(&s.triangles).is_empty());
    }

    /// A capped tube whose middle ring pair lies on one sample: the tube
    /// collapses to a point, and the two cones meeting there get a node each.
    #[test]
    fn a_collapsed_tube_becomes_two_cones_with_a_node_each() {
        // Rings: b = 0..3, a = 3..6, c = 6..9, d = 9..12.
        let ring = |r: u32, i: u32| r + i % 3;
        let mut triangles = vec![[0, 2, 1], [9, 10, 11]];
        for (r, s) in [(0, 3), (3, 6), (6, 9)] {
            for i in 0..3 {
                triangles.push([ring(r, i), ring(r, i + 1), ring(s, i + 1)]);
                triangles.push([ring(r, i), ring(s, i + 1), ring(s, i)]);
            }
        }
        assert!(bad_edges(&triangles).is_empty(), "the tube is closed");
        let positions = (0..12)
            .map(|v| {
                let angle = (v % 3) as f64 * 2.0;
                match v / 3 {
                    0 => [angle.cos(), angle.sin(), -1.0],
                    3 => [angle.cos(), angle.sin(), 1.0],
                    _ => [0.0, 0.0, 0.0],
                }
            })
            .collect();
        let mut s = Surface {
            positions,
            triangles,
            ..Surface::default()
        };
        let at: Vec<u64> = (0..12)
            .map(|v| if (3..9).contains(&v) { 5 } else { NONE })
            .collect();
        weld_at_samples(&mut s, &at);
        assert_eq!((s.positions.len(), s.triangles.len()), (8, 8));
        assert!(bad_edges(&s.triangles).is_empty());
        // Each apex copy is used by exactly one cone's three sides.
        for apex in [3u32, 7] {
            let n = s.triangles.iter().filter(|t| t.contains(&apex)).count();
            assert_eq!(n, 3, "{:?}", s.triangles);
        }
    }
}
