//! The polygonizer's vertices: one per crossed grid edge, found from the
//! packed sign bits and placed by root finding on the owning block's
//! program (Illinois false position, f64).
//!
//! Why planes are refined together: a mixed block holds about 65 crossed
//! edges, 8 planes of them. Refined plane by plane, each call of the
//! interpreted f64 tape ran over 2–4 lanes, so the per-instruction overhead
//! (dispatch, slicing, small copies) cost more than the arithmetic. A run of
//! planes is refined kernel by kernel across all its planes (blocks with
//! equal programs share a kernel), so the batches are several times longer.
//! Every lane is computed independently and with the same block program, so
//! the vertices are bit-identical to refining each plane alone (test
//! `refining_planes_together_gives_the_same_vertices`).

use super::field::{BS, Block, Field, Kernel};
use super::polygonize::Options;
use super::signs::{self, SignRows};
use super::tape::{BATCH, Workspace};
use super::weld;
use std::ops::Range;

/// The crossed edges whose lower end lies in one z plane, and their vertices.
pub(super) struct PlaneVertices {
    /// (j · nx1 + i) · 3 + axis, ascending.
    pub keys: Vec<u32>,
    pub positions: Vec<[f64; 3]>,
    /// The grid sample each vertex sits on, or `weld::NONE`; empty when
    /// no vertex of the plane sits on a sample (the usual case).
    pub at_sample: Vec<u64>,
}

/// An edge's end points and the samples there.
type Ends = ([f64; 3], [f64; 3], f64, f64);

/// The vertices of plane k.
pub(super) fn plane_vertices(
    field: &Field,
    signs: &SignRows,
    coords: &[Vec<f64>; 3],
    k: usize,
    options: &Options,
) -> PlaneVertices {
    let mut one = planes_vertices(field, signs, coords, k..k + 1, options);
    one.pop().unwrap_or(PlaneVertices {
        keys: Vec::new(),
        positions: Vec::new(),
        at_sample: Vec::new(),
    })
}

/// The vertices of planes `ks`, one entry per plane, with the crossings of
/// all the planes refined kernel by kernel together.
pub(super) fn planes_vertices(
    field: &Field,
    signs: &SignRows,
    coords: &[Vec<f64>; 3],
    ks: Range<usize>,
    options: &Options,
) -> Vec<PlaneVertices> {
    let n1 = field.n1;
    // All the planes' edges in one list; plane p's are first[p]..first[p + 1].
    // Sized from the sign bits first: grown push by push, the lists were
    // copied and their fresh pages faulted in several times over.
    let total: usize = ks.clone().map(|k| count_crossed(signs, n1, k)).sum();
    let mut keys = Vec::with_capacity(total);
    let mut ends: Vec<Ends> = Vec::with_capacity(total);
    let mut first = Vec::with_capacity(ks.len() + 1);
    for k in ks.clone() {
        first.push(keys.len());
        crossed_edges(field, signs, coords, k, &mut keys, &mut ends);
    }
    first.push(keys.len());
    // Initial guess: linear interpolation of the samples.
    let mut t: Vec<f64> = ends
        .iter()
        .map(|&(_, _, v0, v1)| (v0 / (v0 - v1)).clamp(0.0, 1.0))
        .collect();
    refine_by_kernel(field, &ks, &first, &keys, &ends, &mut t, options);
    ks.enumerate()
        .map(|(p, k)| {
            let range = first[p]..first[p + 1];
            finish(n1, k, &keys[range.clone()], &ends[range.clone()], &t[range])
        })
        .collect()
}

