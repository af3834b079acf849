//! Conforming surfaces between several implicit solids (issue 5): when two
//! subdomains touch (a pin in a hole carved out of a block), the surface
//! between them must be meshed once and shared, not once per subdomain.
//!
//! Every grid sample gets a label: the first solid (in the given order)
//! with f > 0 there, else the exterior (label 0; solid i is label i + 1).
//! Each cell is split into eight octants, one per corner, by the quads
//! (edge point, face point, cell point, face point) around the midpoints
//! of its edges; a label's region is the union of its corners' octants, so
//! the surface between labels a and b is the set of quads of the cell
//! edges whose ends carry a and b. Points are shared through their grid
//! edge, face or cell, so neighbouring cells use the same nodes: every
//! patch conforms, and each label's boundary is closed.
//!
//! - An edge point is the root, along the edge, of the function of the
//!   solid at one end (the lower-numbered solid when both ends are solids:
//!   its f is > 0 at its end and ≤ 0 at the other), by false position.
//! - Face and cell points are dual contouring's: the least-squares meeting
//!   point of the edge points' tangent planes (about their mean, small
//!   eigenvalues dropped), kept inside the face or cell, so creases (a
//!   box's edges) and junction curves (where three labels meet: the rim of
//!   a pin leaving a block) are kept; where only two labels meet, the point
//!   is then moved onto the surface by Newton steps along the gradient.
//!
//! Limitation: a cell face whose corners alternate between two labels
//! (a, b, a, b) makes the two diagonal octants touch along one segment, a
//! non-manifold edge; at the resolutions models are meshed at this needs a
//! feature thinner than a cell.

use super::polygonize::Grid;
use super::tape::Ssa;
use super::weld;
use rayon::prelude::*;
use std::collections::HashMap;

/// Triangles between labels `pair.0 < pair.1`, oriented with normals
/// pointing from `pair.0` into `pair.1`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Patch {
    pub pair: (u32, u32),
    pub triangles: Vec<[u32; 3]>,
    /// Where solid `pair.1` reaches the grid's box (`pair.0` is then 0): the
    /// cap that closes it there, not its surface.
    pub cap: bool,
}

/// Nodes and the patches between labels, ordered by pair.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Interfaces {
    pub positions: Vec<[f64; 3]>,
    pub patches: Vec<Patch>,
}

impl Interfaces {
    /// Whether two solids share a surface (a patch between two labels > 0).
    pub fn touching(&self) -> bool {
        self.patches.iter().any(|p| p.pair.0 > 0)
    }
}

/// One solid: f > 0 inside, within its box.
#[derive(Debug, Clone)]
pub struct Solid {
    pub ssa: Ssa,
    pub min: [f64; 3],
    pub max: [f64; 3],
}

/// Root-finding iterations per edge and Newton steps per face or cell point.
const ROOT_ITERATIONS: usize = 40;
const NEWTON_STEPS: usize = 4;
/// Face and cell points stay this fraction of the cell inside their face
/// or cell.
const INSET: f64 = 1e-3;
/// Nodes joined by an edge shorter than this fraction of the spacing are
/// merged (several times the inset's diagonal).
const MERGE: f64 = 1e-2;

