//! A block's rows evaluated together: each lane instruction of a
//! [`RowTape`] runs once over all the rows of a block (up to 8 × 8 rows of 8
//! samples) instead of once per row.
//!
//! Why: a mixed block's rows are only 8 samples wide, one AVX2 vector, so
//! evaluated row by row the interpreter's per-instruction cost (dispatch,
//! operand slicing, loop set-up) was paid for every vector of arithmetic;
//! it was most of M2's sampling time. Here the per-row scalars and offsets
//! are gathered first (the same f64 values `eval_row` computes, rounded to
//! f32 as it does), then each instruction is one loop over the block's
//! rows. Every lane sees the same f32 operations in the same order as in
//! `eval_row`, so the samples are bit-identical (test
//! `block_rows_are_bit_identical_to_row_by_row`).

use super::ir::{Binary, Unary, r_and, r_or};
use super::rows::{LaneInstr, Op, RowTape, RowWorkspace, Src};

/// Samples per block row: the workspace's width for a block's xs.
const W: usize = 8;

/// `eval_block`'s scratch, reused by one thread from block to block (its
/// memory grows to the largest kernel and stays).
#[derive(Default)]
pub struct BlockScratch {
    /// Lane slot s of row r at `(s · rows + r) · W`.
    lanes: Vec<f32>,
    /// The per-row scalar operands: operand q of row r at `q · rows + r`.
    scalars: Vec<f32>,
    /// The per-row offsets: offset c of row r at `c · rows + r`.
    offs: Vec<f32>,
    /// The scalar nodes the lane instructions read, ascending.
    nodes: Vec<u32>,
}

impl RowTape {
    /// f on the rows (ys[j], zs[k]) over the workspace's xs (at most 8),
    /// sample i of row (j, k) into `out[(k · 8 + j) · 8 + i]` for i < `len`
    /// (a block's sample layout); `ws` is a workspace of this tape.
    ///
    /// # Panics
    /// If the workspace is wider than 8 samples or `out` shorter than the
    /// rows (a caller bug).
    pub fn eval_block(
        &self,
        ws: &mut RowWorkspace,
        scratch: &mut BlockScratch,
        ys: &[f64],
        zs: &[f64],
        len: usize,
        out: &mut [f32],
    ) {
        assert!(ws.width == W && len <= W && ys.len() <= W, "block rows");
        if ys.is_empty() || zs.is_empty() {
            return;
        }
        if let Src::Scalar(node) = self.out {
            // The root depends on no x: one value per row, as `eval_row`.
            for (k, &z) in zs.iter().enumerate() {
                for (j, &y) in ys.iter().enumerate() {
                    self.set_row(ws, y, z);
                    out[(k * W + j) * W..][..len].fill(ws.scalars[node as usize] as f32);
                }
            }
            return;
        }
        // Rows r = k · 8 + j; rows j ≥ ys.len() of a short block are
        // computed from stale scalars and never read.
        let rows = (zs.len() - 1) * W + ys.len();
        scratch.nodes.clear();
        for ins in &self.lane {
            for src in [ins.a, ins.b] {
                if let Src::Scalar(i) = src {
                    scratch.nodes.push(i);
                }
            }
        }
        scratch.nodes.sort_unstable();
        scratch.nodes.dedup();
        let stride = rows * W;
        grow(&mut scratch.lanes, self.slots.max(1) * stride);
        grow(&mut scratch.scalars, scratch.nodes.len() * rows);
        grow(&mut scratch.offs, ws.offs.len() * rows);
        for &(_, slot) in &self.x_nodes {
            let s = slot as usize;
            let (src, dst) = (&ws.lanes[s * W..][..W], &mut scratch.lanes[s * stride..]);
            for r in 0..rows {
                dst[r * W..][..W].copy_from_slice(src);
            }
        }
        for (k, &z) in zs.iter().enumerate() {
            for (j, &y) in ys.iter().enumerate() {
                self.set_row(ws, y, z);
                let r = k * W + j;
                for (q, &i) in scratch.nodes.iter().enumerate() {
                    scratch.scalars[q * rows + r] = ws.scalars[i as usize] as f32;
                }
                for (c, &o) in ws.offs.iter().enumerate() {
                    scratch.offs[c * rows + r] = o;
                }
            }
        }
        run(&self.lane, scratch, rows);
        for k in 0..zs.len() {
            for j in 0..ys.len() {
                let r = k * W + j;
                let row = &mut out[r * W..][..len];
                match self.out {
                    Src::Lane(slot) => {
                        row.copy_from_slice(
                            &scratch.lanes[slot as usize * stride + r * W..][..len],
                        );
                    }
                    Src::Shifted(slot, k) => {
                        let c = 2 * k as usize;
                        let (c1, c2) =
                            (scratch.offs[c * rows + r], scratch.offs[(c + 1) * rows + r]);
                        let lanes = &scratch.lanes[slot as usize * stride + r * W..][..len];
                        for (o, &v) in row.iter_mut().zip(lanes) {
                            *o = (v + c1) + c2;
                        }
                    }
                    Src::Scalar(_) => unreachable!("handled above"),
                }
            }
        }
    }
}

