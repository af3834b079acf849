//! Expressions of the format (`src/expr`) as programs of the implicit IR, so
//! trims and surface coordinates evaluate like R-functions (tapes, shared
//! subexpressions, constant folding).

use crate::expr::{BinaryOp, Expr, ExprKind, Function};
use crate::implicit::ir::{Binary, Ctx, NodeId, Unary};

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
            let op = match op {
                BinaryOp::Add => Binary::Add,
                BinaryOp::Sub => Binary::Sub,
                BinaryOp::Mul => Binary::Mul,
                BinaryOp::Div => Binary::Div,
                BinaryOp::Pow => Binary::Pow,
            };
            ctx.binary(op, x, y)
        }
        ExprKind::Call(f, args) => {
            let mut ids = Vec::with_capacity(args.len());
            for a in args {
                ids.push(build(ctx, a, vars)?);
            }
            let first = ids
                .first()
                .copied()
                .unwrap_or_else(|| ctx.constant(f64::NAN));
            let unary = match f {
                Function::Sqrt => Unary::Sqrt,
                Function::Sin => Unary::Sin,
                Function::Cos => Unary::Cos,
                Function::Tan => Unary::Tan,
                Function::Asin => Unary::Asin,
                Function::Acos => Unary::Acos,
                Function::Atan => Unary::Atan,
                Function::Exp => Unary::Exp,
                Function::Ln => Unary::Ln,
                Function::Abs => Unary::Abs,
                Function::Min | Function::Max => {
                    let op = if *f == Function::Min {
                        Binary::Min
                    } else {
                        Binary::Max
                    };
                    return Ok(ids[1..]
                        .iter()
                        .fold(first, |acc, &b| ctx.binary(op, acc, b)));
                }
            };
            ctx.unary(unary, first)
        }
    })
}