/// Meshes the labelled partition of the grid by `solids` (f > 0 inside
/// their boxes). Samples on the grid's box are exterior, so every solid is
/// closed against the box where it leaves it.
pub fn polygonize_labels(solids: &[Solid], grid: &Grid) -> Interfaces {
    let coords = [grid.coords(0), grid.coords(1), grid.coords(2)];
    let n1 = grid.cells.map(|n| n + 1);
    let at = |i: usize, j: usize, k: usize| [coords[0][i], coords[1][j], coords[2][k]];
    let samples: Vec<Vec<f32>> = solids
        .iter()
        .map(|s| super::polygonize::sample_grid(&s.ssa, grid))
        .collect();
    let idx = |i: usize, j: usize, k: usize| (k * n1[1] + j) * n1[0] + i;
    let face_key = |cell: [usize; 3], n: usize, s: usize| {
        let mut base = cell;
        base[n] += s;
        (idx(base[0], base[1], base[2]) as u64) * 3 + n as u64
    };
    let mut labels = vec![0u32; n1[0] * n1[1] * n1[2]];
    let plane = n1[0] * n1[1];
    labels
        .par_chunks_mut(plane)
        .enumerate()
        .for_each(|(k, layer)| {
            if k == 0 || k + 1 >= n1[2] {
                return;
            }
            for j in 1..n1[1].saturating_sub(1) {
                for i in 1..n1[0].saturating_sub(1) {
                    let p = at(i, j, k);
                    let p_idx = idx(i, j, k);
                    let within = |s: &Solid| (0..3).all(|a| s.min[a] <= p[a] && p[a] <= s.max[a]);
                    let first = |test: &dyn Fn(f32) -> bool| {
                        solids
                            .iter()
                            .zip(&samples)
                            .position(|(s, v)| test(v[p_idx]) && within(s))
                    };
                    // A sample on the zero sets of two solids lies on their
                    // interface, not in a gap between them: it takes the first
                    // (else the two surfaces would pass on either side of it,
                    // a sheet of exterior between them, as along the lines
                    // where a pin of r = 0.3 touches the samples at 20³).
                    let on_zero = solids
                        .iter()
                        .zip(&samples)
                        .filter(|(s, v)| v[p_idx] == 0.0 && within(s))
                        .count();
                    layer[p_idx - k * plane] = first(&|v| v > 0.0)
                        .or_else(|| (on_zero >= 2).then(|| first(&|v| v == 0.0)).flatten())
                        .map_or(0, |s| s as u32 + 1);
                }
            }
        });
    let label_at = |c: [usize; 3]| labels[idx(c[0], c[1], c[2])];
    // An exterior sample where solid `l` (label) is positive lies on the
    // grid's box or outside that solid's box: the surface between them is
    // the cap closing the solid there, not its boundary.
    let cut_at = |c: [usize; 3], l: u32| {
        let p_idx = idx(c[0], c[1], c[2]);
        l > 0 && samples.get(l as usize - 1).is_some_and(|v| v[p_idx] > 0.0)
    };
    let spacing = (0..3)
        .map(|a| (grid.max[a] - grid.min[a]) / grid.cells[a].max(1) as f64)
        .fold(f64::INFINITY, f64::min);
    let deciding_index = |a: u32, b: u32| deciding_solid(a, b, solids.len());
    let deciding = |a: u32, b: u32| deciding_index(a, b).map(|s| &solids[s].ssa);
    let cells = grid.cells;
    // The point and unit normal of the grid edge from sample `pu` along
    // axis `d`, whose ends carry labels a ≠ b.
    let edge_geometry = |pu: [usize; 3], d: usize, a: u32, b: u32| -> EdgePoint {
        let mut pw = pu;
        pw[d] += 1;
        let f = deciding(a, b);
        let (xu, xw) = (at(pu[0], pu[1], pu[2]), at(pw[0], pw[1], pw[2]));
        // A cap's point is where the edge leaves the solid's box (the
        // exterior sample when that is the grid's box), its normal the box's.
        let cut = if a == 0 && cut_at(pu, b) {
            Some((b, xw, xu, -1.0))
        } else if b == 0 && cut_at(pw, a) {
            Some((a, xu, xw, 1.0))
        } else {
            None
        };
        match cut {
            Some((s, inside, outside, sign)) => {
                let s = &solids[s as usize - 1];
                let bound = if outside[d] > s.max[d] {
                    s.max[d]
                } else if outside[d] < s.min[d] {
                    s.min[d]
                } else {
                    outside[d]
                };
                let mut p = inside;
                p[d] = bound.clamp(xu[d], xw[d]);
                let mut n = [0.0; 3];
                n[d] = sign;
                (p, n)
            }
            None => {
                let p = edge_root(f, xu, xw);
                (p, f.map_or([0.0; 3], |f| unit_gradient(f, p, spacing)))
            }
        }
    };
    // The expensive geometry (root finding, dual contouring's points and
    // their projection) runs in parallel over z planes; each point is a
    // function of its own edge, face or cell only, so whichever thread
    // computes it gives the same bits. The numbering pass below then walks
    // the cells in order as a single thread would: output is identical for
    // any thread count.
    let edge_points: HashMap<u64, EdgePoint> = (0..n1[2])
        .into_par_iter()
        .map(|k| {
            let mut found = Vec::new();
            for j in 0..n1[1] {
                for i in 0..n1[0] {
                    let pu = [i, j, k];
                    for d in 0..3 {
                        let mut pw = pu;
                        pw[d] += 1;
                        if pw[d] >= n1[d] {
                            continue;
                        }
                        let (a, b) = (label_at(pu), label_at(pw));
                        if a != b {
                            let key = (idx(i, j, k) as u64) * 3 + d as u64;
                            found.push((key, edge_geometry(pu, d, a, b)));
                        }
                    }
                }
            }
            found
        })
        .collect::<Vec<_>>()
        .into_iter()
        .flatten()
        .collect();
    // The point of a set of corners of cell `cell`: the mean of their crossed
    // edges' points, projected when two labels meet there.
    let centre = |cell: [usize; 3],
                  l: &[u32; 8],
                  ep: &[Option<EdgePoint>; 12],
                  edges: &[usize],
                  corners: &[usize]| {
        let planes: Vec<EdgePoint> = edges.iter().filter_map(|&e| ep[e]).collect();
        let mean: [f64; 3] = std::array::from_fn(|a| {
            planes.iter().map(|(p, _)| p[a]).sum::<f64>() / planes.len().max(1) as f64
        });
        let mut ls: Vec<u32> = corners.iter().map(|&c| l[c]).collect();
        ls.sort_unstable();
        ls.dedup();
        // The functions whose zero sets meet here: one on a surface
        // (project onto it), more on a junction.
        let mut fs: Vec<usize> = Vec::new();
        for (x, &a) in ls.iter().enumerate() {
            for &b in &ls[x + 1..] {
                if let Some(f) = deciding_index(a, b)
                    && !fs.contains(&f)
                {
                    fs.push(f);
                }
            }
        }
        let (lo, hi) = inset_box(corners.iter().map(|&c| {
            let q = corner_of(cell, c);
            at(q[0], q[1], q[2])
        }));
        let q = qef_point(&planes, mean, lo, hi);
        match fs[..] {
            [f] => project(&solids[f].ssa, q, lo, hi),
            _ => q,
        }
    };
    // Per mixed cell, in order: its corner labels, the points of the faces
    // it owns (its lower faces, and its upper ones on the grid's upper
    // boundary) and its cell point.
    let mixed: Vec<MixedCell> = (0..cells[2])
        .into_par_iter()
        .map(|k| {
            let mut found = Vec::new();
            for j in 0..cells[1] {
                for i in 0..cells[0] {
                    let cell = [i, j, k];
                    let l: [u32; 8] = std::array::from_fn(|c| label_at(corner_of(cell, c)));
                    if l.iter().all(|&x| x == l[0]) {
                        continue;
                    }
                    let ep: [Option<EdgePoint>; 12] = std::array::from_fn(|e| {
                        let (d, o) = (e / 4, e % 4);
                        let (cu, cw) = edge_ends(d, o);
                        if l[cu] == l[cw] {
                            return None;
                        }
                        let pu = corner_of(cell, cu);
                        edge_points
                            .get(&((idx(pu[0], pu[1], pu[2]) as u64) * 3 + d as u64))
                            .copied()
                    });
                    let mut faces = Vec::new();
                    for n in 0..3 {
                        for s in 0..2 {
                            let fe = face_edges(n, s);
                            if fe.iter().all(|&e| ep[e].is_none()) {
                                continue;
                            }
                            if s == 1 && cell[n] + 1 < cells[n] {
                                continue;
                            }
                            let key = face_key(cell, n, s);
                            faces.push((key, centre(cell, &l, &ep, &fe, &face_corners(n, s))));
                        }
                    }
                    let all: Vec<usize> = (0..12).collect();
                    let corners: Vec<usize> = (0..8).collect();
                    let point = centre(cell, &l, &ep, &all, &corners);
                    found.push(MixedCell {
                        cell,
                        l,
                        faces,
                        point,
                    });
                }
            }
            found
        })
        .collect::<Vec<_>>()
        .into_iter()
        .flatten()
        .collect();
    let face_points: HashMap<u64, [f64; 3]> =
        mixed.iter().flat_map(|m| m.faces.iter().copied()).collect();
    let mut out = Interfaces::default();
    // Which nodes are edge points (on the surface of their edge's function).
    let mut edge_point: Vec<bool> = Vec::new();
    let mut edge_nodes: HashMap<u64, u32> = HashMap::new();
    let mut face_nodes: HashMap<u64, u32> = HashMap::new();
    let mut patches: HashMap<PatchKey, Vec<[u32; 3]>> = HashMap::new();
    for m in &mixed {
        let (cell, l) = (m.cell, &m.l);
        let corner = |c: usize| corner_of(cell, c);
        let mut en = [u32::MAX; 12];
        for d in 0..3 {
            for o in 0..4 {
                let (cu, cw) = edge_ends(d, o);
                if l[cu] == l[cw] {
                    continue;
                }
                let pu = corner(cu);
                let key = (idx(pu[0], pu[1], pu[2]) as u64) * 3 + d as u64;
                en[d * 4 + o] = *edge_nodes.entry(key).or_insert_with(|| {
                    let (p, _) = edge_points[&key];
                    out.positions.push(p);
                    edge_point.push(true);
                    (out.positions.len() - 1) as u32
                });
            }
        }
        let mut fnode = [u32::MAX; 6];
        for n in 0..3 {
            for s in 0..2 {
                if face_edges(n, s).iter().all(|&e| en[e] == u32::MAX) {
                    continue;
                }
                let key = face_key(cell, n, s);
                fnode[n * 2 + s] = *face_nodes.entry(key).or_insert_with(|| {
                    out.positions.push(face_points[&key]);
                    edge_point.push(false);
                    (out.positions.len() - 1) as u32
                });
            }
        }
        out.positions.push(m.point);
        edge_point.push(false);
        let c = (out.positions.len() - 1) as u32;
        for d in 0..3 {
            let (d1, d2) = ((d + 1) % 3, (d + 2) % 3);
            for o in 0..4 {
                let e = en[d * 4 + o];
                if e == u32::MAX {
                    continue;
                }
                let (o1, o2) = (o & 1, o >> 1);
                let (f1, f2) = (fnode[d1 * 2 + o1], fnode[d2 * 2 + o2]);
                let (cu, cw) = edge_ends(d, o);
                let (a, b) = (l[cu], l[cw]);
                // E, F1, C, F2 turns about −d when o1 + o2 is even.
                let towards_plus_d = (o1 + o2) % 2 == 1;
                let forward = towards_plus_d == (a < b);
                let (tri1, tri2) = if forward {
                    ([e, f1, c], [e, c, f2])
                } else {
                    ([e, c, f1], [e, f2, c])
                };
                let cap = (a == 0 && cut_at(corner(cu), b)) || (b == 0 && cut_at(corner(cw), a));
                let list = patches.entry(((a.min(b), a.max(b)), cap)).or_default();
                list.push(tri1);
                list.push(tri2);
            }
        }
    }
    let mut pairs: Vec<_> = patches.into_iter().collect();
    pairs.sort_by_key(|(key, _)| *key);
    merge_coincident(&mut out.positions, &edge_point, &mut pairs, MERGE * spacing);
    out.patches = pairs
        .into_iter()
        .map(|((pair, cap), triangles)| Patch {
            pair,
            triangles,
            cap,
        })
        .collect();
    out
}

