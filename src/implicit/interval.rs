//! Interval arithmetic over an [`Ssa`] for pruning: which regions the surface
//! f = 0 cannot cross, and a per-region simplified program.
//!
//! R-function unions widen badly under plain interval arithmetic
//! (PERF-ANCHORS.md: 94% of M1's cells stay ambiguous). Every R-system here
//! has the sign of min/max, so where only the sign of a node matters (the
//! root, and operands of R-operations, min, max and negation that are
//! themselves sign-only) the node's interval is taken as the min/max
//! interval of its operands, which stays tight.

use super::ir::{Binary, Node, Unary};
use super::tape::{Ssa, children, remap};
use std::f64::consts::{FRAC_PI_2, PI};

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Interval {
    pub lo: f64,
    pub hi: f64,
}

impl Interval {
    pub fn new(lo: f64, hi: f64) -> Interval {
        Interval { lo, hi }
    }
    fn point(v: f64) -> Interval {
        Interval { lo: v, hi: v }
    }
    fn whole() -> Interval {
        Interval::new(f64::NEG_INFINITY, f64::INFINITY)
    }
    fn add(self, o: Interval) -> Interval {
        Interval::new(self.lo + o.lo, self.hi + o.hi)
    }
    fn sub(self, o: Interval) -> Interval {
        Interval::new(self.lo - o.hi, self.hi - o.lo)
    }
    fn neg(self) -> Interval {
        Interval::new(-self.hi, -self.lo)
    }
    fn mul(self, o: Interval) -> Interval {
        let c = [
            self.lo * o.lo,
            self.lo * o.hi,
            self.hi * o.lo,
            self.hi * o.hi,
        ];
        if c.iter().any(|v| v.is_nan()) {
            return Interval::whole();
        }
        Interval::new(
            c.iter().copied().fold(f64::INFINITY, f64::min),
            c.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        )
    }
    fn div(self, o: Interval) -> Interval {
        if o.lo <= 0.0 && o.hi >= 0.0 {
            return Interval::whole();
        }
        self.mul(Interval::new(1.0 / o.hi, 1.0 / o.lo))
    }
    fn square(self) -> Interval {
        let (a, b) = (self.lo * self.lo, self.hi * self.hi);
        if self.lo <= 0.0 && self.hi >= 0.0 {
            Interval::new(0.0, a.max(b))
        } else {
            Interval::new(a.min(b), a.max(b))
        }
    }
    fn sqrt(self) -> Interval {
        Interval::new(self.lo.max(0.0).sqrt(), self.hi.max(0.0).sqrt())
    }
    fn min(self, o: Interval) -> Interval {
        Interval::new(self.lo.min(o.lo), self.hi.min(o.hi))
    }
    fn max(self, o: Interval) -> Interval {
        Interval::new(self.lo.max(o.lo), self.hi.max(o.hi))
    }
    fn sin(self) -> Interval {
        if self.hi - self.lo >= 2.0 * PI || self.hi.is_nan() || self.lo.is_nan() {
            return Interval::new(-1.0, 1.0);
        }
        let (a, b) = (self.lo.sin(), self.hi.sin());
        let mut r = Interval::new(a.min(b), a.max(b));
        // A maximum at π/2 + 2kπ or a minimum at −π/2 + 2kπ inside the interval.
        let k = ((self.lo - FRAC_PI_2) / (2.0 * PI)).ceil();
        if FRAC_PI_2 + 2.0 * PI * k <= self.hi {
            r.hi = 1.0;
        }
        let k = ((self.lo + FRAC_PI_2) / (2.0 * PI)).ceil();
        if -FRAC_PI_2 + 2.0 * PI * k <= self.hi {
            r.lo = -1.0;
        }
        r
    }
    fn monotone(self, f: fn(f64) -> f64) -> Interval {
        Interval::new(f(self.lo), f(self.hi))
    }
}

/// Which nodes only matter through their sign (see the module doc).
pub fn sign_only(ssa: &Ssa) -> Vec<bool> {
    let n = ssa.ops.len();
    let mut value_needed = vec![false; n];
    for i in (0..n).rev() {
        let combinator = matches!(
            ssa.ops[i],
            Node::RAnd(..)
                | Node::ROr(..)
                | Node::Binary(Binary::Min | Binary::Max, ..)
                | Node::Unary(Unary::Neg, _)
        );
        if value_needed[i] || !combinator {
            for c in children(&ssa.ops[i]) {
                value_needed[c as usize] = true;
            }
        }
    }
    value_needed.iter().map(|v| !v).collect()
}

/// The interval of every node over the box; sign-only nodes get their
/// sign-equivalent (min/max) interval.
pub fn eval(ssa: &Ssa, sign: &[bool], bounds: [Interval; 3]) -> Vec<Interval> {
    let mut v: Vec<Interval> = Vec::with_capacity(ssa.ops.len());
    for (i, op) in ssa.ops.iter().enumerate() {
        let g = |k: u32| v[k as usize];
        let r = match *op {
            Node::Const(bits) => Interval::point(f64::from_bits(bits)),
            Node::Var(axis) => bounds[axis as usize],
            Node::Unary(u, a) => unary(u, g(a)),
            Node::Binary(b, x, y) => binary(b, g(x), g(y)),
            Node::RAnd(x, y, _) if sign[i] => g(x).min(g(y)),
            Node::ROr(x, y, _) if sign[i] => g(x).max(g(y)),
            Node::RAnd(x, y, a) | Node::ROr(x, y, a) => {
                let (x, y, alpha) = (g(x), g(y), f64::from_bits(a));
                let root = x
                    .square()
                    .add(y.square())
                    .sub(x.mul(y).mul(Interval::point(2.0 * alpha)))
                    .sqrt();
                let s = x.add(y);
                let r = if matches!(op, Node::RAnd(..)) {
                    s.sub(root)
                } else {
                    s.add(root)
                };
                r.mul(Interval::point(1.0 / (1.0 + alpha)))
            }
        };
        v.push(if r.lo.is_nan() || r.hi.is_nan() {
            Interval::whole()
        } else {
            r
        });
    }
    v
}

