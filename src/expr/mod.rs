//! The expression language of numeric attributes: numbers, names (parameters,
//! basis coordinates, free variables), `+ - * / ^`, parentheses, unary minus,
//! `pi`, and the functions sqrt sin cos tan asin acos atan exp ln abs min max.

// User-controlled bytes and values: no panicking index (docs/reliability.md).
#![cfg_attr(not(test), deny(clippy::indexing_slicing))]

mod eval;
mod parse;
mod short;

pub use eval::{EvalError, eval};
pub use parse::{ExprLimits, MAX_DEPTH, MAX_NODES, ParseError, parse, parse_with};

use crate::span::Span;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BinaryOp {
    Add,
    Sub,
    Mul,
    Div,
    Pow,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Function {
    Sqrt,
    Sin,
    Cos,
    Tan,
    Asin,
    Acos,
    Atan,
    Exp,
    Ln,
    Abs,
    Min,
    Max,
}

impl Function {
    pub const ALL: &'static [(&'static str, Function)] = &[
        ("sqrt", Function::Sqrt),
        ("sin", Function::Sin),
        ("cos", Function::Cos),
        ("tan", Function::Tan),
        ("asin", Function::Asin),
        ("acos", Function::Acos),
        ("atan", Function::Atan),
        ("exp", Function::Exp),
        ("ln", Function::Ln),
        ("abs", Function::Abs),
        ("min", Function::Min),
        ("max", Function::Max),
    ];

    pub fn lookup(name: &str) -> Option<Function> {
        Function::ALL
            .iter()
            .find(|(n, _)| *n == name)
            .map(|&(_, f)| f)
    }

    pub fn name(self) -> &'static str {
        Function::ALL
            .iter()
            .find(|(_, f)| *f == self)
            .map_or("?", |(n, _)| n)
    }

    /// True when the function takes a variable number (at least two) of arguments.
    pub fn is_variadic(self) -> bool {
        matches!(self, Function::Min | Function::Max)
    }
}

#[derive(Debug, Clone, PartialEq)]
pub enum ExprKind {
    Number(f64),
    /// A parameter, basis coordinate, free variable or the constant `pi`.
    Name(String),
    Neg(Box<Expr>),
    Binary(BinaryOp, Box<Expr>, Box<Expr>),
    Call(Function, Vec<Expr>),
}

/// A parsed expression; spans are absolute positions in the source file.
#[derive(Debug, Clone, PartialEq)]
pub struct Expr {
    pub kind: ExprKind,
    pub span: Span,
}

impl Expr {
    pub fn number(value: f64, span: Span) -> Expr {
        Expr {
            kind: ExprKind::Number(value),
            span,
        }
    }

    /// Every name the expression refers to, with its span, in source order.
    pub fn names(&self) -> Vec<(&str, Span)> {
        let mut out = Vec::new();
        let mut stack = vec![self];
        while let Some(expr) = stack.pop() {
            match &expr.kind {
                ExprKind::Number(_) => {}
                ExprKind::Name(name) => out.push((name.as_str(), expr.span)),
                ExprKind::Neg(inner) => stack.push(inner),
                ExprKind::Binary(_, a, b) => {
                    stack.push(b);
                    stack.push(a);
                }
                ExprKind::Call(_, args) => stack.extend(args.iter().rev()),
            }
        }
        out
    }

    /// The value if the expression is a plain number literal.
    pub fn as_literal(&self) -> Option<f64> {
        match self.kind {
            ExprKind::Number(v) => Some(v),
            ExprKind::Neg(ref inner) => inner.as_literal().map(|v| -v),
            _ => None,
        }
    }
}
