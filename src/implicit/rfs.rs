//! R-function systems: how ∧, ∨ and ¬ combine implicit functions. Every system
//! here has the sign of min/max (x ∧ y > 0 exactly where min(x, y) > 0), so
//! the solid {f > 0} is the same whichever is chosen; they differ in
//! smoothness and in how f grows away from the surface.

use super::ir::{Ctx, NodeId};

/// The R_α family: x ∧ y = (x + y − sqrt(x² + y² − 2αxy)) / (1 + α),
/// α ∈ (−1, 1]. α = 0 is Rvachev's system (paper 001's default), α = 1 is min/max.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum RSystem {
    /// x ∧ y = x + y − sqrt(x² + y²), x ∨ y = x + y + sqrt(x² + y²).
    #[default]
    Rvachev,
    /// x ∧ y = min(x, y), x ∨ y = max(x, y).
    MinMax,
    /// The general R_α member.
    Alpha(f64),
}

impl RSystem {
    pub fn alpha(self) -> f64 {
        match self {
            RSystem::Rvachev => 0.0,
            RSystem::MinMax => 1.0,
            RSystem::Alpha(a) => a,
        }
    }

    /// Whether α is inside the family's range (−1, 1].
    pub fn is_valid(self) -> bool {
        let a = self.alpha();
        a > -1.0 && a <= 1.0
    }

    pub fn and(self, ctx: &mut Ctx, a: NodeId, b: NodeId) -> NodeId {
        ctx.r_and(a, b, self.alpha())
    }

    pub fn or(self, ctx: &mut Ctx, a: NodeId, b: NodeId) -> NodeId {
        ctx.r_or(a, b, self.alpha())
    }

    pub fn not(self, ctx: &mut Ctx, a: NodeId) -> NodeId {
        ctx.neg(a)
    }

    /// a ∧ ¬b.
    pub fn difference(self, ctx: &mut Ctx, a: NodeId, b: NodeId) -> NodeId {
        let nb = ctx.neg(b);
        self.and(ctx, a, nb)
    }

    /// Folds a list left to right (paper 001's `Con(a, b, c)` = (a ∧ b) ∧ c).
    pub fn and_all(self, ctx: &mut Ctx, items: &[NodeId]) -> Option<NodeId> {
        let (&first, rest) = items.split_first()?;
        Some(rest.iter().fold(first, |acc, &x| self.and(ctx, acc, x)))
    }

    pub fn or_all(self, ctx: &mut Ctx, items: &[NodeId]) -> Option<NodeId> {
        let (&first, rest) = items.split_first()?;
        Some(rest.iter().fold(first, |acc, &x| self.or(ctx, acc, x)))
    }
}