/// The crossed x, y and z edges of word w of row j in plane k, as bit masks
/// over the row's samples (bits past the row are 0).
#[inline]
fn crossed_words(signs: &SignRows, n1: [usize; 3], j: usize, k: usize, w: usize) -> [u64; 3] {
    let r = signs.row(j, k);
    let ry = (j + 1 < n1[1]).then(|| signs.row(j + 1, k));
    let rz = (k + 1 < n1[2]).then(|| signs.row(j, k + 1));
    [
        (r[w] ^ signs::shifted(r, w)) & signs::low_bits(n1[0] - 1, w),
        ry.map_or(0, |q| r[w] ^ q[w]),
        rz.map_or(0, |q| r[w] ^ q[w]),
    ]
}

/// The number of crossed edges whose lower end lies in plane k.
fn count_crossed(signs: &SignRows, n1: [usize; 3], k: usize) -> usize {
    (0..n1[1])
        .flat_map(|j| (0..signs.words).map(move |w| (j, w)))
        .map(|(j, w)| {
            let c = crossed_words(signs, n1, j, k, w);
            (c[0].count_ones() + c[1].count_ones() + c[2].count_ones()) as usize
        })
        .sum()
}

/// Appends plane k's crossed edges (keys ascending) and their end samples.
fn crossed_edges(
    field: &Field,
    signs: &SignRows,
    coords: &[Vec<f64>; 3],
    k: usize,
    keys: &mut Vec<u32>,
    ends: &mut Vec<Ends>,
) {
    let n1 = field.n1;
    for j in 0..n1[1] {
        // Crossed edges from the sign bits: x edges within the row, y and z
        // edges against the next row and plane.
        for w in 0..signs.words {
            let crossed = crossed_words(signs, n1, j, k, w);
            for i in signs::bits(crossed[0] | crossed[1] | crossed[2], w) {
                let v0 = field.value(i, j, k) as f64;
                let bit = 1u64 << (i % 64);
                for (axis, (ii, jj, kk)) in [(i + 1, j, k), (i, j + 1, k), (i, j, k + 1)]
                    .into_iter()
                    .enumerate()
                {
                    if crossed[axis] & bit == 0 {
                        continue;
                    }
                    let v1 = field.value(ii, jj, kk) as f64;
                    keys.push(((j * n1[0] + i) * 3 + axis) as u32);
                    ends.push((
                        [coords[0][i], coords[1][j], coords[2][k]],
                        [coords[0][ii], coords[1][jj], coords[2][kk]],
                        v0,
                        v1,
                    ));
                }
            }
        }
    }
}

/// Refines the crossings with their owning blocks' programs, grouped by
/// kernel (a counting sort: a comparison sort of the edges cost more than
/// the root finding). Blocks with equal programs share a kernel, so their
/// edges run in one batch: a block alone has about 20 edges per axis, and
/// the interpreted tape's per-call cost was then larger than the
/// arithmetic. Every lane is independent, so the grouping does not change
/// any vertex.
fn refine_by_kernel(
    field: &Field,
    ks: &Range<usize>,
    first: &[usize],
    keys: &[u32],
    ends: &[Ends],
    t: &mut [f64],
    options: &Options,
) {
    let (n1, nb) = (field.n1, field.nb);
    if ks.is_empty() || field.kernels.is_empty() {
        // Given samples (no kernel): nothing to refine.
        return;
    }
    let last = ks.end - 1;
    // The block layers the planes lie in.
    let layers = ks.start / BS..last / BS + 1;
    let per_layer = nb[0] * nb[1];
    let blocks = &field.blocks[layers.start * per_layer..layers.end * per_layer];
    // Each edge's bucket, kernel id · 3 + axis (the axis tapes take one
    // axis at a time), `none` for edges of proven blocks (their linear
    // guess stays).
    let none = field.kernels.len() as u32 * 3;
    let mut bucket_of = Vec::with_capacity(keys.len());
    for (p, k) in ks.clone().enumerate() {
        let layer = (k / BS - layers.start) * per_layer;
        bucket_of.extend(keys[first[p]..first[p + 1]].iter().map(|&key| {
            let (key, axis) = (key as usize / 3, key % 3);
            let b = layer + (key / n1[0] / BS) * nb[0] + (key % n1[0]) / BS;
            match &blocks[b] {
                Block::Mixed(kernel) => kernel.id * 3 + axis,
                _ => none,
            }
        }));
    }
    let mut start = vec![0u32; none as usize + 2];
    for &id in &bucket_of {
        start[id as usize + 1] += 1;
    }
    for id in 0..=none as usize {
        start[id + 1] += start[id];
    }
    let mut order = vec![0usize; keys.len()];
    let mut next = start.clone();
    for (e, &id) in bucket_of.iter().enumerate() {
        order[next[id as usize] as usize] = e;
        next[id as usize] += 1;
    }
    let mut ws = Workspace::default();
    for (id, kernel) in field.kernels.iter().enumerate() {
        let axes: [&[usize]; 3] =
            [0, 1, 2].map(|a| &order[start[id * 3 + a] as usize..start[id * 3 + a + 1] as usize]);
        if axes.iter().any(|e| !e.is_empty()) {
            refine(kernel, &mut ws, axes, ends, t, options.iterations);
        }
    }
}

