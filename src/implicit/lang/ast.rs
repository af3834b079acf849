//! The syntax tree of an `.rfs` program: `Geom.<field> = value;` settings and
//! `function name(args) { … }` definitions.

use crate::span::Span;

#[derive(Debug, Clone, PartialEq)]
pub enum Expr {
    Num(f64, Span),
    Str(String, Span),
    /// A variable or parameter.
    Name(String, Span),
    /// `Math.PI`, `Geom.x_min`: an object and a field.
    Member(String, String, Span),
    /// A call of a function, a library function or `Math.<name>`.
    Call {
        callee: String,
        callee_span: Span,
        args: Vec<Expr>,
        span: Span,
    },
    Neg(Box<Expr>, Span),
    Binary(char, Box<Expr>, Box<Expr>, Span),
}

impl Expr {
    pub fn span(&self) -> Span {
        match self {
            Expr::Num(_, s)
            | Expr::Str(_, s)
            | Expr::Name(_, s)
            | Expr::Member(_, _, s)
            | Expr::Neg(_, s)
            | Expr::Binary(_, _, _, s) => *s,
            Expr::Call { span, .. } => *span,
        }
    }
}

#[derive(Debug, Clone, PartialEq)]
pub enum Stmt {
    /// `var a = e, b = f;`
    Var(Vec<(String, Span, Expr)>),
    /// `a = e;`
    Assign(String, Span, Expr),
    Return(Expr, Span),
}

#[derive(Debug, Clone, PartialEq)]
pub struct Function {
    pub name: String,
    pub span: Span,
    pub params: Vec<(String, Span)>,
    pub body: Vec<Stmt>,
}

#[derive(Debug, Clone, PartialEq, Default)]
pub struct Program {
    /// `Geom.<field> = value;` in file order.
    pub geom: Vec<(String, Span, Expr)>,
    pub functions: Vec<Function>,
}
