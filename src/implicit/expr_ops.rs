//! The format's expression operators (`src/expr`) as implicit-IR operations:
//! one table for every translator (`<rfunction>` formulas, trims and
//! parametric surfaces), so they cannot disagree.

use super::ir::{Binary, Ctx, NodeId, Unary};
use crate::expr::{BinaryOp, Function};

/// How a format function becomes IR: one unary operation, or a fold of a
/// binary one over the arguments (`min`, `max` take any number).
pub enum FunctionOp {
    Unary(Unary),
    Fold(Binary),
}

pub fn binary(op: BinaryOp) -> Binary {
    match op {
        BinaryOp::Add => Binary::Add,
        BinaryOp::Sub => Binary::Sub,
        BinaryOp::Mul => Binary::Mul,
        BinaryOp::Div => Binary::Div,
        BinaryOp::Pow => Binary::Pow,
    }
}

pub fn function(f: Function) -> FunctionOp {
    match f {
        Function::Sqrt => FunctionOp::Unary(Unary::Sqrt),
        Function::Sin => FunctionOp::Unary(Unary::Sin),
        Function::Cos => FunctionOp::Unary(Unary::Cos),
        Function::Tan => FunctionOp::Unary(Unary::Tan),
        Function::Asin => FunctionOp::Unary(Unary::Asin),
        Function::Acos => FunctionOp::Unary(Unary::Acos),
        Function::Atan => FunctionOp::Unary(Unary::Atan),
        Function::Exp => FunctionOp::Unary(Unary::Exp),
        Function::Ln => FunctionOp::Unary(Unary::Ln),
        Function::Abs => FunctionOp::Unary(Unary::Abs),
        Function::Min => FunctionOp::Fold(Binary::Min),
        Function::Max => FunctionOp::Fold(Binary::Max),
    }
}

/// Applies `f` to already built arguments; `None` when there are none (the
/// expression parser checks arity, so callers turn this into their own error).
pub fn apply(ctx: &mut Ctx, f: Function, args: &[NodeId]) -> Option<NodeId> {
    let (&first, rest) = args.split_first()?;
    Some(match function(f) {
        FunctionOp::Unary(op) => ctx.unary(op, first),
        FunctionOp::Fold(op) => rest.iter().fold(first, |acc, &x| ctx.binary(op, acc, x)),
    })
}