/// An edge point and its unit normal (a cap's point: the box face's).
type EdgePoint = ([f64; 3], [f64; 3]);

/// A cell some of whose corners differ in label, with what the parallel
/// pass computed for it.
struct MixedCell {
    cell: [usize; 3],
    l: [u32; 8],
    /// (face key, point) of the faces this cell owns.
    faces: Vec<(u64, [f64; 3])>,
    point: [f64; 3],
}

/// Grid sample of corner `c` (bit a: +1 along axis a) of `cell`.
fn corner_of(cell: [usize; 3], c: usize) -> [usize; 3] {
    [
        cell[0] + (c & 1),
        cell[1] + (c >> 1 & 1),
        cell[2] + (c >> 2 & 1),
    ]
}

/// Cell edge (d, o): along axis d, at offset o & 1 along d + 1 and o >> 1
/// along d + 2; its corners (lower, upper).
fn edge_ends(d: usize, o: usize) -> (usize, usize) {
    let mut lo = [0usize; 3];
    lo[(d + 1) % 3] = o & 1;
    lo[(d + 2) % 3] = o >> 1;
    let mut hi = lo;
    hi[d] = 1;
    (
        lo[0] | lo[1] << 1 | lo[2] << 2,
        hi[0] | hi[1] << 1 | hi[2] << 2,
    )
}

