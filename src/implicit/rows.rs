//! Row-separable evaluation of a function on grid rows (x varies along a
//! row, y and z are fixed), the fast path of grid sampling.
//!
//! Every instruction is classified by the coordinates it depends on:
//! - no x: evaluated once per row, as an f64 scalar (for a ball the y and z
//!   terms, for the gyroid all its sin/cos of y and z);
//! - x only: evaluated once per set of x coordinates, in f64, stored as f32
//!   lanes (the x terms, sin 6x, …);
//! - x and y or z: evaluated per row over f32 lanes, one tight loop per
//!   instruction that the compiler vectorises (AVX2 when the CPU has it);
//!   `lane ± row scalar` (a ball's y and z terms) is folded into the operand
//!   of the instruction that reads it, so M1's seven balls and six unions
//!   take six lane passes per row, not twenty.
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
pub(super) enum Src {
    /// A lane slot.
    Lane(u32),
    /// A lane slot plus two per-row offsets added in order, in f32
    /// (`RowWorkspace::offs[2k]`, `[2k + 1]`): the folded form of up to two
    /// additions or subtractions of per-row scalars (a ball's y and z terms).
    Shifted(u32, u32),
    /// A per-row scalar (index into the SSA values).
    Scalar(u32),
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Op {
    Unary(Unary),
    Binary(Binary),
    RvOr,
    RvAnd,
    ROr(f64),
    RAnd(f64),
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct LaneInstr {
    pub(super) op: Op,
    pub(super) out: u32,
    pub(super) a: Src,
    pub(super) b: Src,
}

/// One folded per-row term: the scalar node, negated for a subtraction.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Term {
    negate: bool,
    node: u32,
}

/// A program split into per-x, per-row and per-lane parts.
#[derive(Debug, Clone)]
pub struct RowTape {
    ssa: Ssa,
    /// SSA nodes with no x dependency, in order (constants included).
    row_nodes: Vec<u32>,
    /// Of those, the ones depending on z only, on y only, and on both y and
    /// z: re-evaluated when z changes, when y changes, and every row.
    z_nodes: Vec<u32>,
    y_nodes: Vec<u32>,
    yz_nodes: Vec<u32>,
    /// SSA nodes depending on x only, and the lane slot each is stored in.
    pub(super) x_nodes: Vec<(u32, u32)>,
    pub(super) lane: Vec<LaneInstr>,
    /// The terms of each `Src::Shifted` offset pair (None: −0.0, which adds
    /// exactly nothing, even to −0.0).
    shifts: Vec<[Option<Term>; 2]>,
    pub(super) slots: usize,
    pub(super) out: Src,
    /// Nodes that depend on no coordinate.
    consts_only: Vec<bool>,
}

/// Per-thread scratch: the lane slots, the x-only lanes for one set of x
/// coordinates, the per-row scalars and the per-row offsets.
pub struct RowWorkspace {
    pub(super) width: usize,
    pub(super) lanes: Vec<f32>,
    pub(super) scalars: Vec<f64>,
    pub(super) offs: Vec<f32>,
    /// The bits of the y and z the scalars were last evaluated at (a NaN's
    /// at first, so the first row evaluates everything).
    last_y: u64,
    last_z: u64,
    /// The y-only values of the first `Y_CACHE` ys seen: their bits, and
    /// per y the values of `y_nodes` in order. A block's rows take z in the
    /// outer loop and y in the inner one, so without them the y terms (the
    /// gyroid's sin 6y and cos 6y, libm calls) were evaluated for every row
    /// instead of once per y.
    y_seen: Vec<u64>,
    y_values: Vec<f64>,
}

/// The ys whose y-only values a workspace keeps (a block's rows).
const Y_CACHE: usize = 8;

const X: u8 = 1;

impl RowTape {
    pub fn new(ssa: &Ssa) -> RowTape {
        let n = ssa.ops.len();
        let root = n - 1;
        let mut mask = vec![0u8; n];
        let mut uses = vec![0u32; n];
        for (i, op) in ssa.ops.iter().enumerate() {
            mask[i] = match *op {
                Node::Var(a) => 1 << a,
                _ => children(op).fold(0, |m, c| m | mask[c as usize]),
            };
            for c in children(op) {
                uses[c as usize] += 1;
            }
        }
        let mixed = |i: usize| mask[i] & X != 0 && mask[i] != X;
        let lane_valued = |i: u32| mask[i as usize] & X != 0;
        let row_valued = |i: u32| mask[i as usize] & X == 0;
        // Fold `lane ± row scalar` (used once, by another lane instruction)
        // into its consumer's operand: a lane plus up to two offsets. The
        // consumer adds them in the same order and f32 rounding as the
        // instructions it replaces (a − s is exactly a + (−s)), so values are
        // bit-identical, and a ball's row costs one lane pass instead of three.
        let mut shift: Vec<Option<(u32, Vec<Term>)>> = vec![None; n];
        for (i, op) in ssa.ops.iter().enumerate() {
            if !mixed(i) || i == root || uses[i] != 1 {
                continue;
            }
            let (base, term) = match *op {
                Node::Binary(Binary::Add, a, b) if lane_valued(a) && row_valued(b) => (
                    a,
                    Term {
                        negate: false,
                        node: b,
                    },
                ),
                Node::Binary(Binary::Add, a, b) if row_valued(a) && lane_valued(b) => (
                    b,
                    Term {
                        negate: false,
                        node: a,
                    },
                ),
                Node::Binary(Binary::Sub, a, b) if lane_valued(a) && row_valued(b) => (
                    a,
                    Term {
                        negate: true,
                        node: b,
                    },
                ),
                _ => continue,
            };
            let (base, mut terms) = shift[base as usize].clone().unwrap_or((base, Vec::new()));
            if terms.len() < 2 {
                terms.push(term);
                shift[i] = Some((base, terms));
            }
        }
        // An operand as the instruction reading it sees it: the lane node it
        // reads (through any fold) and the fold.
        let resolve = |c: u32| match &shift[c as usize] {
            Some((base, _)) => *base,
            None => c,
        };
        let emitted = |i: usize| mixed(i) && shift[i].is_none();
        let mut last_use = vec![0usize; n];
        for (i, op) in ssa.ops.iter().enumerate() {
            if emitted(i) {
                for c in children(op) {
                    last_use[resolve(c) as usize] = i;
                }
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
        let mut shifts: Vec<[Option<Term>; 2]> = Vec::new();
        let mut src = |i: u32, slot_of: &[u32]| match &shift[i as usize] {
            Some((base, terms)) => {
                shifts.push([terms.first().copied(), terms.get(1).copied()]);
                Src::Shifted(slot_of[*base as usize], (shifts.len() - 1) as u32)
            }
            None if row_valued(i) => Src::Scalar(i),
            None => Src::Lane(slot_of[i as usize]),
        };
        let mut free: Vec<u32> = Vec::new();
        let mut lane = Vec::new();
        for (i, op) in ssa.ops.iter().enumerate() {
            if !emitted(i) {
                continue;
            }
            let out = free.pop().unwrap_or_else(|| {
                slots += 1;
                slots - 1
            });
            let kids: Vec<u32> = children(op).collect();
            let a = kids.first().map_or(Src::Lane(out), |&c| src(c, &slot_of));
            let b = kids.get(1).map_or(a, |&c| src(c, &slot_of));
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
            for (k, &c) in kids.iter().enumerate() {
                let c = resolve(c);
                if mixed(c as usize) && last_use[c as usize] == i && !freed.contains(&c) {
                    free.push(slot_of[c as usize]);
                }
                freed[k] = c;
            }
        }
        let out = src(root as u32, &slot_of);
        let only = |m: u8| -> Vec<u32> {
            row_nodes
                .iter()
                .copied()
                .filter(|&i| mask[i as usize] == m)
                .collect()
        };
        let (y_nodes, z_nodes, yz_nodes) = (only(2), only(4), only(6));
        RowTape {
            out,
            ssa: ssa.clone(),
            z_nodes,
            y_nodes,
            yz_nodes,
            row_nodes,
            x_nodes,
            lane,
            shifts,
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
            offs: vec![-0.0; 2 * self.shifts.len()],
            last_y: f64::NAN.to_bits(),
            last_z: f64::NAN.to_bits(),
            y_seen: Vec::new(),
            y_values: Vec::new(),
        };
        // x-only nodes, evaluated in f64 point by point (after the
        // constants they may use).
        let mut vals = vec![0.0f64; self.ssa.ops.len()];
        for &i in &self.row_nodes {
            if self.consts_only[i as usize] {
                vals[i as usize] = eval_node(self.ssa.ops[i as usize], &vals);
                ws.scalars[i as usize] = vals[i as usize];
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
        self.set_row(ws, y, z);
        run(&self.lane, ws);
        let n = out.len();
        match self.out {
            Src::Lane(slot) => {
                out.copy_from_slice(&ws.lanes[slot as usize * ws.width..][..n]);
            }
            Src::Shifted(slot, k) => {
                let (c1, c2) = (ws.offs[2 * k as usize], ws.offs[2 * k as usize + 1]);
                let lanes = &ws.lanes[slot as usize * ws.width..][..n];
                for (o, &v) in out.iter_mut().zip(lanes) {
                    *o = (v + c1) + c2;
                }
            }
            Src::Scalar(i) => out.fill(ws.scalars[i as usize] as f32),
        }
    }

    /// The per-row scalars and offsets of row (y, z) into the workspace.
    pub(super) fn set_row(&self, ws: &mut RowWorkspace, y: f64, z: f64) {
        // Constants were set by `workspace`; z-only and y-only terms only
        // change with z and y (a plane's rows share z).
        let eval = |s: &mut [f64], nodes: &[u32]| {
            for &i in nodes {
                s[i as usize] = match self.ssa.ops[i as usize] {
                    Node::Var(1) => y,
                    Node::Var(_) => z,
                    op => eval_node(op, s),
                };
            }
        };
        let s = &mut ws.scalars;
        if z.to_bits() != ws.last_z {
            eval(s, &self.z_nodes);
        }
        if y.to_bits() != ws.last_y {
            let count = self.y_nodes.len();
            match ws.y_seen.iter().position(|&b| b == y.to_bits()) {
                Some(c) => {
                    let seen = &ws.y_values[c * count..][..count];
                    for (&i, &v) in self.y_nodes.iter().zip(seen) {
                        s[i as usize] = v;
                    }
                }
                None => {
                    eval(s, &self.y_nodes);
                    if count > 0 && ws.y_seen.len() < Y_CACHE {
                        ws.y_seen.push(y.to_bits());
                        ws.y_values
                            .extend(self.y_nodes.iter().map(|&i| s[i as usize]));
                    }
                }
            }
        }
        eval(s, &self.yz_nodes);
        (ws.last_y, ws.last_z) = (y.to_bits(), z.to_bits());
        for (k, terms) in self.shifts.iter().enumerate() {
            for (t, term) in terms.iter().enumerate() {
                ws.offs[2 * k + t] = term.map_or(-0.0, |t| {
                    let v = ws.scalars[t.node as usize] as f32;
                    if t.negate { -v } else { v }
                });
            }
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

/// An operand of a lane loop.
#[derive(Clone, Copy)]
enum Opd<'a> {
    Lane(&'a [f32]),
    /// (lane + c1) + c2.
    Shifted(&'a [f32], f32, f32),
    Scalar(f32),
}

#[inline(always)]
fn run_generic(lane: &[LaneInstr], ws: &mut RowWorkspace) {
    let w = ws.width;
    for ins in lane {
        let (lo, hi) = ws.lanes.split_at_mut(ins.out as usize * w);
        let (o, rest) = hi.split_at_mut(w);
        let o: &mut [f32] = o;
        let slot = |k: u32| -> &[f32] {
            let k = k as usize;
            if k < ins.out as usize {
                &lo[k * w..][..w]
            } else {
                &rest[(k - ins.out as usize - 1) * w..][..w]
            }
        };
        let pick = |s: Src| -> Opd {
            match s {
                Src::Lane(k) => Opd::Lane(slot(k)),
                Src::Shifted(k, c) => {
                    let c = 2 * c as usize;
                    Opd::Shifted(slot(k), ws.offs[c], ws.offs[c + 1])
                }
                Src::Scalar(i) => Opd::Scalar(ws.scalars[i as usize] as f32),
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

/// One lane loop over `o` with each operand a lane slot, a shifted lane
/// slot or a scalar; monomorphised per combination so each is a plain loop
/// the compiler vectorises.
#[inline(always)]
fn each2(o: &mut [f32], a: Opd, b: Opd, f: impl Fn(f32, f32) -> f32) {
    let n = o.len();
    match a {
        Opd::Lane(a) => {
            let a = &a[..n];
            with_b(o, b, |i| a[i], f)
        }
        Opd::Shifted(a, c1, c2) => {
            let a = &a[..n];
            with_b(o, b, |i| (a[i] + c1) + c2, f)
        }
        Opd::Scalar(a) => match b {
            Opd::Scalar(b) => o.fill(f(a, b)),
            _ => with_b(o, b, |_| a, f),
        },
    }
}

// Index loops: the operand getter `ga` is indexed like `b`, one loop shape
// for every combination, which the compiler vectorises.
#[allow(clippy::needless_range_loop)]
#[inline(always)]
fn with_b(o: &mut [f32], b: Opd, ga: impl Fn(usize) -> f32, f: impl Fn(f32, f32) -> f32) {
    let n = o.len();
    match b {
        Opd::Lane(b) => {
            let b = &b[..n];
            for i in 0..n {
                o[i] = f(ga(i), b[i]);
            }
        }
        Opd::Shifted(b, c1, c2) => {
            let b = &b[..n];
            for i in 0..n {
                o[i] = f(ga(i), (b[i] + c1) + c2);
            }
        }
        Opd::Scalar(b) => {
            for (i, o) in o.iter_mut().enumerate() {
                *o = f(ga(i), b);
            }
        }
    }
}

#[inline(always)]
fn unary(u: Unary, o: &mut [f32], a: Opd) {
    let z = Opd::Scalar(0.0);
    match u {
        Unary::Neg => each2(o, a, z, |x, _| -x),
        Unary::Square => each2(o, a, z, |x, _| x * x),
        Unary::Sqrt => each2(o, a, z, |x, _| x.sqrt()),
        Unary::Abs => each2(o, a, z, |x, _| x.abs()),
        _ => each2(o, a, z, |x, _| u.apply(x as f64) as f32),
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

    #[test]
    fn remembered_y_terms_give_the_bits_of_a_fresh_workspace() {
        // z outer, y inner, as a block's rows, with more ys than the
        // workspace remembers: every row as from a workspace of its own.
        let mut ctx = Ctx::new();
        let g = gyroid(&mut ctx);
        let ssa = Ssa::from_ctx(&ctx, g);
        let tape = RowTape::new(&ssa);
        assert!(!tape.y_nodes.is_empty());
        let xs: Vec<f64> = (0..8).map(|i| -0.3 + i as f64 * 0.07).collect();
        let mut ws = tape.workspace(&xs);
        let (mut got, mut want) = (vec![0.0f32; 8], vec![0.0f32; 8]);
        let mut remembered = 0;
        for k in 0..3 {
            for j in 0..(Y_CACHE + 3) {
                let (y, z) = (0.1 * j as f64 - 0.4, 0.05 * k as f64);
                tape.eval_row(&mut ws, y, z, &mut got);
                tape.eval_row(&mut tape.workspace(&xs), y, z, &mut want);
                let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(&got), bits(&want), "row y {y}, z {z}");
                remembered = ws.y_seen.len();
            }
        }
        assert_eq!(remembered, Y_CACHE);
    }

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

    /// Folding a ball's y and z terms into the union's operands must give
    /// the very f32 bits of the unfolded instructions (f32 subtractions of
    /// the f64 row terms rounded to f32, in order).
    #[test]
    fn folded_ball_terms_are_bit_identical_to_the_unfolded_sequence() {
        let balls = [
            (0.7, [0.0, 0.0, 0.0]),
            (0.3, [0.7, 0.0, 0.0]),
            (0.3, [0.0, -0.7, 0.35]),
        ];
        let mut ctx = Ctx::new();
        let (x, y, z) = (ctx.var(0), ctx.var(1), ctx.var(2));
        let mut f = None;
        for (r, c) in balls {
            let rc = ctx.constant(r);
            let mut b = ctx.square(rc);
            for (v, c) in [x, y, z].into_iter().zip(c) {
                let c = ctx.constant(c);
                let d = ctx.sub(v, c);
                let s = ctx.square(d);
                b = ctx.sub(b, s);
            }
            f = Some(f.map_or(b, |acc| ctx.r_or(acc, b, 0.0)));
        }
        let ssa = Ssa::from_ctx(&ctx, f.expect("three balls"));
        let tape = RowTape::new(&ssa);
        assert_eq!(tape.lane_len(), 2, "two unions, the balls folded into them");
        let xs: Vec<f64> = (0..41).map(|i| -1.0 + i as f64 * 0.05).collect();
        let mut ws = tape.workspace(&xs);
        let mut out = vec![0.0f32; xs.len()];
        for (y, z) in [(0.0, 0.0), (0.3, -0.2), (-0.65, 0.35), (1.0, -1.0)] {
            tape.eval_row(&mut ws, y, z, &mut out);
            for (i, &x) in xs.iter().enumerate() {
                let ball = |(r, c): (f64, [f64; 3])| {
                    let xt = (r * r - (x - c[0]) * (x - c[0])) as f32;
                    let yt = ((y - c[1]) * (y - c[1])) as f32;
                    let zt = ((z - c[2]) * (z - c[2])) as f32;
                    (xt - yt) - zt
                };
                let or = |a: f32, b: f32| a + b + (a * a + b * b).sqrt();
                let want = or(or(ball(balls[0]), ball(balls[1])), ball(balls[2]));
                assert_eq!(out[i].to_bits(), want.to_bits(), "{x} {y} {z}");
            }
        }
    }
}
