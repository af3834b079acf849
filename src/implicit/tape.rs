//! A flat evaluation tape: the reachable nodes of one function in SSA order
//! ([`Ssa`]), register-allocated into a few slots ([`Tape`]), evaluated over
//! batches of points laid out coordinate stream by coordinate stream (x[],
//! y[], z[]), so each instruction is one tight loop the compiler vectorises.

use super::ir::{Binary, Ctx, Node, NodeId, Unary, r_and, r_or};

/// Points per batch: small enough that the live slots stay in L1.
pub const BATCH: usize = 128;

/// The reachable part of a function, renumbered densely; children refer to
/// earlier indices; the last entry is the root.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct Ssa {
    pub ops: Vec<Node>,
}

impl Ssa {
    pub fn from_ctx(ctx: &Ctx, root: NodeId) -> Ssa {
        let n = root as usize + 1;
        let mut live = vec![false; n];
        live[root as usize] = true;
        for i in (0..n).rev() {
            if live[i] {
                for c in children(&ctx.nodes[i]) {
                    live[c as usize] = true;
                }
            }
        }
        let mut renumber = vec![u32::MAX; n];
        let mut ops = Vec::new();
        for i in 0..n {
            if live[i] {
                renumber[i] = ops.len() as u32;
                ops.push(remap(ctx.nodes[i], &renumber));
            }
        }
        Ssa { ops }
    }

    pub fn root(&self) -> usize {
        self.ops.len() - 1
    }

    /// Evaluates at one point (for tests and scalar uses).
    pub fn eval_point(&self, p: [f64; 3]) -> f64 {
        let mut v = vec![0.0; self.ops.len()];
        for (i, op) in self.ops.iter().enumerate() {
            v[i] = match *op {
                Node::Const(bits) => f64::from_bits(bits),
                Node::Var(axis) => p[axis as usize],
                Node::Unary(u, a) => u.apply(v[a as usize]),
                Node::Binary(b, x, y) => b.apply(v[x as usize], v[y as usize]),
                Node::RAnd(x, y, a) => r_and(v[x as usize], v[y as usize], f64::from_bits(a)),
                Node::ROr(x, y, a) => r_or(v[x as usize], v[y as usize], f64::from_bits(a)),
            };
        }
        v[self.root()]
    }
}

pub fn children(node: &Node) -> impl Iterator<Item = NodeId> {
    let (a, b) = match *node {
        Node::Const(_) | Node::Var(_) => (None, None),
        Node::Unary(_, a) => (Some(a), None),
        Node::Binary(_, a, b) | Node::RAnd(a, b, _) | Node::ROr(a, b, _) => (Some(a), Some(b)),
    };
    a.into_iter().chain(b)
}

/// The node with its children renumbered through `map`.
pub fn remap(node: Node, map: &[u32]) -> Node {
    let m = |i: NodeId| map[i as usize];
    match node {
        Node::Const(_) | Node::Var(_) => node,
        Node::Unary(u, a) => Node::Unary(u, m(a)),
        Node::Binary(b, x, y) => Node::Binary(b, m(x), m(y)),
        Node::RAnd(x, y, a) => Node::RAnd(m(x), m(y), a),
        Node::ROr(x, y, a) => Node::ROr(m(x), m(y), a),
    }
}

/// For each node, the index of the later `cos` of its argument when it is a
/// `sin`, or of the later `sin` when it is a `cos`: the tapes compute such a
/// pair with one [`Op::SinCos`] at the first of the two. The IR is
/// hash-consed, so an argument has at most one of each.
fn sin_cos_partners(ssa: &Ssa) -> Vec<Option<u32>> {
    let mut partner = vec![None; ssa.ops.len()];
    let mut seen: std::collections::HashMap<(bool, NodeId), usize> = Default::default();
    for (i, op) in ssa.ops.iter().enumerate() {
        let (is_sin, arg) = match *op {
            Node::Unary(Unary::Sin, a) => (true, a),
            Node::Unary(Unary::Cos, a) => (false, a),
            _ => continue,
        };
        match seen.get(&(!is_sin, arg)) {
            Some(&first) if partner[first].is_none() => partner[first] = Some(i as u32),
            _ => {
                seen.insert((is_sin, arg), i);
            }
        }
    }
    partner
}