fn unary(u: Unary, a: Interval) -> Interval {
    match u {
        Unary::Neg => a.neg(),
        Unary::Square => a.square(),
        Unary::Sqrt => a.sqrt(),
        Unary::Abs => {
            if a.lo >= 0.0 {
                a
            } else if a.hi <= 0.0 {
                a.neg()
            } else {
                Interval::new(0.0, (-a.lo).max(a.hi))
            }
        }
        Unary::Sin => a.sin(),
        Unary::Cos => a.add(Interval::point(FRAC_PI_2)).sin(),
        Unary::Exp => a.monotone(f64::exp),
        Unary::Ln => Interval::new(a.lo.max(0.0).ln(), a.hi.max(0.0).ln()),
        Unary::Atan => a.monotone(f64::atan),
        Unary::Asin => Interval::new(a.lo.clamp(-1.0, 1.0).asin(), a.hi.clamp(-1.0, 1.0).asin()),
        Unary::Acos => Interval::new(a.hi.clamp(-1.0, 1.0).acos(), a.lo.clamp(-1.0, 1.0).acos()),
        Unary::Floor => a.monotone(f64::floor),
        Unary::Ceil => a.monotone(f64::ceil),
        Unary::Tan => Interval::whole(),
    }
}

fn binary(b: Binary, x: Interval, y: Interval) -> Interval {
    match b {
        Binary::Add => x.add(y),
        Binary::Sub => x.sub(y),
        Binary::Mul => x.mul(y),
        Binary::Div => x.div(y),
        Binary::Min => x.min(y),
        Binary::Max => x.max(y),
        Binary::Pow | Binary::Atan2 => Interval::whole(),
    }
}

/// What the root's sign is over a region.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Sign {
    /// f > 0 everywhere (inside).
    Inside,
    /// f ≤ 0 everywhere (outside).
    Outside,
    Ambiguous,
}

pub fn classify(root: Interval) -> Sign {
    // A small margin guards against rounding in the interval bounds.
    let margin = 1e-12 * (root.lo.abs() + root.hi.abs());
    if root.lo > margin {
        Sign::Inside
    } else if root.hi < -margin {
        Sign::Outside
    } else {
        Sign::Ambiguous
    }
}

/// A program with the same sign as `ssa` everywhere in the region whose
/// intervals are `iv`: operands of sign-only unions that are never positive
/// there (and of intersections that are always positive) are dropped, and
/// min/max operands dominated by the other operand.
pub fn simplify(ssa: &Ssa, sign: &[bool], iv: &[Interval]) -> Ssa {
    let n = ssa.ops.len();
    let mut alias: Vec<u32> = (0..n as u32).collect();
    for (i, op) in ssa.ops.iter().enumerate() {
        let pick = match *op {
            Node::ROr(x, y, _) | Node::Binary(Binary::Max, x, y) if sign[i] => {
                let (a, b) = (iv[x as usize], iv[y as usize]);
                if b.hi <= 0.0 || a.lo > 0.0 {
                    Some(x)
                } else if a.hi <= 0.0 || b.lo > 0.0 {
                    Some(y)
                } else {
                    None
                }
            }
            Node::RAnd(x, y, _) | Node::Binary(Binary::Min, x, y) if sign[i] => {
                let (a, b) = (iv[x as usize], iv[y as usize]);
                if b.lo > 0.0 || a.hi <= 0.0 {
                    Some(x)
                } else if a.lo > 0.0 || b.hi <= 0.0 {
                    Some(y)
                } else {
                    None
                }
            }
            Node::Binary(Binary::Max, x, y) => {
                let (a, b) = (iv[x as usize], iv[y as usize]);
                if a.lo >= b.hi {
                    Some(x)
                } else if b.lo >= a.hi {
                    Some(y)
                } else {
                    None
                }
            }
            Node::Binary(Binary::Min, x, y) => {
                let (a, b) = (iv[x as usize], iv[y as usize]);
                if a.hi <= b.lo {
                    Some(x)
                } else if b.hi <= a.lo {
                    Some(y)
                } else {
                    None
                }
            }
            _ => None,
        };
        if let Some(c) = pick {
            alias[i] = alias[c as usize];
        }
    }
    let root = alias[n - 1] as usize;
    let mut live = vec![false; n];
    live[root] = true;
    for i in (0..=root).rev() {
        if live[i] && alias[i] as usize == i {
            for c in children(&ssa.ops[i]) {
                live[alias[c as usize] as usize] = true;
            }
        }
    }
    let mut renumber = vec![u32::MAX; n];
    let mut ops = Vec::new();
    for i in 0..=root {
        if live[i] && alias[i] as usize == i {
            renumber[i] = ops.len() as u32;
            ops.push(remap(remap(ssa.ops[i], &alias), &renumber));
        }
    }
    Ssa { ops }
}
