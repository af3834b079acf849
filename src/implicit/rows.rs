//! Row-separable evaluation of a function on grid rows (x varies along a
//! row, y and z are fixed), the fast path of grid sampling.
//!
//! Every instruction is classified by the coordinates it depends on:
//! - no x: evaluated once per row, as an f64 scalar (for a ball the y and z
//!   terms, for the gyroid all its sin/cos of y and z);
//! - x only: evaluated once per set of x coordinates, in f64, stored as f32
//!   lanes (the x terms, sin 6x, …);
//! - x and y or z: evaluated per row over f32 lanes, one tight loop per
//!   instruction that the compiler vectorises (AVX2 when the CPU has it).
//!
//! Why f32 lanes: samples only decide the inside/outside sign of grid points
//! and the first guess of each edge crossing; crossings are then refined on
//! the f64 tape (`tape::Tape`), so vertex accuracy does not depend on the
//! lanes. f32 doubles the lanes per vector and square roots are about twice
//! as fast per lane, and the grid takes half the memory. Add, subtract,
//! multiply, divide and square root are IEEE-exact operations, so results are
//! identical with or without AVX2 and for any thread count.

use super::ir::{Binary, Node, Unary, r_and, r_or};
use super::tape::{Ssa, children};

#[derive(Debug, Clone, Copy, PartialEq)]
enum Src {
    /// A lane slot.
    Lane(u32),
    /// A per-row scalar (index into the SSA values).
    Scalar(u32),
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Op {
    Unary(Unary),
    Binary(Binary),
    RvOr,
    RvAnd,
    ROr(f64),
    RAnd(f64),
}

#[derive(Debug, Clone, Copy, PartialEq)]
struct LaneInstr {
    op: Op,
    out: u32,
    a: Src,
    b: Src,
}

/// A program split into per-x, per-row and per-lane parts.
#[derive(Debug, Clone)]
pub struct RowTape {
    ssa: Ssa,
    /// SSA nodes evaluated once per row (no x dependency), in order.
    row_nodes: Vec<u32>,
    /// SSA nodes depending on x only, and the lane slot each is stored in.
    x_nodes: Vec<(u32, u32)>,
    lane: Vec<LaneInstr>,
    slots: usize,
    out: Src,
    /// Nodes that depend on no coordinate.
    consts_only: Vec<bool>,
}

/// Per-thread scratch: the lane slots, the x-only lanes for one set of x
/// coordinates, and the per-row scalars.
pub struct RowWorkspace {
    width: usize,
    lanes: Vec<f32>,
    scalars: Vec<f64>,
}

const X: u8 = 1;

impl RowTape {
    pub fn new(ssa: &Ssa) -> RowTape {
        let n = ssa.ops.len();
        let mut mask = vec![0u8; n];
        for (i, op) in ssa.ops.iter().enumerate() {
            mask[i] = match *op {
                Node::Var(a) => 1 << a,
                _ => children(op).fold(0, |m, c| m | mask[c as usize]),
            };
        }
        let mut last_use = vec![0usize; n];
        for (i, op) in ssa.ops.iter().enumerate() {
            for c in children(op) {
                last_use[c as usize] = i;
            }
        }
        let mut row_nodes = Vec::new();
        let mut x_nodes = Vec::new();
        let mut slot_of = vec![u32::MAX; n];
        let mut slots = 0u32;
        // x-only nodes get slots of their own (filled once per x set).
        for (i, &m) in mask.iter().enumerate() {
            if m == X {
                slot_of[i] = slots;
                x_nodes.push((i as u32, slots));
                slots += 1;
            } else if m & X == 0 {
                row_nodes.push(i as u32);
            }
        }
        let src = |i: u32, slot_of: &[u32]| {
            if mask[i as usize] & X == 0 {
                Src::Scalar(i)
            } else {
                Src::Lane(slot_of[i as usize])
            }
        };
        let mut free: Vec<u32> = Vec::new();
        let mut lane = Vec::new();
        for (i, op) in ssa.ops.iter().enumerate() {
            if mask[i] & X == 0 || mask[i] == X {
                continue;
            }
            let out = free.pop().unwrap_or_else(|| {
                slots += 1;
                slots - 1
            });
            let mut args = children(op).map(|c| src(c, &slot_of));
            let a = args.next().unwrap_or(Src::Lane(out));
            let b = args.next().unwrap_or(a);
            let op = match *op {
                Node::Unary(u, _) => Op::Unary(u),
                Node::Binary(bin, _, _) => Op::Binary(bin),
                Node::ROr(_, _, al) if f64::from_bits(al) == 0.0 => Op::RvOr,
                Node::RAnd(_, _, al) if f64::from_bits(al) == 0.0 => Op::RvAnd,
                Node::ROr(_, _, al) => Op::ROr(f64::from_bits(al)),
                Node::RAnd(_, _, al) => Op::RAnd(f64::from_bits(al)),
                Node::Const(_) | Node::Var(_) => unreachable!("constants have no x"),
            };
            lane.push(LaneInstr { op, out, a, b });
            slot_of[i] = out;
            // Free mixed operands at their last use, after allocating the
            // output so it never aliases an input.
            let mut freed = [u32::MAX; 2];
            for (k, c) in children(&ssa.ops[i]).enumerate() {
                let c = c as usize;
                let mixed = mask[c] & X != 0 && mask[c] != X;
                if mixed && last_use[c] == i && !freed.contains(&(c as u32)) {
                    free.push(slot_of[c]);
                }
                freed[k] = c as u32;
            }
        }
        let root = (n - 1) as u32;
        RowTape {
            out: src(root, &slot_of),
            ssa: ssa.clone(),
            row_nodes,
            x_nodes,
            lane,
            slots: slots as usize,
            consts_only: mask.iter().map(|&m| m == 0).collect(),
        }
    }