/// The instruction computing a node into slot `out`; `second` is the slot
/// of its sin/cos partner, allocated together with `out` (the pair becomes
/// one `SinCos`).
fn instruction(op: &Node, out: u32, slot_of: &[u32], second: Option<u32>) -> Instr {
    let mut args = children(op);
    let a = args.next().map_or(out, |c| slot_of[c as usize]);
    let b = args.next().map_or(a, |c| slot_of[c as usize]);
    match (op, second) {
        (Node::Unary(Unary::Sin, _), Some(cos)) => Instr {
            op: Op::SinCos,
            out,
            a,
            b: cos,
        },
        (Node::Unary(Unary::Cos, _), Some(sin)) => Instr {
            op: Op::SinCos,
            out: sin,
            a,
            b: out,
        },
        _ => Instr {
            op: op_of(op),
            out,
            a,
            b,
        },
    }
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Op {
    Unary(Unary),
    Binary(Binary),
    /// R_α conjunction/disjunction with α = 0 (Rvachev), the common case.
    RvAnd,
    RvOr,
    RAnd(f64),
    ROr(f64),
    /// sin and cos of the same argument in one pass (`trig::sin_cos_lanes`):
    /// the sine goes to `out`, the cosine to `b`.
    SinCos,
}

#[derive(Debug, Clone, Copy, PartialEq)]
struct Instr {
    op: Op,
    out: u32,
    a: u32,
    b: u32,
}

/// A register-allocated program: constants and coordinates live in fixed
/// slots; operation results reuse slots freed after their last use.
#[derive(Debug, Clone, PartialEq)]
pub struct Tape {
    instrs: Vec<Instr>,
    consts: Vec<(u32, f64)>,
    vars: [Option<u32>; 3],
    slots: usize,
    out: u32,
}

impl Tape {
    pub fn new(ssa: &Ssa) -> Tape {
        let n = ssa.ops.len();
        let mut last_use = vec![usize::MAX; n];
        for (i, op) in ssa.ops.iter().enumerate() {
            for c in children(op) {
                last_use[c as usize] = i;
            }
        }
        let mut slot_of = vec![0u32; n];
        let mut fixed = vec![false; n];
        let mut free: Vec<u32> = Vec::new();
        let mut slots = 0u32;
        let mut consts = Vec::new();
        let mut vars = [None; 3];
        let mut instrs = Vec::new();
        let partner = sin_cos_partners(ssa);
        // Nodes already computed by their partner's `SinCos`.
        let mut paired = vec![false; n];
        // Constants and coordinates get slots of their own, never reused:
        // their values are written before the instructions run.
        let mut alloc = |free: &mut Vec<u32>, fresh: bool| {
            let reused = if fresh { None } else { free.pop() };
            reused.unwrap_or_else(|| {
                slots += 1;
                slots - 1
            })
        };
        for (i, op) in ssa.ops.iter().enumerate() {
            let out = match *op {
                Node::Const(bits) => {
                    let s = alloc(&mut free, true);
                    consts.push((s, f64::from_bits(bits)));
                    fixed[i] = true;
                    s
                }
                Node::Var(axis) => {
                    let s = alloc(&mut free, true);
                    vars[axis as usize] = Some(s);
                    fixed[i] = true;
                    s
                }
                _ if paired[i] => slot_of[i],
                _ => {
                    let s = alloc(&mut free, false);
                    let second = partner[i].map(|j| {
                        let t = alloc(&mut free, false);
                        slot_of[j as usize] = t;
                        paired[j as usize] = true;
                        t
                    });
                    instrs.push(instruction(op, s, &slot_of, second));
                    s
                }
            };
            slot_of[i] = out;
            // Free operands whose last use is this instruction (after allocating
            // the output, so an output never aliases an input).
            let mut seen = [u32::MAX; 2];
            for (k, c) in children(op).enumerate() {
                let c = c as usize;
                if last_use[c] == i && !fixed[c] && !seen.contains(&(c as u32)) {
                    free.push(slot_of[c]);
                }
                seen[k] = c as u32;
            }
        }
        Tape {
            instrs,
            consts,
            vars,
            slots: slots as usize,
            out: slot_of[n - 1],
        }
    }

    pub fn from_ctx(ctx: &Ctx, root: NodeId) -> Tape {
        Tape::new(&Ssa::from_ctx(ctx, root))
    }

    /// Instructions (excluding constants and coordinates).
    pub fn len(&self) -> usize {
        self.instrs.len()
    }

    pub fn is_empty(&self) -> bool {
        self.instrs.is_empty()
    }

    /// Working memory for evaluating this tape, reusable across calls.
    pub fn workspace(&self) -> Workspace {
        let mut buf = vec![0.0; self.slots.max(1) * BATCH];
        for &(s, v) in &self.consts {
            buf[s as usize * BATCH..][..BATCH].fill(v);
        }
        Workspace { buf }
    }

    /// Evaluates f at the points (xs[i], ys[i], zs[i]) into `out`.
    pub fn eval(&self, ws: &mut Workspace, xs: &[f64], ys: &[f64], zs: &[f64], out: &mut [f64]) {
        let n = out.len();
        let mut start = 0;
        while start < n {
            let len = (n - start).min(BATCH);
            for (axis, src) in [xs, ys, zs].into_iter().enumerate() {
                if let Some(s) = self.vars[axis] {
                    let dst = &mut ws.buf[s as usize * BATCH..][..BATCH];
                    dst[..len].copy_from_slice(&src[start..start + len]);
                }
            }
            self.run(&mut ws.buf, len);
            out[start..start + len].copy_from_slice(&ws.buf[self.out as usize * BATCH..][..len]);
            start += len;
        }
    }

    fn run(&self, buf: &mut [f64], len: usize) {
        run(&self.instrs, buf, len);
    }
}

/// Runs the instructions over the first `len` lanes (a short last batch
/// or a small group of edges must not pay for a full batch).
fn run(instrs: &[Instr], buf: &mut [f64], len: usize) {
    {
        for ins in instrs {
            if matches!(ins.op, Op::SinCos) {
                sin_cos(buf, ins, len);
                continue;
            }
            let (o, a, b) = io(buf, ins.out as usize, ins.a as usize, ins.b as usize);
            let (o, a, b) = (&mut o[..len], &a[..len], &b[..len]);
            match ins.op {
                Op::Unary(u) => unary(u, o, a),
                Op::Binary(bin) => binary(bin, o, a, b),
                Op::RvAnd => {
                    for i in 0..len {
                        o[i] = a[i] + b[i] - (a[i] * a[i] + b[i] * b[i]).sqrt();
                    }
                }
                Op::RvOr => {
                    for i in 0..len {
                        o[i] = a[i] + b[i] + (a[i] * a[i] + b[i] * b[i]).sqrt();
                    }
                }
                Op::RAnd(al) => {
                    for i in 0..len {
                        o[i] = r_and(a[i], b[i], al);
                    }
                }
                Op::ROr(al) => {
                    for i in 0..len {
                        o[i] = r_or(a[i], b[i], al);
                    }
                }
                Op::SinCos => unreachable!("run before `io`"),
            }
        }
    }
}

/// The tape split for points on segments parallel to one axis (the grid
/// edges whose crossings root finding refines): the instructions that do
/// not depend on that coordinate run once per segment (`setup`), the others
/// at every step. For M2's gyroid along an x edge, four of its six sines and
/// cosines are setup. The operations and their inputs are the same as
/// [`Tape`]'s, so the values are bit-identical.
#[derive(Debug, Clone, PartialEq)]
pub struct AxisTape {
    axis: usize,
    setup: Vec<Instr>,
    step: Vec<Instr>,
    consts: Vec<(u32, f64)>,
    vars: [Option<u32>; 3],
    slots: usize,
    out: u32,
}

impl AxisTape {
    pub fn new(ssa: &Ssa, axis: usize) -> AxisTape {
        let n = ssa.ops.len();
        let mut varies = vec![false; n];
        let mut last_use = vec![usize::MAX; n];
        for (i, op) in ssa.ops.iter().enumerate() {
            varies[i] = match *op {
                Node::Var(a) => a as usize == axis,
                _ => children(op).any(|c| varies[c as usize]),
            };
            for c in children(op) {
                last_use[c as usize] = i;
            }
        }
        let mut slot_of = vec![0u32; n];
        let mut free: Vec<u32> = Vec::new();
        let mut slots = 0u32;
        let partner = sin_cos_partners(ssa);
        let mut paired = vec![false; n];
        let mut tape = AxisTape {
            axis,
            setup: Vec::new(),
            step: Vec::new(),
            consts: Vec::new(),
            vars: [None; 3],
            slots: 0,
            out: 0,
        };
        for (i, op) in ssa.ops.iter().enumerate() {
            // Everything that does not vary along the axis keeps its slot for
            // the whole segment; varying results reuse freed slots.
            let fixed = !varies[i] || matches!(op, Node::Var(_));
            let mut alloc = |free: &mut Vec<u32>| match if fixed { None } else { free.pop() } {
                Some(s) => s,
                None => {
                    slots += 1;
                    slots - 1
                }
            };
            if paired[i] {
                // Computed with its partner (same `varies`: same argument).
            } else {
                let out = alloc(&mut free);
                slot_of[i] = out;
            }
            let out = slot_of[i];
            match *op {
                Node::Const(bits) => tape.consts.push((out, f64::from_bits(bits))),
                Node::Var(a) => tape.vars[a as usize] = Some(out),
                _ if paired[i] => {}
                _ => {
                    let second = partner[i].map(|j| {
                        let t = alloc(&mut free);
                        slot_of[j as usize] = t;
                        paired[j as usize] = true;
                        t
                    });
                    let ins = instruction(op, out, &slot_of, second);
                    if varies[i] {
                        tape.step.push(ins);
                    } else {
                        tape.setup.push(ins);
                    }
                }
            }
            let mut seen = [u32::MAX; 2];
            for (k, c) in children(op).enumerate() {
                let c = c as usize;
                if last_use[c] == i && varies[c] && !seen.contains(&(c as u32)) {
                    free.push(slot_of[c]);
                }
                seen[k] = c as u32;
            }
        }
        tape.slots = slots as usize;
        tape.out = slot_of[n - 1];
        tape
    }

    /// The axis the segments run along.
    pub fn axis(&self) -> usize {
        self.axis
    }

    pub fn workspace(&self) -> Workspace {
        let mut ws = Workspace { buf: Vec::new() };
        self.prepare(&mut ws, BATCH);
        ws
    }

    /// Makes `ws` (from any tape) this tape's workspace, reusing its memory:
    /// a block's few edges must not pay for allocating and zeroing a fresh
    /// workspace (that cost more than the root finding itself).
    /// Only the first `lanes` lanes get the constants: set up and evaluate
    /// at most that many segments per call.
    pub fn prepare(&self, ws: &mut Workspace, lanes: usize) {
        let len = self.slots.max(1) * BATCH;
        if ws.buf.len() < len {
            ws.buf.resize(len, 0.0);
        }
        for &(s, v) in &self.consts {
            ws.buf[s as usize * BATCH..][..lanes.min(BATCH)].fill(v);
        }
    }

    /// Sets up up to [`BATCH`] segments: `fixed[b][m]` is segment m's
    /// coordinate on axis b (the entry for the segment axis is ignored).
    pub fn setup(&self, ws: &mut Workspace, fixed: [&[f64]; 3]) {
        let len = fixed[(self.axis + 1) % 3].len();
        for (b, src) in fixed.into_iter().enumerate() {
            if let (Some(s), true) = (self.vars[b], b != self.axis) {
                ws.buf[s as usize * BATCH..][..len].copy_from_slice(src);
            }
        }
        run(&self.setup, &mut ws.buf, len);
    }

    /// f at the set-up segments' points with coordinate `along[m]` on the
    /// axis, into `out`.
    pub fn eval(&self, ws: &mut Workspace, along: &[f64], out: &mut [f64]) {
        let len = along.len();
        if let Some(s) = self.vars[self.axis] {
            ws.buf[s as usize * BATCH..][..len].copy_from_slice(along);
        }
        run(&self.step, &mut ws.buf, len);
        out[..len].copy_from_slice(&ws.buf[self.out as usize * BATCH..][..len]);
    }
}

fn op_of(op: &Node) -> Op {
    match *op {
        Node::Unary(u, _) => Op::Unary(u),
        Node::Binary(bin, _, _) => Op::Binary(bin),
        Node::RAnd(_, _, al) if f64::from_bits(al) == 0.0 => Op::RvAnd,
        Node::ROr(_, _, al) if f64::from_bits(al) == 0.0 => Op::RvOr,
        Node::RAnd(_, _, al) => Op::RAnd(f64::from_bits(al)),
        Node::ROr(_, _, al) => Op::ROr(f64::from_bits(al)),
        Node::Const(_) | Node::Var(_) => {
            unreachable!("constants and coordinates have no instruction")
        }
    }
}

/// Scratch memory for one thread.
#[derive(Default)]
pub struct Workspace {
    buf: Vec<f64>,
}

/// The output slot (mutable) and two input slots of one instruction; the
/// allocator guarantees the output differs from both inputs.
// Slot numbers come from the tape compiler, never from input: a bad one is a bug.
#[allow(clippy::expect_used)]
fn io(
    buf: &mut [f64],
    o: usize,
    a: usize,
    b: usize,
) -> (&mut [f64; BATCH], &[f64; BATCH], &[f64; BATCH]) {
    let (lo, hi) = buf.split_at_mut(o * BATCH);
    let (out, rest) = hi.split_at_mut(BATCH);
    let pick = |s: usize| -> &[f64; BATCH] {
        let slice = if s < o {
            &lo[s * BATCH..][..BATCH]
        } else {
            &rest[(s - o - 1) * BATCH..][..BATCH]
        };
        slice.try_into().expect("slot is BATCH long")
    };
    let (a, b) = (pick(a), pick(b));
    (out.try_into().expect("slot is BATCH long"), a, b)
}

/// A `SinCos` instruction over the first `len` lanes (the allocator gives
/// it three distinct slots; the argument is copied out first, so the two
/// outputs are the only borrows of `buf`).
fn sin_cos(buf: &mut [f64], ins: &Instr, len: usize) {
    let mut arg = [0.0; BATCH];
    arg[..len].copy_from_slice(&buf[ins.a as usize * BATCH..][..len]);
    let (s, c) = (ins.out as usize, ins.b as usize);
    let (lo, hi) = buf.split_at_mut(s.max(c) * BATCH);
    let first = &mut lo[s.min(c) * BATCH..][..len];
    let second = &mut hi[..len];
    let (sin, cos) = if s < c {
        (first, second)
    } else {
        (second, first)
    };
    super::trig::sin_cos_lanes(sin, cos, &arg[..len]);
}

fn unary(u: Unary, o: &mut [f64], a: &[f64]) {
    macro_rules! each {
        ($f:expr) => {
            for (o, &a) in o.iter_mut().zip(a) {
                *o = $f(a);
            }
        };
    }
    match u {
        Unary::Neg => each!(|x: f64| -x),
        Unary::Square => each!(|x: f64| x * x),
        Unary::Sqrt => each!(f64::sqrt),
        Unary::Abs => each!(f64::abs),
        Unary::Sin => super::trig::sin_lanes(o, a),
        Unary::Cos => super::trig::cos_lanes(o, a),
        _ => each!(|x| u.apply(x)),
    }
}

fn binary(bin: Binary, o: &mut [f64], a: &[f64], b: &[f64]) {
    macro_rules! each {
        ($f:expr) => {
            for ((o, &a), &b) in o.iter_mut().zip(a).zip(b) {
                *o = $f(a, b);
            }
        };
    }
    match bin {
        Binary::Add => each!(|x: f64, y: f64| x + y),
        Binary::Sub => each!(|x: f64, y: f64| x - y),
        Binary::Mul => each!(|x: f64, y: f64| x * y),
        Binary::Div => each!(|x: f64, y: f64| x / y),
        Binary::Min => each!(|x: f64, y: f64| if x < y { x } else { y }),
        Binary::Max => each!(|x: f64, y: f64| if x > y { x } else { y }),
        _ => each!(|x, y| bin.apply(x, y)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::implicit::ir::gyroid;

    #[test]
    fn tape_matches_scalar_evaluation() {
        let mut ctx = Ctx::new();
        let (x, y, z) = (ctx.var(0), ctx.var(1), ctx.var(2));
        let xy = ctx.add(x, y);
        let s = ctx.unary(Unary::Sin, xy);
        let t = ctx.sub(s, z);
        let one = ctx.constant(1.0);
        let a = ctx.add(t, one);
        let zz = ctx.sub(z, s);
        let root = ctx.r_and(a, zz, 0.0);
        let root = ctx.r_or(root, x, 0.3);
        let tape = Tape::from_ctx(&ctx, root);
        let mut ws = tape.workspace();
        let n = 300;
        let xs: Vec<f64> = (0..n).map(|i| i as f64 * 0.01 - 1.0).collect();
        let ys: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
        let zs: Vec<f64> = (0..n).map(|i| (i as f64 * 0.11).cos()).collect();
        let mut out = vec![0.0; n];
        tape.eval(&mut ws, &xs, &ys, &zs, &mut out);
        for i in 0..n {
            let want = ctx.eval_point(root, [xs[i], ys[i], zs[i]]);
            assert!((out[i] - want).abs() < 1e-14, "{i}: {} vs {want}", out[i]);
        }
        assert!(tape.slots < ctx.nodes.len());
    }

    #[test]
    fn axis_tapes_give_the_tape_values_bit_for_bit() {
        let mut ctx = Ctx::new();
        let (x, y, z) = (ctx.var(0), ctx.var(1), ctx.var(2));
        let six = ctx.constant(6.0);
        let sx = ctx.mul(six, x);
        let sy = ctx.mul(six, y);
        let a = ctx.unary(Unary::Sin, sx);
        let b = ctx.unary(Unary::Cos, sy);
        let ab = ctx.mul(a, b);
        let zz = ctx.square(z);
        let c = ctx.sub(ab, zz);
        let d = ctx.r_or(c, b, 0.0);
        let root = ctx.r_and(d, zz, 0.5);
        let ssa = Ssa::from_ctx(&ctx, root);
        let tape = Tape::new(&ssa);
        let n = 100;
        let p: [Vec<f64>; 3] =
            [0.37, 0.11, 0.73].map(|w| (0..n).map(|i| (i as f64 * w).sin()).collect());
        for axis in 0..3 {
            let along = AxisTape::new(&ssa, axis);
            assert!(
                along.step.len() < tape.len(),
                "axis {axis} setup is not empty"
            );
            let mut ws = along.workspace();
            along.setup(&mut ws, [&p[0], &p[1], &p[2]]);
            for shift in [0.0, 0.25, -0.5] {
                let moved: Vec<f64> = p[axis].iter().map(|v| v + shift).collect();
                let mut q = p.clone();
                q[axis] = moved.clone();
                let (mut want, mut got) = (vec![0.0; n], vec![0.0; n]);
                tape.eval(&mut tape.workspace(), &q[0], &q[1], &q[2], &mut want);
                along.eval(&mut ws, &moved, &mut got);
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(&got), bits(&want), "axis {axis} shift {shift}");
            }
        }
    }

    /// PERF-ANCHORS.md's M2: min(0.04 − g², 0.81 − |p|²), g the gyroid.
    fn gyroid_in_ball() -> (Ctx, NodeId) {
        let mut ctx = Ctx::new();
        let g = gyroid(&mut ctx);
        let v = [ctx.var(0), ctx.var(1), ctx.var(2)];
        let gg = ctx.square(g);
        let c = ctx.constant(0.04);
        let shell = ctx.sub(c, gg);
        let rr: Vec<NodeId> = v.iter().map(|&a| ctx.square(a)).collect();
        let r2 = ctx.add(rr[0], rr[1]);
        let r2 = ctx.add(r2, rr[2]);
        let big = ctx.constant(0.81);
        let ball = ctx.sub(big, r2);
        let root = ctx.binary(Binary::Min, shell, ball);
        (ctx, root)
    }

    #[test]
    fn sin_and_cos_lanes_give_the_scalar_values_on_the_gyroid() {
        // The tapes take sin and cos from `trig` (vectorised), the scalar
        // evaluation from libm: within 1e-12 of the function's scale (its
        // terms are of order 1), on a grid's points and between them.
        let (ctx, root) = gyroid_in_ball();
        let ssa = Ssa::from_ctx(&ctx, root);
        let tape = Tape::new(&ssa);
        let n = 2000;
        let p: [Vec<f64>; 3] =
            [0.37, 0.11, 0.73].map(|w| (0..n).map(|i| (i as f64 * w).sin() * 1.05).collect());
        let mut got = vec![0.0; n];
        tape.eval(&mut tape.workspace(), &p[0], &p[1], &p[2], &mut got);
        let mut worst: f64 = 0.0;
        for i in 0..n {
            let want = ssa.eval_point([p[0][i], p[1][i], p[2][i]]);
            worst = worst.max((got[i] - want).abs() / want.abs().max(1.0));
        }
        assert!(worst <= 1e-12, "tape: {worst:e} relative");
        for axis in 0..3 {
            let along = AxisTape::new(&ssa, axis);
            let mut ws = along.workspace();
            let m = 100;
            along.setup(&mut ws, [&p[0][..m], &p[1][..m], &p[2][..m]]);
            for step in [0.0, 0.3, 1.0] {
                let moved: Vec<f64> = p[axis][..m].iter().map(|v| v + step / 128.0).collect();
                let mut out = vec![0.0; m];
                along.eval(&mut ws, &moved, &mut out);
                for i in 0..m {
                    let mut q = [p[0][i], p[1][i], p[2][i]];
                    q[axis] = moved[i];
                    let want = ssa.eval_point(q);
                    let rel = (out[i] - want).abs() / want.abs().max(1.0);
                    assert!(rel <= 1e-12, "axis {axis}, point {i}: {} vs {want}", out[i]);
                }
            }
        }
    }

    #[test]
    fn a_sine_and_cosine_of_one_argument_are_one_instruction_with_their_own_bits() {
        // cos before sin, a lone sine, and the pair used after other
        // operations freed slots: one SinCos, values bit for bit those of
        // the separate lane functions.
        let mut ctx = Ctx::new();
        let (x, y, z) = (ctx.var(0), ctx.var(1), ctx.var(2));
        let xy = ctx.mul(x, y);
        let c = ctx.unary(Unary::Cos, xy);
        let sz = ctx.unary(Unary::Sin, z);
        let zz = ctx.square(sz);
        let t = ctx.add(c, zz);
        let s = ctx.unary(Unary::Sin, xy);
        let root = ctx.sub(t, s);
        let ssa = Ssa::from_ctx(&ctx, root);
        let tape = Tape::new(&ssa);
        let fused = |ins: &[Instr]| ins.iter().filter(|i| matches!(i.op, Op::SinCos)).count();
        assert_eq!(fused(&tape.instrs), 1);
        assert_eq!(tape.len(), 6, "mul, sincos, sin, square, add, sub");
        let n = 50;
        let p: [Vec<f64>; 3] =
            [0.37, 0.11, 0.73].map(|w| (0..n).map(|i| (i as f64 * w).sin() * 3.0).collect());
        let mut got = vec![0.0; n];
        tape.eval(&mut tape.workspace(), &p[0], &p[1], &p[2], &mut got);
        let xy: Vec<f64> = (0..n).map(|i| p[0][i] * p[1][i]).collect();
        let (mut sin, mut cos, mut sinz) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        super::super::trig::sin_lanes(&mut sin, &xy);
        super::super::trig::cos_lanes(&mut cos, &xy);
        super::super::trig::sin_lanes(&mut sinz, &p[2]);
        for i in 0..n {
            let want = (cos[i] + sinz[i] * sinz[i]) - sin[i];
            assert_eq!(got[i].to_bits(), want.to_bits(), "point {i}");
        }
        // The axis tapes too: along z the pair is set up once per segment.
        let along = AxisTape::new(&ssa, 2);
        assert_eq!(fused(&along.setup), 1);
        let mut ws = along.workspace();
        along.setup(&mut ws, [&p[0], &p[1], &p[2]]);
        let mut out = vec![0.0; n];
        along.eval(&mut ws, &p[2], &mut out);
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&out), bits(&got));
    }

    #[test]
    fn constants_after_operations_keep_their_slots() {
        // Regression: a constant first used after a freed operation slot must
        // not share that slot (its value is written before the tape runs).
        let mut ctx = Ctx::new();
        let (x, y, z) = (ctx.var(0), ctx.var(1), ctx.var(2));
        let xx = ctx.square(x);
        let yy = ctx.square(y);
        let r2 = ctx.add(xx, yy);
        let r = ctx.unary(Unary::Sqrt, r2);
        let big = ctx.constant(0.6);
        let d = ctx.sub(r, big);
        let dd = ctx.square(d);
        let small = ctx.constant(0.0625);
        let a = ctx.sub(small, dd);
        let zz = ctx.square(z);
        let root = ctx.sub(a, zz);
        let tape = Tape::from_ctx(&ctx, root);
        let mut ws = tape.workspace();
        let mut out = [0.0; 2];
        tape.eval(&mut ws, &[1.0, 0.6], &[1.0, 0.0], &[1.0, 0.1], &mut out);
        assert!((out[0] - (0.0625 - (2f64.sqrt() - 0.6).powi(2) - 1.0)).abs() < 1e-14);
        assert!((out[1] - (0.0625 - 0.01)).abs() < 1e-14);
    }
}