/// Plane k's vertices from its refined crossings: those within
/// `weld::SNAP` of a sample sit exactly on it (and are merged into one node
/// by `weld`).
fn finish(n1: [usize; 3], k: usize, keys: &[u32], ends: &[Ends], t: &[f64]) -> PlaneVertices {
    let plane = n1[0] * n1[1];
    let snapped = t.iter().any(|&t| t <= weld::SNAP || t >= 1.0 - weld::SNAP);
    let at_sample = keys
        .iter()
        .take(if snapped { keys.len() } else { 0 })
        .zip(t)
        .map(|(&key, &t)| {
            let base = (key / 3) as usize;
            let end = match key % 3 {
                0 => base + 1,
                1 => base + n1[0],
                _ => base + plane,
            };
            if t <= weld::SNAP {
                (k * plane + base) as u64
            } else if t >= 1.0 - weld::SNAP {
                (k * plane + end) as u64
            } else {
                weld::NONE
            }
        })
        .collect();
    let positions = ends
        .iter()
        .zip(t)
        .map(|(&(p0, p1, _, _), &t)| {
            if t <= weld::SNAP {
                return p0;
            }
            if t >= 1.0 - weld::SNAP {
                return p1;
            }
            [0, 1, 2].map(|a| {
                if p0[a] == p1[a] {
                    p0[a]
                } else {
                    p0[a] + t * (p1[a] - p0[a])
                }
            })
        })
        .collect();
    PlaneVertices {
        keys: keys.to_vec(),
        positions,
        at_sample,
    }
}