/// Face (n, s) of a cell (normal n, offset s): its edges (d, o) with d ≠ n,
/// as indices d * 4 + o, in that order.
fn face_edges(n: usize, s: usize) -> Vec<usize> {
    (0..3)
        .filter(|&d| d != n)
        .flat_map(|d| (0..4).map(move |o| (d, o)))
        .filter(|&(d, o)| {
            let off = if n == (d + 1) % 3 { o & 1 } else { o >> 1 };
            off == s
        })
        .map(|(d, o)| d * 4 + o)
        .collect()
}

fn face_corners(n: usize, s: usize) -> Vec<usize> {
    (0..8).filter(|&c| (c >> n) & 1 == s).collect()
}

/// The bounding box of `points`, inset by INSET of its size: a point
/// clamped onto the box would be collinear with the edge points there.
fn inset_box(points: impl Iterator<Item = [f64; 3]>) -> ([f64; 3], [f64; 3]) {
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for p in points {
        for a in 0..3 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    let d: [f64; 3] = std::array::from_fn(|a| INSET * (hi[a] - lo[a]));
    (
        std::array::from_fn(|a| lo[a] + d[a]),
        std::array::from_fn(|a| hi[a] - d[a]),
    )
}

/// The solid whose function decides the surface between labels `a` and `b`
/// (the lower-numbered solid when both are solids) among `n` solids.
pub fn deciding_solid(a: u32, b: u32, n: usize) -> Option<usize> {
    let s = match (a, b) {
        (0, s) | (s, 0) => s,
        (a, b) => a.min(b),
    };
    let s = s.checked_sub(1)? as usize;
    (s < n).then_some(s)
}

/// A pair of labels and whether the triangles between them are a box cap.
type PatchKey = ((u32, u32), bool);
/// The triangles between one pair of labels.
type PairTriangles = (PatchKey, Vec<[u32; 3]>);

/// Nodes joined by an edge shorter than `tol` become one node: an edge point
/// on a sample and the face or cell points clamped next to it (the inset
/// keeps them 1e-3 of a cell apart, which left 0.15° slivers that folded
/// over each other where the pin's rim lies on samples, 20³). The group
/// takes an edge point's position when it has one (that point is on the
/// surface). Triangles that collapse are dropped, so are pairs of one patch
/// that became the same triangle both ways round (a fin), and unused nodes
/// are removed (order kept).
fn merge_coincident(
    positions: &mut Vec<[f64; 3]>,
    edge_point: &[bool],
    pairs: &mut [PairTriangles],
    tol: f64,
) {
    let n = positions.len();
    let mut parent: Vec<u32> = (0..n as u32).collect();
    fn find(parent: &mut [u32], mut x: u32) -> u32 {
        while parent[x as usize] != x {
            x = parent[x as usize];
        }
        x
    }
    let mut any = false;
    for (_, tris) in pairs.iter() {
        for t in tris {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                let (pa, pb) = (positions[a as usize], positions[b as usize]);
                let d2: f64 = (0..3).map(|k| (pa[k] - pb[k]) * (pa[k] - pb[k])).sum();
                if d2 <= tol * tol {
                    let (ra, rb) = (find(&mut parent, a), find(&mut parent, b));
                    parent[ra.max(rb) as usize] = ra.min(rb);
                    any = true;
                }
            }
        }
    }
    if !any {
        return;
    }
    let root: Vec<u32> = (0..n as u32).map(|v| find(&mut parent, v)).collect();
    // The lowest-numbered edge point of each group gives its position.
    let mut placed = vec![false; n];
    for v in 0..n {
        let r = root[v] as usize;
        if edge_point.get(v).copied().unwrap_or(false) && !placed[r] {
            positions[r] = positions[v];
            placed[r] = true;
        }
    }
    let mut used = vec![false; n];
    for (_, tris) in pairs.iter_mut() {
        tris.retain_mut(|t| {
            *t = t.map(|v| root[v as usize]);
            t[0] != t[1] && t[1] != t[2] && t[0] != t[2]
        });
        drop_fins(tris);
        for t in tris.iter() {
            for &v in t {
                used[v as usize] = true;
            }
        }
    }
    let mut new_id = vec![u32::MAX; n];
    let mut kept = Vec::with_capacity(n);
    for (v, p) in positions.iter().enumerate() {
        if used[v] {
            new_id[v] = kept.len() as u32;
            kept.push(*p);
        }
    }
    *positions = kept;
    for (_, tris) in pairs.iter_mut() {
        for t in tris.iter_mut() {
            *t = t.map(|v| new_id[v as usize]);
        }
    }
}