fn grow(v: &mut Vec<f32>, len: usize) {
    if v.len() < len {
        v.resize(len, 0.0);
    }
}

fn run(lane: &[LaneInstr], scratch: &mut BlockScratch, rows: usize) {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports AVX2 (checked just above).
            unsafe { run_avx2(lane, scratch, rows) };
            return;
        }
    }
    run_generic(lane, scratch, rows);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn run_avx2(lane: &[LaneInstr], scratch: &mut BlockScratch, rows: usize) {
    run_generic(lane, scratch, rows);
}

/// An operand over a block's rows.
#[derive(Clone, Copy)]
enum Opd<'a> {
    /// W lanes per row.
    Lane(&'a [f32]),
    /// (lane + c1[r]) + c2[r].
    Shifted(&'a [f32], &'a [f32], &'a [f32]),
    /// One value per row.
    Scalar(&'a [f32]),
}

#[inline(always)]
fn run_generic(lane: &[LaneInstr], scratch: &mut BlockScratch, rows: usize) {
    let stride = rows * W;
    let (nodes, scalars, offs) = (&scratch.nodes, &scratch.scalars, &scratch.offs);
    for ins in lane {
        let (lo, hi) = scratch.lanes.split_at_mut(ins.out as usize * stride);
        let (o, rest) = hi.split_at_mut(stride);
        let o: &mut [f32] = o;
        let slot = |k: u32| -> &[f32] {
            let k = k as usize;
            if k < ins.out as usize {
                &lo[k * stride..][..stride]
            } else {
                &rest[(k - ins.out as usize - 1) * stride..][..stride]
            }
        };
        let pick = |s: Src| -> Opd {
            match s {
                Src::Lane(k) => Opd::Lane(slot(k)),
                Src::Shifted(k, c) => {
                    let c = 2 * c as usize;
                    Opd::Shifted(
                        slot(k),
                        &offs[c * rows..][..rows],
                        &offs[(c + 1) * rows..][..rows],
                    )
                }
                Src::Scalar(i) => {
                    let q = nodes.partition_point(|&n| n < i);
                    Opd::Scalar(&scalars[q * rows..][..rows])
                }
            }
        };
        let (a, b) = (pick(ins.a), pick(ins.b));
        match ins.op {
            Op::Unary(u) => unary(u, o, a),
            Op::Binary(bin) => binary(bin, o, a, b),
            Op::RvOr => each2(o, a, b, |x, y| x + y + (x * x + y * y).sqrt()),
            Op::RvAnd => each2(o, a, b, |x, y| x + y - (x * x + y * y).sqrt()),
            Op::ROr(al) => each2(o, a, b, |x, y| r_or(x as f64, y as f64, al) as f32),
            Op::RAnd(al) => each2(o, a, b, |x, y| r_and(x as f64, y as f64, al) as f32),
        }
    }
}

/// Row r of a lane operand.
#[inline(always)]
fn row(s: &[f32], r: usize) -> [f32; W] {
    let mut v = [0.0; W];
    v.copy_from_slice(&s[r * W..][..W]);
    v
}

/// One loop over the rows with each operand a lane slot, a shifted lane
/// slot or a per-row scalar; monomorphised per combination, each row one
/// vector operation.
#[inline(always)]
fn each2(o: &mut [f32], a: Opd, b: Opd, f: impl Fn(f32, f32) -> f32) {
    match a {
        Opd::Lane(a) => with_b(o, b, |r| row(a, r), f),
        Opd::Shifted(a, c1, c2) => with_b(o, b, |r| row(a, r).map(|v| (v + c1[r]) + c2[r]), f),
        Opd::Scalar(a) => with_b(o, b, |r| [a[r]; W], f),
    }
}

#[inline(always)]
fn with_b(o: &mut [f32], b: Opd, ga: impl Fn(usize) -> [f32; W], f: impl Fn(f32, f32) -> f32) {
    let store = |o: &mut [f32], x: [f32; W], y: [f32; W]| {
        for ((o, x), y) in o.iter_mut().zip(x).zip(y) {
            *o = f(x, y);
        }
    };
    match b {
        Opd::Lane(b) => {
            for (r, o) in o.chunks_exact_mut(W).enumerate() {
                store(o, ga(r), row(b, r));
            }
        }
        Opd::Shifted(b, c1, c2) => {
            for (r, o) in o.chunks_exact_mut(W).enumerate() {
                store(o, ga(r), row(b, r).map(|v| (v + c1[r]) + c2[r]));
            }
        }
        Opd::Scalar(b) => {
            for (r, o) in o.chunks_exact_mut(W).enumerate() {
                store(o, ga(r), [b[r]; W]);
            }
        }
    }
}

#[inline(always)]
fn unary(u: Unary, o: &mut [f32], a: Opd) {
    match u {
        Unary::Neg => map1(o, a, |x| -x),
        Unary::Square => map1(o, a, |x| x * x),
        Unary::Sqrt => map1(o, a, |x| x.sqrt()),
        Unary::Abs => map1(o, a, |x| x.abs()),
        _ => map1(o, a, |x| u.apply(x as f64) as f32),
    }
}

#[inline(always)]
fn map1(o: &mut [f32], a: Opd, f: impl Fn(f32) -> f32) {
    let store = |o: &mut [f32], x: [f32; W]| {
        for (o, x) in o.iter_mut().zip(x) {
            *o = f(x);
        }
    };
    match a {
        Opd::Lane(a) => {
            for (r, o) in o.chunks_exact_mut(W).enumerate() {
                store(o, row(a, r));
            }
        }
        Opd::Shifted(a, c1, c2) => {
            for (r, o) in o.chunks_exact_mut(W).enumerate() {
                store(o, row(a, r).map(|v| (v + c1[r]) + c2[r]));
            }
        }
        Opd::Scalar(a) => {
            for (r, o) in o.chunks_exact_mut(W).enumerate() {
                store(o, [a[r]; W]);
            }
        }
    }
}

#[inline(always)]
fn binary(bin: Binary, o: &mut [f32], a: Opd, b: Opd) {
    match bin {
        Binary::Add => each2(o, a, b, |x, y| x + y),
        Binary::Sub => each2(o, a, b, |x, y| x - y),
        Binary::Mul => each2(o, a, b, |x, y| x * y),
        Binary::Div => each2(o, a, b, |x, y| x / y),
        Binary::Min => each2(o, a, b, |x, y| if x < y { x } else { y }),
        Binary::Max => each2(o, a, b, |x, y| if x > y { x } else { y }),
        _ => each2(o, a, b, |x, y| bin.apply(x as f64, y as f64) as f32),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::implicit::ir::{Ctx, gyroid};
    use crate::implicit::tape::Ssa;

    /// The gyroid in a ball with an Rvachev-joined ball (lane, shifted and
    /// per-row scalar operands, a root of x and of no x): a full block and
    /// short ones (1 × 3 × 2 rows, 5 samples wide) give each row's bits.
    #[test]
    fn block_rows_are_bit_identical_to_row_by_row() {
        let mut ctx = Ctx::new();
        let g = gyroid(&mut ctx);
        let ball = crate::implicit::vertices::tests::ball(&mut ctx, 0.8, [0.1, -0.2, 0.05]);
        let small = crate::implicit::vertices::tests::ball(&mut ctx, 0.3, [0.6, 0.0, 0.0]);
        let joined = ctx.r_or(ball, small, 0.0);
        let f = ctx.binary(Binary::Min, g, joined);
        let y = ctx.var(1);
        let y_only = ctx.unary(Unary::Cos, y);
        for root in [f, g, joined, y_only] {
            let tape = RowTape::new(&Ssa::from_ctx(&ctx, root));
            let mut scratch = BlockScratch::default();
            for (nx, ny, nz) in [(8, 8, 8), (5, 3, 2), (1, 8, 1), (8, 1, 8)] {
                let xs: Vec<f64> = (0..nx).map(|i| -0.4 + 0.09 * i as f64).collect();
                let ys: Vec<f64> = (0..ny).map(|j| 0.3 - 0.11 * j as f64).collect();
                let zs: Vec<f64> = (0..nz).map(|k| -0.7 + 0.13 * k as f64).collect();
                let mut got = vec![f32::NAN; W * W * W];
                let mut ws = tape.workspace(&xs);
                tape.eval_block(&mut ws, &mut scratch, &ys, &zs, nx, &mut got);
                let mut row_ws = tape.workspace(&xs);
                let mut want = vec![0.0f32; nx];
                for (k, &z) in zs.iter().enumerate() {
                    for (j, &y) in ys.iter().enumerate() {
                        tape.eval_row(&mut row_ws, y, z, &mut want);
                        let at = (k * W + j) * W;
                        let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                        assert_eq!(bits(&got[at..at + nx]), bits(&want), "row {j}, {k}");
                    }
                }
                // Samples past `len` and rows past the block are not written.
                assert!(got[nx..W].iter().all(|v| v.is_nan()) || nx == W);
            }
        }
    }
}
