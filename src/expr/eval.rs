//! Evaluating an expression against a name lookup.

use super::{BinaryOp, Expr, ExprKind, Function};
use crate::span::Span;

#[derive(Debug, Clone, PartialEq)]
pub enum EvalError {
    /// The lookup did not know the name.
    Unknown { name: String, span: Span },
    /// The result, or an intermediate value, is not finite.
    NonFinite { span: Span, what: String },
}

/// Evaluates `expr`; `lookup` gives the value of each name (`pi` is built in
/// unless the lookup defines it).
pub fn eval(
    expr: &Expr,
    lookup: &mut dyn FnMut(&str, Span) -> Option<f64>,
) -> Result<f64, EvalError> {
    let value = match &expr.kind {
        ExprKind::Number(v) => *v,
        ExprKind::Name(name) => match lookup(name, expr.span) {
            Some(v) => v,
            None if name == "pi" => std::f64::consts::PI,
            None => {
                return Err(EvalError::Unknown {
                    name: name.clone(),
                    span: expr.span,
                });
            }
        },
        ExprKind::Neg(inner) => -eval(inner, lookup)?,
        ExprKind::Binary(op, a, b) => {
            let a = eval(a, lookup)?;
            let b = eval(b, lookup)?;
            match op {
                BinaryOp::Add => a + b,
                BinaryOp::Sub => a - b,
                BinaryOp::Mul => a * b,
                BinaryOp::Div => {
                    if b == 0.0 {
                        return Err(EvalError::NonFinite {
                            span: expr.span,
                            what: format!("division of {a} by zero"),
                        });
                    }
                    a / b
                }
                BinaryOp::Pow => a.powf(b),
            }
        }
        ExprKind::Call(function, args) => {
            let mut values = Vec::with_capacity(args.len());
            for arg in args {
                values.push(eval(arg, lookup)?);
            }
            let x = values.first().copied().unwrap_or(f64::NAN);
            match function {
                Function::Sqrt => x.sqrt(),
                Function::Sin => x.sin(),
                Function::Cos => x.cos(),
                Function::Tan => x.tan(),
                Function::Asin => x.asin(),
                Function::Acos => x.acos(),
                Function::Atan => x.atan(),
                Function::Exp => x.exp(),
                Function::Ln => x.ln(),
                Function::Abs => x.abs(),
                Function::Min => values.iter().copied().fold(f64::INFINITY, f64::min),
                Function::Max => values.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            }
        }
    };
    if value.is_finite() {
        Ok(value)
    } else {
        Err(EvalError::NonFinite {
            span: expr.span,
            what: format!("the value is {value}"),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::super::{ParseError, parse};
    use super::*;

    fn value(text: &str) -> f64 {
        let expr = parse(text, 0).expect("parses");
        eval(&expr, &mut |name, _| match name {
            "r" => Some(0.5),
            "x1" => Some(2.0),
            _ => None,
        })
        .expect("evaluates")
    }

    #[test]
    fn precedence_and_functions() {
        assert_eq!(value("1 + 2 * 3"), 7.0);
        assert_eq!(value("-2^2"), -4.0);
        assert_eq!(value("2^3^2"), 512.0);
        assert_eq!(value("(1 + 2) * 3"), 9.0);
        assert_eq!(value("max(1, x1, r) - min(r, 3)"), 1.5);
        assert_eq!(value("1.5e1 + .5"), 15.5);
        assert!((value("sin(pi / 2)") - 1.0).abs() < 1e-15);
        assert_eq!(value("sqrt(x1 * 8)"), 4.0);
        assert_eq!(value("--3"), 3.0);
    }

    #[test]
    fn errors_are_located() {
        assert!(
            matches!(parse("1 +", 10), Err(ParseError::Syntax { span, .. }) if span.start == 13)
        );
        assert!(
            matches!(parse("foo(1)", 0), Err(ParseError::UnknownFunction { ref name, .. }) if name == "foo")
        );
        assert!(matches!(
            parse("min(1)", 0),
            Err(ParseError::WrongArgumentCount { given: 1, .. })
        ));
        assert!(matches!(parse("(1 + 2", 0), Err(ParseError::Syntax { .. })));
        assert!(matches!(parse("1 2", 0), Err(ParseError::Syntax { span, .. }) if span.start == 2));
        assert!(
            matches!(parse("1 $ 2", 0), Err(ParseError::Syntax { span, .. }) if span.start == 2)
        );
        let expr = parse("1 / (r - r)", 0).expect("parses");
        let result = eval(&expr, &mut |_, _| Some(1.0));
        assert!(matches!(result, Err(EvalError::NonFinite { .. })));
        // The tree's depth is bounded, not only the parser's recursion: a long
        // left-associative chain is as deep as it is long.
        let chain = vec!["1"; 300].join("+");
        assert!(matches!(parse(&chain, 0), Err(ParseError::TooLarge { .. })));
        let chain = vec!["1"; 200].join("+");
        assert_eq!(
            eval(&parse(&chain, 0).expect("parses"), &mut |_, _| None),
            Ok(200.0)
        );
        let deep = "(".repeat(1000) + "1" + &")".repeat(1000);
        assert!(matches!(parse(&deep, 0), Err(ParseError::TooLarge { .. })));
    }
}