    /// Lane instructions per point (the per-row and per-x work is amortised).
    pub fn lane_len(&self) -> usize {
        self.lane.len()
    }

    /// A workspace for rows over the x coordinates `xs`.
    pub fn workspace(&self, xs: &[f64]) -> RowWorkspace {
        let width = xs.len().next_multiple_of(8);
        let mut ws = RowWorkspace {
            width,
            lanes: vec![0.0; self.slots.max(1) * width],
            scalars: vec![0.0; self.ssa.ops.len()],
        };
        // x-only nodes, evaluated in f64 point by point (after the
        // constants they may use).
        let mut vals = vec![0.0f64; self.ssa.ops.len()];
        for &i in &self.row_nodes {
            if self.consts_only[i as usize] {
                vals[i as usize] = eval_node(self.ssa.ops[i as usize], &vals);
            }
        }
        for (lane, &x) in xs.iter().enumerate() {
            for &(i, slot) in &self.x_nodes {
                let v = match self.ssa.ops[i as usize] {
                    Node::Var(_) => x,
                    op => eval_node(op, &vals),
                };
                vals[i as usize] = v;
                ws.lanes[slot as usize * width + lane] = v as f32;
            }
        }
        ws
    }

    /// f on the row (xs of the workspace, y, z) into `out` (one per x).
    pub fn eval_row(&self, ws: &mut RowWorkspace, y: f64, z: f64, out: &mut [f32]) {
        let s = &mut ws.scalars;
        for &i in &self.row_nodes {
            s[i as usize] = match self.ssa.ops[i as usize] {
                Node::Var(1) => y,
                Node::Var(_) => z,
                op => eval_node(op, s),
            };
        }
        run(&self.lane, ws);
        let n = out.len();
        match self.out {
            Src::Lane(slot) => {
                out.copy_from_slice(&ws.lanes[slot as usize * ws.width..][..n]);
            }
            Src::Scalar(i) => out.fill(ws.scalars[i as usize] as f32),
        }
    }
}

fn eval_node(op: Node, v: &[f64]) -> f64 {
    let g = |k: u32| v[k as usize];
    match op {
        Node::Const(bits) => f64::from_bits(bits),
        Node::Var(_) => unreachable!("coordinates are set by the caller"),
        Node::Unary(u, a) => u.apply(g(a)),
        Node::Binary(b, x, y) => b.apply(g(x), g(y)),
        Node::RAnd(x, y, a) => r_and(g(x), g(y), f64::from_bits(a)),
        Node::ROr(x, y, a) => r_or(g(x), g(y), f64::from_bits(a)),
    }
}

fn run(lane: &[LaneInstr], ws: &mut RowWorkspace) {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports AVX2 (checked just above).
            unsafe { run_avx2(lane, ws) };
            return;
        }
    }
    run_generic(lane, ws);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn run_avx2(lane: &[LaneInstr], ws: &mut RowWorkspace) {
    run_generic(lane, ws);
}