/// Drops the triangle pairs that are one triangle both ways round.
fn drop_fins(tris: &mut Vec<[u32; 3]>) {
    let key = |t: &[u32; 3]| {
        let mut k = *t;
        k.sort_unstable();
        k
    };
    // Cyclic order of a sorted key: +1 when t runs like the key.
    let turn = |t: &[u32; 3]| {
        let k = t
            .iter()
            .position(|&v| v == t.iter().copied().min().unwrap_or(0));
        let k = k.unwrap_or(0);
        t[(k + 1) % 3] < t[(k + 2) % 3]
    };
    let mut seen: HashMap<[u32; 3], Vec<usize>> = HashMap::new();
    for (i, t) in tris.iter().enumerate() {
        seen.entry(key(t)).or_default().push(i);
    }
    let mut drop = vec![false; tris.len()];
    for ids in seen.values() {
        let (up, down): (Vec<usize>, Vec<usize>) = ids.iter().partition(|&&i| turn(&tris[i]));
        for (&a, &b) in up.iter().zip(&down) {
            drop[a] = true;
            drop[b] = true;
        }
    }
    if drop.iter().any(|&d| d) {
        let mut i = 0;
        tris.retain(|_| {
            i += 1;
            !drop[i - 1]
        });
    }
}

/// The unit gradient of f at p by central differences (zero where it is
/// not finite or vanishes).
fn unit_gradient(f: &Ssa, p: [f64; 3], spacing: f64) -> [f64; 3] {
    let h = spacing * 1e-4;
    let g: [f64; 3] = std::array::from_fn(|a| {
        let (mut up, mut down) = (p, p);
        up[a] += h;
        down[a] -= h;
        (f.eval_point(up) - f.eval_point(down)) / (2.0 * h)
    });
    let n = g.iter().map(|x| x * x).sum::<f64>().sqrt();
    if n.is_finite() && n > 0.0 {
        g.map(|x| x / n)
    } else {
        [0.0; 3]
    }
}

