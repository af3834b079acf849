//! The expression IR of an implicit function f(x, y, z): a hash-consed arena of
//! nodes in topological order (children before parents), so common
//! subexpressions are shared and constants are folded as the tree is built.

use std::collections::HashMap;

/// Index of a node in a [`Ctx`].
pub type NodeId = u32;

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Unary {
    Neg,
    Sqrt,
    Square,
    Abs,
    Sin,
    Cos,
    Tan,
    Asin,
    Acos,
    Atan,
    Exp,
    Ln,
    Floor,
    Ceil,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Binary {
    Add,
    Sub,
    Mul,
    Div,
    Pow,
    Min,
    Max,
    Atan2,
}

/// One node. R-operations keep their own kind (rather than being expanded into
/// arithmetic) because interval pruning treats them specially: they have the
/// sign of min/max, which keeps sign questions tight.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Node {
    /// A constant, stored as its bits so nodes can be hashed.
    Const(u64),
    /// Coordinate 0, 1 or 2.
    Var(u8),
    Unary(Unary, NodeId),
    Binary(Binary, NodeId, NodeId),
    /// R-conjunction of the R_α system, α stored as bits.
    RAnd(NodeId, NodeId, u64),
    /// R-disjunction of the R_α system.
    ROr(NodeId, NodeId, u64),
}

/// The arena with hash-consing.
#[derive(Debug, Clone, Default)]
pub struct Ctx {
    pub nodes: Vec<Node>,
    index: HashMap<Node, NodeId>,
}

impl Unary {
    pub fn apply(self, a: f64) -> f64 {
        match self {
            Unary::Neg => -a,
            Unary::Sqrt => a.sqrt(),
            Unary::Square => a * a,
            Unary::Abs => a.abs(),
            Unary::Sin => a.sin(),
            Unary::Cos => a.cos(),
            Unary::Tan => a.tan(),
            Unary::Asin => a.asin(),
            Unary::Acos => a.acos(),
            Unary::Atan => a.atan(),
            Unary::Exp => a.exp(),
            Unary::Ln => a.ln(),
            Unary::Floor => a.floor(),
            Unary::Ceil => a.ceil(),
        }
    }
}

impl Binary {
    pub fn apply(self, a: f64, b: f64) -> f64 {
        match self {
            Binary::Add => a + b,
            Binary::Sub => a - b,
            Binary::Mul => a * b,
            Binary::Div => a / b,
            Binary::Pow => a.powf(b),
            Binary::Min => a.min(b),
            Binary::Max => a.max(b),
            Binary::Atan2 => a.atan2(b),
        }
    }
}

/// R_α conjunction: (x + y − sqrt(x² + y² − 2αxy)) / (1 + α); α = 0 is
/// Rvachev's system, α = 1 is min.
pub fn r_and(x: f64, y: f64, alpha: f64) -> f64 {
    (x + y - (x * x + y * y - 2.0 * alpha * x * y).max(0.0).sqrt()) / (1.0 + alpha)
}

/// R_α disjunction: (x + y + sqrt(x² + y² − 2αxy)) / (1 + α).
pub fn r_or(x: f64, y: f64, alpha: f64) -> f64 {
    (x + y + (x * x + y * y - 2.0 * alpha * x * y).max(0.0).sqrt()) / (1.0 + alpha)
}

impl Ctx {
    pub fn new() -> Ctx {
        Ctx::default()
    }

    fn intern(&mut self, node: Node) -> NodeId {
        if let Some(&id) = self.index.get(&node) {
            return id;
        }
        let id = self.nodes.len() as NodeId;
        self.nodes.push(node);
        self.index.insert(node, id);
        id
    }

    pub fn constant(&mut self, v: f64) -> NodeId {
        // One canonical zero, so -0.0 and 0.0 share a node.
        let v = if v == 0.0 { 0.0 } else { v };
        self.intern(Node::Const(v.to_bits()))
    }

    pub fn var(&mut self, axis: u8) -> NodeId {
        self.intern(Node::Var(axis))
    }

    /// The value of a constant node.
    pub fn const_value(&self, id: NodeId) -> Option<f64> {
        match self.nodes[id as usize] {
            Node::Const(bits) => Some(f64::from_bits(bits)),
            _ => None,
        }
    }

    pub fn unary(&mut self, op: Unary, a: NodeId) -> NodeId {
        if let Some(v) = self.const_value(a) {
            return self.constant(op.apply(v));
        }
        if op == Unary::Neg
            && let Node::Unary(Unary::Neg, inner) = self.nodes[a as usize]
        {
            return inner;
        }
        self.intern(Node::Unary(op, a))
    }

    pub fn binary(&mut self, op: Binary, a: NodeId, b: NodeId) -> NodeId {
        let (ca, cb) = (self.const_value(a), self.const_value(b));
        if let (Some(x), Some(y)) = (ca, cb) {
            return self.constant(op.apply(x, y));
        }
        match (op, ca, cb) {
            (Binary::Add, Some(0.0), _) => return b,
            (Binary::Add | Binary::Sub, _, Some(0.0)) => return a,
            (Binary::Sub, Some(0.0), _) => return self.unary(Unary::Neg, b),
            (Binary::Mul, Some(1.0), _) => return b,
            (Binary::Mul | Binary::Div, _, Some(1.0)) => return a,
            (Binary::Pow, _, Some(2.0)) => return self.unary(Unary::Square, a),
            (Binary::Pow, _, Some(0.5)) => return self.unary(Unary::Sqrt, a),
            _ => {}
        }
        if op == Binary::Mul && a == b {
            return self.unary(Unary::Square, a);
        }
        // Commutative operations get a canonical operand order for sharing.
        let (a, b) = match op {
            Binary::Add | Binary::Mul | Binary::Min | Binary::Max if a > b => (b, a),
            _ => (a, b),
        };
        self.intern(Node::Binary(op, a, b))
    }