#[inline(always)]
fn run_generic(lane: &[LaneInstr], ws: &mut RowWorkspace) {
    let w = ws.width;
    for ins in lane {
        let (lo, hi) = ws.lanes.split_at_mut(ins.out as usize * w);
        let (o, rest) = hi.split_at_mut(w);
        let o: &mut [f32] = o;
        let pick = |s: Src| -> Result<&[f32], f32> {
            match s {
                Src::Lane(k) => {
                    let k = k as usize;
                    Ok(if k < ins.out as usize {
                        &lo[k * w..][..w]
                    } else {
                        &rest[(k - ins.out as usize - 1) * w..][..w]
                    })
                }
                Src::Scalar(i) => Err(ws.scalars[i as usize] as f32),
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

/// One lane loop with each operand either a lane slot (Ok) or a scalar (Err).
#[inline(always)]
fn each2(
    o: &mut [f32],
    a: Result<&[f32], f32>,
    b: Result<&[f32], f32>,
    f: impl Fn(f32, f32) -> f32,
) {
    match (a, b) {
        (Ok(a), Ok(b)) => {
            for ((o, &a), &b) in o.iter_mut().zip(a).zip(b) {
                *o = f(a, b);
            }
        }
        (Ok(a), Err(b)) => {
            for (o, &a) in o.iter_mut().zip(a) {
                *o = f(a, b);
            }
        }
        (Err(a), Ok(b)) => {
            for (o, &b) in o.iter_mut().zip(b) {
                *o = f(a, b);
            }
        }
        (Err(a), Err(b)) => o.fill(f(a, b)),
    }
}

#[inline(always)]
fn unary(u: Unary, o: &mut [f32], a: Result<&[f32], f32>) {
    let each = |o: &mut [f32], f: &dyn Fn(f32) -> f32| each2(o, a, Err(0.0), |x, _| f(x));
    match u {
        Unary::Neg => each2(o, a, Err(0.0), |x, _| -x),
        Unary::Square => each2(o, a, Err(0.0), |x, _| x * x),
        Unary::Sqrt => each2(o, a, Err(0.0), |x, _| x.sqrt()),
        Unary::Abs => each2(o, a, Err(0.0), |x, _| x.abs()),
        _ => each(o, &|x| u.apply(x as f64) as f32),
    }
}

#[inline(always)]
fn binary(bin: Binary, o: &mut [f32], a: Result<&[f32], f32>, b: Result<&[f32], f32>) {
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
    use crate::implicit::ir::Ctx;

    #[test]
    fn rows_match_scalar_evaluation_for_every_dependency_class() {
        let mut ctx = Ctx::new();
        let (x, y, z) = (ctx.var(0), ctx.var(1), ctx.var(2));
        let half = ctx.constant(0.5);
        let xh = ctx.sub(x, half);
        let sx = ctx.unary(Unary::Sin, xh);
        let cy = ctx.unary(Unary::Cos, y);
        let yz = ctx.mul(cy, z);
        let mixed = ctx.sub(sx, yz);
        let xx = ctx.square(x);
        let r = ctx.r_or(mixed, xx, 0.0);
        let q = ctx.r_and(r, yz, 0.5);
        let m = ctx.binary(Binary::Min, q, sx);
        let root = ctx.binary(Binary::Max, m, yz);
        let ssa = Ssa::from_ctx(&ctx, root);
        let tape = RowTape::new(&ssa);
        let xs: Vec<f64> = (0..37).map(|i| -1.0 + i as f64 * 0.055).collect();
        let mut ws = tape.workspace(&xs);
        let mut out = vec![0.0f32; xs.len()];
        for (y, z) in [(0.3, -0.2), (-0.9, 0.7), (0.0, 0.0)] {
            tape.eval_row(&mut ws, y, z, &mut out);
            for (i, &x) in xs.iter().enumerate() {
                let want = ssa.eval_point([x, y, z]);
                assert!(
                    (out[i] as f64 - want).abs() < 1e-5,
                    "{x} {y} {z}: {} vs {want}",
                    out[i]
                );
            }
        }
        // A function of y only fills the row with one value.
        let ssa = Ssa::from_ctx(&ctx, cy);
        let tape = RowTape::new(&ssa);
        let mut ws = tape.workspace(&xs);
        tape.eval_row(&mut ws, 0.5, 0.0, &mut out);
        assert!(out.iter().all(|&v| v == 0.5f64.cos() as f32));
    }
}