/// Dual contouring's point: the least-squares meeting point of the tangent
/// planes (point, unit normal) of the edge points, solved about their mean
/// with small eigenvalues dropped (a flat surface keeps the mean along
/// it, a crease or junction curve pulls the point onto the curve), kept in
/// the box [lo, hi].
fn qef_point(
    planes: &[([f64; 3], [f64; 3])],
    mean: [f64; 3],
    lo: [f64; 3],
    hi: [f64; 3],
) -> [f64; 3] {
    use nalgebra::{Matrix3, SymmetricEigen, Vector3};
    let mut ata = Matrix3::<f64>::zeros();
    let mut atb = Vector3::<f64>::zeros();
    for (p, n) in planes {
        let n = Vector3::from(*n);
        let d = n.dot(&(Vector3::from(*p) - Vector3::from(mean)));
        ata += n * n.transpose();
        atb += n * d;
    }
    let eig = SymmetricEigen::new(ata);
    let top = eig.eigenvalues.iter().fold(0.0f64, |m, &v| m.max(v.abs()));
    if !(top.is_finite() && top > 0.0) {
        return mean;
    }
    let mut x = Vector3::<f64>::zeros();
    for k in 0..3 {
        let v = eig.eigenvalues[k];
        if v.abs() > 0.1 * top {
            let e = eig.eigenvectors.column(k);
            x += e * (e.dot(&atb) / v);
        }
    }
    let q: [f64; 3] = std::array::from_fn(|a| (mean[a] + x[a]).clamp(lo[a], hi[a]));
    if q.iter().all(|c| c.is_finite()) {
        q
    } else {
        mean
    }
}

