//! Expressions of the format (`src/expr`) as programs of the implicit IR, so
//! trims and surface coordinates evaluate like R-functions (tapes, shared
//! subexpressions, constant folding).

use crate::expr::{BinaryOp, Expr, ExprKind};
use crate::implicit::expr_ops;
use crate::implicit::ir::{Ctx, NodeId};

/// Builds `expr` into `ctx`; the names in `vars` are coordinates 0, 1, 2.
/// Other names (parameters are already folded) are an error naming them.
pub fn build(ctx: &mut Ctx, expr: &Expr, vars: &[&str]) -> Result<NodeId, String> {
    Ok(match &expr.kind {
        ExprKind::Number(v) => ctx.constant(*v),
        ExprKind::Name(n) => match vars.iter().position(|v| v == n) {
            Some(axis) => ctx.var(axis as u8),
            None if n == "pi" => ctx.constant(std::f64::consts::PI),
            None => return Err(n.clone()),
        },
        ExprKind::Neg(inner) => {
            let a = build(ctx, inner, vars)?;
            ctx.neg(a)
        }
        ExprKind::Binary(op, a, b) => {
            let x = build(ctx, a, vars)?;
            if *op == BinaryOp::Pow && b.as_literal() == Some(2.0) {
                return Ok(ctx.square(x));
            }
            let y = build(ctx, b, vars)?;
            ctx.binary(expr_ops::binary(*op), x, y)
        }
        ExprKind::Call(f, args) => {
            let mut ids = Vec::with_capacity(args.len());
            for a in args {
                ids.push(build(ctx, a, vars)?);
            }
            // The parser checks arity; an empty call is NaN, never a panic.
            match expr_ops::apply(ctx, *f, &ids) {
                Some(id) => id,
                None => ctx.constant(f64::NAN),
            }
        }
    })
}