/// Refines one kernel's crossed edges (`axes[a]`: those along axis a,
/// indices into `ends` and `t`). Edges are evaluated on the kernel's axis
/// tapes, so the terms constant along an edge are computed once per edge
/// instead of at every step; the values, and so the vertices, are
/// bit-identical to the plain tape's. Coordinates that `p + 0.0` would
/// change (−0.0, NaN) or that are infinite take the plain tape.
fn refine(
    kernel: &Kernel,
    ws: &mut Workspace,
    axes: [&[usize]; 3],
    ends: &[Ends],
    t: &mut [f64],
    iterations: usize,
) {
    let plain = |c: f64| c.is_finite() && (c + 0.0).to_bits() == c.to_bits();
    let all = || axes.iter().flat_map(|e| e.iter());
    if !all().all(|&e| ends[e].0.iter().all(|&c| plain(c))) {
        let mut ws = kernel.tape.workspace();
        let edges: Vec<usize> = all().copied().collect();
        for chunk in edges.chunks(BATCH) {
            let eval_at = |s: &[f64], out: &mut [f64]| {
                let [xs, ys, zs] = [0, 1, 2].map(|a| {
                    let mut c = [0.0; BATCH];
                    for ((c, &e), &s) in c.iter_mut().zip(chunk).zip(s) {
                        let (p0, p1, _, _) = ends[e];
                        *c = p0[a] + s * (p1[a] - p0[a]);
                    }
                    c
                });
                let n = chunk.len();
                kernel.tape.eval(&mut ws, &xs[..n], &ys[..n], &zs[..n], out);
            };
            illinois(chunk, ends, t, iterations, eval_at);
        }
        return;
    }
    // Scratch reused by every chunk (zeroing fresh 1 kB arrays per call cost
    // as much as a short batch's arithmetic).
    let (mut fixed, mut coord) = ([[0.0; BATCH]; 3], [0.0; BATCH]);
    let (mut base, mut span) = ([0.0; BATCH], [0.0; BATCH]);
    for (axis, (along, group)) in kernel.along.iter().zip(axes).enumerate() {
        if group.is_empty() {
            continue;
        }
        along.prepare(ws, group.len().min(BATCH));
        for chunk in group.chunks(BATCH) {
            let n = chunk.len();
            for (m, &e) in chunk.iter().enumerate() {
                let (p0, p1, _, _) = ends[e];
                for (b, fixed) in fixed.iter_mut().enumerate() {
                    fixed[m] = p0[b];
                }
                // The point at s is base + s · span, as p0 + s · (p1 − p0).
                (base[m], span[m]) = (p0[axis], p1[axis] - p0[axis]);
            }
            along.setup(ws, [&fixed[0][..n], &fixed[1][..n], &fixed[2][..n]]);
            let eval_at = |s: &[f64], out: &mut [f64]| {
                for m in 0..s.len() {
                    coord[m] = base[m] + s[m] * span[m];
                }
                along.eval(ws, &coord[..n], out);
            };
            illinois(chunk, ends, t, iterations, eval_at);
        }
    }
}

