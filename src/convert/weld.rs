//! `--weld EPS`: merges nodes closer than EPS (each into the first node of
//! its neighbourhood, in node order, so the result is deterministic) with a
//! hash grid of cell size EPS, then removes triangles that collapsed.

use super::{compact_nodes, renumber};
use crate::formats::read::build::FastMap;
use crate::mesh::Mesh;

#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Welded {
    pub merged: usize,
    pub removed_triangles: usize,
    /// Volume cells two of whose corners became one node.
    pub removed_cells: usize,
}

pub fn weld(mesh: &mut Mesh, eps: f64) -> Welded {
    let mut out = Welded::default();
    let n = mesh.nodes.len();
    let mut map: Vec<u32> = (0..n as u32).collect();
    let cell = if eps > 0.0 && eps.is_finite() {
        eps
    } else {
        0.0
    };
    let key = |p: &[f64; 3]| -> [i64; 3] {
        if cell == 0.0 {
            p.map(|c| if c == 0.0 { 0 } else { c.to_bits() as i64 })
        } else {
            p.map(|c| (c / cell).floor() as i64)
        }
    };
    // Cell → representatives in it.
    let mut grid: FastMap<[i64; 3], Vec<u32>> = FastMap::default();
    for (i, target) in map.iter_mut().enumerate() {
        let p = mesh.nodes[i];
        let k = key(&p);
        let mut found = None;
        if cell == 0.0 {
            found = grid.get(&k).and_then(|v| v.first().copied());
        } else {
            'search: for dx in -1..=1 {
                for dy in -1..=1 {
                    for dz in -1..=1 {
                        let Some(reps) = grid.get(&[k[0] + dx, k[1] + dy, k[2] + dz]) else {
                            continue;
                        };
                        for &r in reps {
                            let q = mesh.nodes[r as usize];
                            let d2 = (0..3).map(|c| (p[c] - q[c]).powi(2)).sum::<f64>();
                            if d2 <= eps * eps {
                                found = Some(r);
                                break 'search;
                            }
                        }
                    }
                }
            }
        }
        match found {
            Some(r) => {
                *target = r;
                out.merged += 1;
            }
            None => grid.entry(k).or_default().push(i as u32),
        }
    }
    drop(grid);
    if out.merged > 0 {
        renumber(mesh, &map);
        for f in &mut mesh.faces {
            let before = f.triangles.len();
            f.triangles
                .retain(|t| t[0] != t[1] && t[1] != t[2] && t[0] != t[2]);
            out.removed_triangles += before - f.triangles.len();
        }
        for p in &mut mesh.polylines {
            p.nodes.dedup();
        }
        for v in &mut mesh.volumes {
            let per = v.kind.corners();
            let before = v.nodes.len();
            let mut kept = Vec::with_capacity(before);
            for cell in v.nodes.chunks_exact(per) {
                let distinct = (1..per).all(|i| !cell[..i].contains(&cell[i]));
                if distinct {
                    kept.extend_from_slice(cell);
                }
            }
            out.removed_cells += (before - kept.len()) / per;
            v.nodes = kept;
        }
        mesh.volumes.retain(|v| !v.nodes.is_empty());
        compact_nodes(mesh);
    }
    out
}