    pub fn add(&mut self, a: NodeId, b: NodeId) -> NodeId {
        self.binary(Binary::Add, a, b)
    }
    pub fn sub(&mut self, a: NodeId, b: NodeId) -> NodeId {
        self.binary(Binary::Sub, a, b)
    }
    pub fn mul(&mut self, a: NodeId, b: NodeId) -> NodeId {
        self.binary(Binary::Mul, a, b)
    }
    pub fn div(&mut self, a: NodeId, b: NodeId) -> NodeId {
        self.binary(Binary::Div, a, b)
    }
    pub fn neg(&mut self, a: NodeId) -> NodeId {
        self.unary(Unary::Neg, a)
    }
    pub fn square(&mut self, a: NodeId) -> NodeId {
        self.unary(Unary::Square, a)
    }

    /// R-conjunction with parameter α (α = 1 gives a plain min).
    pub fn r_and(&mut self, a: NodeId, b: NodeId, alpha: f64) -> NodeId {
        if alpha == 1.0 {
            return self.binary(Binary::Min, a, b);
        }
        if let (Some(x), Some(y)) = (self.const_value(a), self.const_value(b)) {
            return self.constant(r_and(x, y, alpha));
        }
        self.intern(Node::RAnd(a, b, alpha.to_bits()))
    }

    /// R-disjunction with parameter α (α = 1 gives a plain max).
    pub fn r_or(&mut self, a: NodeId, b: NodeId, alpha: f64) -> NodeId {
        if alpha == 1.0 {
            return self.binary(Binary::Max, a, b);
        }
        if let (Some(x), Some(y)) = (self.const_value(a), self.const_value(b)) {
            return self.constant(r_or(x, y, alpha));
        }
        self.intern(Node::ROr(a, b, alpha.to_bits()))
    }

    /// Evaluates `root` at one point by walking the arena (slow; for tests and
    /// single values — use a [`crate::implicit::tape::Tape`] for batches).
    pub fn eval_point(&self, root: NodeId, p: [f64; 3]) -> f64 {
        let mut values = vec![0.0; root as usize + 1];
        for (i, node) in self.nodes.iter().enumerate().take(root as usize + 1) {
            values[i] = match *node {
                Node::Const(bits) => f64::from_bits(bits),
                Node::Var(axis) => p[axis as usize],
                Node::Unary(op, a) => op.apply(values[a as usize]),
                Node::Binary(op, a, b) => op.apply(values[a as usize], values[b as usize]),
                Node::RAnd(a, b, alpha) => r_and(
                    values[a as usize],
                    values[b as usize],
                    f64::from_bits(alpha),
                ),
                Node::ROr(a, b, alpha) => r_or(
                    values[a as usize],
                    values[b as usize],
                    f64::from_bits(alpha),
                ),
            };
        }
        values[root as usize]
    }
}

/// The gyroid sin 6x cos 6y + sin 6y cos 6z + sin 6z cos 6x (the surface of
/// PERF-ANCHORS.md's M2), for the evaluators' tests.
#[cfg(test)]
pub(crate) fn gyroid(ctx: &mut Ctx) -> NodeId {
    let v = [ctx.var(0), ctx.var(1), ctx.var(2)];
    let six = ctx.constant(6.0);
    let s: Vec<NodeId> = v.iter().map(|&a| ctx.mul(six, a)).collect();
    let mut g = ctx.constant(0.0);
    for k in 0..3 {
        let sn = ctx.unary(Unary::Sin, s[k]);
        let cs = ctx.unary(Unary::Cos, s[(k + 1) % 3]);
        let t = ctx.mul(sn, cs);
        g = ctx.add(g, t);
    }
    g
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn folds_constants_and_shares_subexpressions() {
        let mut ctx = Ctx::new();
        let x = ctx.var(0);
        let two = ctx.constant(2.0);
        let three = ctx.constant(3.0);
        let six = ctx.mul(two, three);
        assert_eq!(ctx.const_value(six), Some(6.0));
        let a = ctx.add(x, six);
        let b = ctx.add(six, x);
        assert_eq!(a, b);
        assert_eq!(ctx.eval_point(a, [1.5, 0.0, 0.0]), 7.5);
        let nn = ctx.neg(x);
        assert_eq!(ctx.neg(nn), x);
    }

    #[test]
    fn r_functions_have_the_sign_of_min_and_max() {
        for &(x, y) in &[
            (1.0, 2.0),
            (-1.0, 2.0),
            (-1.0, -0.5),
            (0.0, -3.0),
            (0.3, 0.0),
        ] {
            for &alpha in &[0.0, 0.5, -0.5] {
                assert_eq!(r_and(x, y, alpha) > 0.0, x.min(y) > 0.0);
                assert_eq!(r_or(x, y, alpha) > 0.0, x.max(y) > 0.0);
            }
            assert!((r_and(x, y, 1.0) - x.min(y)).abs() < 1e-12);
        }
    }
}