/// Illinois false position on each edge, batched: `eval_at(s, out)` gives f
/// at parameter s[m] along edge `edges[m]`.
fn illinois(
    edges: &[usize],
    ends: &[Ends],
    t: &mut [f64],
    iterations: usize,
    mut eval_at: impl FnMut(&[f64], &mut [f64]),
) {
    // At most BATCH edges (callers chunk): working arrays on the stack.
    let n = edges.len().min(BATCH);
    let (mut tl, mut tr) = ([0.0; BATCH], [1.0; BATCH]);
    let (mut fl, mut fr) = ([0.0; BATCH], [0.0; BATCH]);
    eval_at(&tl[..n], &mut fl[..n]);
    eval_at(&tr[..n], &mut fr[..n]);
    // Edges whose exact end values do not bracket (a capped box sample, a
    // pruned neighbour) keep the linear guess.
    let mut ok = [false; BATCH];
    for m in 0..n {
        let (_, _, v0, v1) = ends[edges[m]];
        ok[m] = (fl[m] > 0.0) == (v0 > 0.0)
            && (fr[m] > 0.0) == (v1 > 0.0)
            && (fl[m] > 0.0) != (fr[m] > 0.0);
    }
    // The side each lane's last step replaced: −1 left, 1 right, 0 none yet.
    let mut side = [0.0; BATCH];
    let mut s = [0.0; BATCH];
    for m in 0..n {
        s[m] = t[edges[m]];
    }
    let mut fs = [0.0; BATCH];
    for _ in 0..iterations {
        for m in 0..n {
            let d = fr[m] - fl[m];
            let guess = (tl[m] * fr[m] - tr[m] * fl[m]) / d;
            // A function that is NaN somewhere (sqrt of a negative, 0/0) must not
            // poison the bracket: bisect instead, so tl and tr stay finite.
            s[m] = if d != 0.0 && guess.is_finite() {
                guess.max(tl[m]).min(tr[m])
            } else {
                0.5 * (tl[m] + tr[m])
            };
        }
        eval_at(&s[..n], &mut fs[..n]);
        // Selects, not branches (the side taken is data, about a coin flip
        // per lane): the step replaces the end of f's sign and halves the
        // other end's value when that end was kept twice in a row.
        for m in 0..n {
            let left = (fs[m] > 0.0) == (fl[m] > 0.0);
            let halved_l = if side[m] == 1.0 { fl[m] * 0.5 } else { fl[m] };
            let halved_r = if side[m] == -1.0 { fr[m] * 0.5 } else { fr[m] };
            tl[m] = if left { s[m] } else { tl[m] };
            tr[m] = if left { tr[m] } else { s[m] };
            fl[m] = if left { fs[m] } else { halved_l };
            fr[m] = if left { halved_r } else { fs[m] };
            side[m] = if left { -1.0 } else { 1.0 };
        }
    }
    for m in 0..n {
        if ok[m] {
            t[edges[m]] = s[m];
        }
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::implicit::field::sample_field;
    use crate::implicit::ir::{Binary, Ctx, NodeId};
    use crate::implicit::library;
    use crate::implicit::polygonize::Grid;
    use crate::implicit::rfs::RSystem;
    use crate::implicit::tape::Ssa;

    /// Paper 001's `Ball` of radius r about c (Rvachev's system).
    pub(in crate::implicit) fn ball(ctx: &mut Ctx, r: f64, c: [f64; 3]) -> NodeId {
        let args = [
            ctx.var(0),
            ctx.var(1),
            ctx.var(2),
            ctx.constant(r),
            ctx.constant(c[0]),
            ctx.constant(c[1]),
            ctx.constant(c[2]),
        ];
        let lib = library::lookup("Ball").expect("Ball is in the library");
        (lib.build)(ctx, RSystem::Rvachev, &args).expect("Ball builds")
    }

    /// Three Rvachev-joined balls and a max-joined one (both kinds of
    /// per-block simplification).
    fn model() -> Ssa {
        let mut ctx = Ctx::new();
        let mut f = ball(&mut ctx, 0.6, [0.0; 3]);
        for c in [[0.6, 0.0, 0.1], [-0.1, -0.6, 0.0]] {
            let b = ball(&mut ctx, 0.3, c);
            f = ctx.r_or(f, b, 0.0);
        }
        let b = ball(&mut ctx, 0.25, [0.1, 0.2, 0.65]);
        f = ctx.binary(Binary::Max, f, b);
        Ssa::from_ctx(&ctx, f)
    }

    #[test]
    fn refining_planes_together_gives_the_same_vertices() {
        let grid = Grid {
            min: [-1.0; 3],
            max: [1.0; 3],
            cells: [37, 30, 45],
        };
        let field = sample_field(&model(), &grid, &Options::default());
        let signs = field.signs();
        let coords = [0, 1, 2].map(|a| grid.coords(a));
        let options = Options::default();
        let alone: Vec<PlaneVertices> = (0..=45)
            .map(|k| plane_vertices(&field, &signs, &coords, k, &options))
            .collect();
        let crossed: usize = alone.iter().map(|p| p.keys.len()).sum();
        assert!(crossed > 2_000, "{crossed} crossed edges");
        // Runs within one block layer, across layers, and the whole grid.
        for ks in [3..7, 5..20, 0..46, 44..46] {
            let together = planes_vertices(&field, &signs, &coords, ks.clone(), &options);
            assert_eq!(together.len(), ks.len());
            for (p, k) in together.iter().zip(ks) {
                let a = &alone[k];
                assert_eq!(p.keys, a.keys, "plane {k}");
                assert_eq!(p.at_sample, a.at_sample, "plane {k}");
                let bits = |v: &[[f64; 3]]| -> Vec<[u64; 3]> {
                    v.iter().map(|q| q.map(f64::to_bits)).collect()
                };
                assert_eq!(bits(&p.positions), bits(&a.positions), "plane {k}");
            }
        }
    }
}
