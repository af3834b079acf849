//! The short forms most expressions of large files take: one name (`r`), or
//! one operator between two operands that are names or unsigned literals
//! (`r/2`, `2*r`, `h - 0.5`). They are read here in one pass over the bytes,
//! without the token list and the Pratt parser, into the tree the general
//! path makes of them. Anything else is `None` and goes the general way, which
//! also reports every error: the short form only accepts what parses.

use super::parse::{infix_power, is_space};
use super::{BinaryOp, Expr, ExprKind};
use crate::span::Span;

/// The expression of `text` (first byte at absolute offset `base`) if it is
/// a name, or `operand op operand` with names and unsigned literals without
/// exponent, spaces allowed around each operand; `None` otherwise.
pub(super) fn short_form(text: &str, base: usize) -> Option<Expr> {
    let bytes = text.as_bytes();
    let mut at = skip_space(bytes, 0);
    let (left, end) = operand(text, at, base)?;
    at = skip_space(bytes, end);
    let Some(&op) = bytes.get(at) else {
        // A single literal that got here did not parse (the plain-number path
        // takes the others): the general path reports it.
        return matches!(left.kind, ExprKind::Name(_)).then_some(left);
    };
    let op = binary_op(op)?;
    at = skip_space(bytes, at + 1);
    let (right, end) = operand(text, at, base)?;
    if skip_space(bytes, end) != bytes.len() {
        return None;
    }
    let span = Span::new(left.span.start as usize, right.span.end as usize);
    Some(Expr {
        kind: ExprKind::Binary(op, Box::new(left), Box::new(right)),
        span,
    })
}

/// The first index from `at` that is not a space the lexer skips.
fn skip_space(bytes: &[u8], mut at: usize) -> usize {
    while bytes.get(at).is_some_and(|&b| is_space(b)) {
        at += 1;
    }
    at
}

/// The parser's binary operator written as `byte`.
fn binary_op(byte: u8) -> Option<BinaryOp> {
    infix_power(char::from(byte)).map(|(_, _, op)| op)
}

/// A name or an unsigned literal starting at `at`, with the index after it.
/// What follows must end the token as the lexer would end it: a space, an
/// operator or the end (so `sin(`, `2e3`, `2r` are left to the general path).
fn operand(text: &str, at: usize, base: usize) -> Option<(Expr, usize)> {
    let bytes = text.as_bytes();
    let first = *bytes.get(at)?;
    let is_name = first.is_ascii_alphabetic() || first == b'_';
    let is_literal = first.is_ascii_digit() || first == b'.';
    let continues = |b: u8| {
        if is_name {
            b.is_ascii_alphanumeric() || b == b'_'
        } else {
            b.is_ascii_digit() || b == b'.'
        }
    };
    if !is_name && !is_literal {
        return None;
    }
    let mut end = at + 1;
    while bytes.get(end).is_some_and(|&b| continues(b)) {
        end += 1;
    }
    if let Some(&next) = bytes.get(end)
        && !(is_space(next) || binary_op(next).is_some())
    {
        return None;
    }
    let token = text.get(at..end)?;
    let span = Span::new(base + at, base + end);
    let kind = if is_name {
        ExprKind::Name(token.to_string())
    } else {
        ExprKind::Number(token.parse().ok()?)
    };
    Some((Expr { kind, span }, end))
}

#[cfg(test)]
mod tests {
    use super::super::parse::{ExprLimits, parse_tokens, parse_with};
    use super::*;
    use crate::test_rng::TestRng;

    #[test]
    fn short_forms_are_the_trees_of_the_general_path() {
        let limits = ExprLimits::default();
        for (text, want) in [
            ("r", "r"),
            (" r_2 ", "r_2"),
            ("r/2", "Div"),
            ("2*r", "Mul"),
            ("h - 0.5", "Sub"),
            ("\tr+1\n", "Add"),
            ("a^b", "Pow"),
            ("pi", "pi"),
        ] {
            let short = short_form(text, 30).expect("a short form");
            assert_eq!(
                Ok(short.clone()),
                parse_tokens(text, 30, &limits),
                "{text:?}"
            );
            let got = match &short.kind {
                ExprKind::Name(name) => name.clone(),
                ExprKind::Binary(op, _, _) => format!("{op:?}"),
                other => format!("{other:?}"),
            };
            assert_eq!(got, want, "{text:?}");
        }
        // `r/2` at 30: the name at 30..31, the literal at 32..33.
        let ExprKind::Binary(_, left, right) = short_form("r/2", 30).expect("short").kind else {
            panic!("r/2 is a binary expression");
        };
        assert_eq!(
            (left.span, right.span),
            (Span::new(30, 31), Span::new(32, 33))
        );
        for text in [
            "", " ", "2", "1.2.3", "-r", "r/-2", "sin(r)", "r/2e3", "2r", "r/2/3", "(r)", "r/",
            "/2", "r 2", "r..", "r/1.2.3", "é", "r/2 )",
        ] {
            assert_eq!(short_form(text, 0), None, "{text:?}");
        }
    }

    /// Texts near the short forms: names, literals, operators, spaces, and
    /// the bytes that make them something else.
    fn random_text(rng: &mut TestRng) -> String {
        const PIECES: &[&str] = &[
            "r", "h_2", "_", "pi", "sin", "2", "0.5", ".", "1.2.3", "7.", "e", "E3", " ", "\t",
            "+", "-", "*", "/", "^", "(", ")", ",", "é", "1e5",
        ];
        let mut text = String::new();
        for _ in 0..rng.below(6) {
            text.push_str(PIECES[rng.below(PIECES.len())]);
        }
        text
    }

    #[test]
    fn parsing_with_the_short_forms_gives_what_the_general_path_gives() {
        let mut rng = TestRng::new(0x5eed_e4b1);
        let tight = [
            ExprLimits::default(),
            ExprLimits {
                max_nodes: 2,
                max_depth: 256,
            },
            ExprLimits {
                max_nodes: 3,
                max_depth: 1,
            },
            ExprLimits {
                max_nodes: 3,
                max_depth: 2,
            },
            ExprLimits {
                max_nodes: 0,
                max_depth: 0,
            },
        ];
        let mut short = 0;
        for case in 0..60_000 {
            let text = random_text(&mut rng);
            let base = rng.below(1000);
            short += usize::from(short_form(&text, base).is_some());
            let limits = &tight[case % tight.len()];
            assert_eq!(
                parse_with(&text, base, limits),
                parse_tokens(&text, base, limits),
                "{text:?} at {base} with {limits:?}"
            );
        }
        // The generator reaches the short forms often, not only their misses.
        assert!(short > 5_000, "{short} short forms");
    }
}