/// Newton steps from `p` towards f = 0 along the gradient, kept in the box
/// [lo, hi] (a face's box is flat along its normal, so the point stays on
/// the face); `p` itself when f is not finite there.
fn project(f: &Ssa, p: [f64; 3], lo: [f64; 3], hi: [f64; 3]) -> [f64; 3] {
    let size = (0..3).map(|a| hi[a] - lo[a]).fold(0.0, f64::max);
    let h = size * 1e-6;
    let mut q = p;
    for _ in 0..NEWTON_STEPS {
        let v = f.eval_point(q);
        let g: [f64; 3] = std::array::from_fn(|a| {
            if hi[a] == lo[a] {
                return 0.0;
            }
            let (mut up, mut down) = (q, q);
            up[a] += h;
            down[a] -= h;
            (f.eval_point(up) - f.eval_point(down)) / (2.0 * h)
        });
        let g2: f64 = g.iter().map(|x| x * x).sum();
        if !(v.is_finite() && g2.is_finite()) || g2 == 0.0 {
            return if v.is_finite() { q } else { p };
        }
        let next: [f64; 3] = std::array::from_fn(|a| (q[a] - v * g[a] / g2).clamp(lo[a], hi[a]));
        if next == q {
            break;
        }
        q = next;
    }
    if q.iter().all(|c| c.is_finite()) {
        q
    } else {
        p
    }
}

/// The root of `f` on the segment p0–p1 (f changes sign between them), by
/// Illinois false position; the midpoint without a function.
fn edge_root(f: Option<&Ssa>, p0: [f64; 3], p1: [f64; 3]) -> [f64; 3] {
    let lerp = |t: f64| std::array::from_fn(|a| p0[a] + t * (p1[a] - p0[a]));
    let Some(f) = f else {
        return lerp(0.5);
    };
    let (mut tl, mut tr) = (0.0, 1.0);
    let (mut fl, mut fr) = (f.eval_point(p0), f.eval_point(p1));
    if !(fl.is_finite() && fr.is_finite()) || (fl > 0.0) == (fr > 0.0) {
        return lerp(0.5);
    }
    let mut side = 0;
    let mut t = 0.5;
    for _ in 0..ROOT_ITERATIONS {
        let d = fr - fl;
        let guess = (tl * fr - tr * fl) / d;
        t = if d != 0.0 && guess.is_finite() {
            guess.clamp(tl, tr)
        } else {
            0.5 * (tl + tr)
        };
        let ft = f.eval_point(lerp(t));
        if ft == 0.0 || tr - tl < 1e-15 {
            break;
        }
        if (ft > 0.0) == (fl > 0.0) {
            tl = t;
            fl = ft;
            if side == -1 {
                fr *= 0.5;
            }
            side = -1;
        } else {
            tr = t;
            fr = ft;
            if side == 1 {
                fl *= 0.5;
            }
            side = 1;
        }
    }
    // On a sample within the snap tolerance, exactly on it.
    if t <= weld::SNAP {
        return p0;
    }
    if t >= 1.0 - weld::SNAP {
        return p1;
    }
    lerp(t)
}
