//! A Pratt parser for expressions, with a bound on size and depth so that a
//! hostile attribute cannot exhaust the stack.

use super::{BinaryOp, Expr, ExprKind, Function};
use crate::span::Span;

/// Most nodes one expression may have (the default; `--max-expression-nodes`).
pub const MAX_NODES: usize = 10_000;
/// Deepest nesting of one expression (the default; `--max-expression-depth`).
pub const MAX_DEPTH: usize = 256;

/// The size bounds of one expression. Parsing, evaluation and dropping
/// recurse over the tree, so the depth stays bounded even when raised.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ExprLimits {
    pub max_nodes: usize,
    pub max_depth: usize,
}

impl Default for ExprLimits {
    fn default() -> ExprLimits {
        ExprLimits {
            max_nodes: MAX_NODES,
            max_depth: MAX_DEPTH,
        }
    }
}

#[derive(Debug, Clone, PartialEq)]
pub enum ParseError {
    /// Malformed syntax; the message says what was expected.
    Syntax {
        span: Span,
        message: String,
    },
    UnknownFunction {
        span: Span,
        name: String,
    },
    WrongArgumentCount {
        span: Span,
        function: Function,
        given: usize,
    },
    TooLarge {
        span: Span,
    },
}

#[derive(Debug, Clone, PartialEq)]
enum Token {
    Number(f64),
    Ident(String),
    Op(char),
    LParen,
    RParen,
    Comma,
}

/// Parses `text`, whose first byte is at absolute offset `base` in the source file.
pub fn parse(text: &str, base: usize) -> Result<Expr, ParseError> {
    parse_with(text, base, &ExprLimits::default())
}

/// [`parse`] with the size bounds given.
pub fn parse_with(text: &str, base: usize, limits: &ExprLimits) -> Result<Expr, ParseError> {
    let first = text.bytes().find(|&b| !is_space(b));
    if limits.max_nodes >= 1
        && matches!(first, Some(b'0'..=b'9' | b'.'))
        && let Some(expr) = plain_number(text, base)
    {
        return Ok(expr);
    }
    // Room for the three nodes and two levels of `a op b`, so the short form
    // never has to report a limit the general path would report.
    if limits.max_nodes >= 3
        && limits.max_depth >= 2
        && let Some(expr) = super::short::short_form(text, base)
    {
        return Ok(expr);
    }
    parse_tokens(text, base, limits)
}

/// The general path of [`parse_with`]: tokens, then the Pratt parser.
pub(super) fn parse_tokens(
    text: &str,
    base: usize,
    limits: &ExprLimits,
) -> Result<Expr, ParseError> {
    let tokens = lex(text, base)?;
    let end = base + text.len();
    let mut parser = Parser {
        tokens,
        pos: 0,
        nodes: 0,
        end,
        limits: *limits,
    };
    if parser.tokens.is_empty() {
        return Err(ParseError::Syntax {
            span: Span::new(base, end),
            message: "expected a number or an expression, found nothing".into(),
        });
    }
    let (expr, _) = parser.expression(0, 0)?;
    if let Some((token, span)) = parser.tokens.get(parser.pos) {
        let what = match token {
            Token::RParen => "an unmatched ')'".to_string(),
            other => format!("{} after a complete expression", describe(other)),
        };
        return Err(ParseError::Syntax {
            span: *span,
            message: format!("unexpected {what}"),
        });
    }
    Ok(expr)
}

/// The expression of a text that is one unsigned literal without exponent
/// (most attributes), made without the token list; the same value and span as
/// the general path. Anything else, or a literal that does not parse, is `None`.
fn plain_number(text: &str, base: usize) -> Option<Expr> {
    let space = [' ', '\t', '\n', '\r'];
    let body = text.trim_matches(space);
    let start = text.len() - text.trim_start_matches(space).len();
    let plain = !body.is_empty() && body.bytes().all(|b| b.is_ascii_digit() || b == b'.');
    let value: f64 = plain.then(|| body.parse().ok())??;
    let span = Span::new(base + start, base + start + body.len());
    Some(Expr::number(value, span))
}

fn describe(token: &Token) -> String {
    match token {
        Token::Number(v) => format!("number {v}"),
        Token::Ident(name) => format!("name '{name}'"),
        Token::Op(c) => format!("'{c}'"),
        Token::LParen => "'('".into(),
        Token::RParen => "')'".into(),
        Token::Comma => "','".into(),
    }
}

fn lex(text: &str, base: usize) -> Result<Vec<(Token, Span)>, ParseError> {
    let bytes = text.as_bytes();
    let mut tokens = Vec::new();
    // Out of range reads as 0, which no token starts with.
    let at = |k: usize| bytes.get(k).copied().unwrap_or(0);
    let mut i = 0;
    while let Some(&c) = bytes.get(i) {
        let start = i;
        match c {
            c if is_space(c) => {
                i += 1;
                continue;
            }
            b'0'..=b'9' | b'.' => {
                while at(i).is_ascii_digit() || at(i) == b'.' {
                    i += 1;
                }
                if at(i) == b'e' || at(i) == b'E' {
                    let mut j = i + 1;
                    if at(j) == b'+' || at(j) == b'-' {
                        j += 1;
                    }
                    if at(j).is_ascii_digit() {
                        while at(j).is_ascii_digit() {
                            j += 1;
                        }
                        i = j;
                    }
                }
                let literal = text.get(start..i).unwrap_or_default();
                let value: f64 = literal.parse().map_err(|_| ParseError::Syntax {
                    span: Span::new(base + start, base + i),
                    message: format!("'{literal}' is not a number"),
                })?;
                tokens.push((Token::Number(value), Span::new(base + start, base + i)));
                continue;
            }
            b'+' | b'-' | b'*' | b'/' | b'^' => {
                tokens.push((Token::Op(c as char), Span::new(base + i, base + i + 1)))
            }
            b'(' => tokens.push((Token::LParen, Span::new(base + i, base + i + 1))),
            b')' => tokens.push((Token::RParen, Span::new(base + i, base + i + 1))),
            b',' => tokens.push((Token::Comma, Span::new(base + i, base + i + 1))),
            c if c.is_ascii_alphabetic() || c == b'_' => {
                while at(i).is_ascii_alphanumeric() || at(i) == b'_' {
                    i += 1;
                }
                tokens.push((
                    Token::Ident(text.get(start..i).unwrap_or_default().to_string()),
                    Span::new(base + start, base + i),
                ));
                continue;
            }
            _ => {
                let ch = text[i..].chars().next().unwrap_or('?');
                return Err(ParseError::Syntax {
                    span: Span::new(base + i, base + i + ch.len_utf8()),
                    message: format!("unexpected character '{ch}' in an expression"),
                });
            }
        }
        i += 1;
    }
    Ok(tokens)
}

struct Parser {
    tokens: Vec<(Token, Span)>,
    pos: usize,
    nodes: usize,
    end: usize,
    limits: ExprLimits,
}

/// A space the lexer skips between tokens.
pub(super) fn is_space(byte: u8) -> bool {
    matches!(byte, b' ' | b'\t' | b'\n' | b'\r')
}

/// Binding powers: (left, right). `^` is right-associative and binds tighter
/// than unary minus on its left (-2^2 = -4), as in mathematics.
pub(super) fn infix_power(op: char) -> Option<(u8, u8, BinaryOp)> {
    Some(match op {
        '+' => (1, 2, BinaryOp::Add),
        '-' => (1, 2, BinaryOp::Sub),
        '*' => (3, 4, BinaryOp::Mul),
        '/' => (3, 4, BinaryOp::Div),
        '^' => (8, 7, BinaryOp::Pow),
        _ => return None,
    })
}
const PREFIX_POWER: u8 = 5;

impl Parser {
    fn peek(&self) -> Option<&(Token, Span)> {
        self.tokens.get(self.pos)
    }

    fn end_span(&self) -> Span {
        Span::new(self.end, self.end)
    }

    fn node(&mut self, span: Span) -> Result<(), ParseError> {
        self.nodes += 1;
        if self.nodes > self.limits.max_nodes {
            return Err(ParseError::TooLarge { span });
        }
        Ok(())
    }

    /// Parses an expression and returns it with the depth of its tree: the
    /// tree's depth is bounded (not only the parser's recursion), so that every
    /// recursive walk over it (evaluation, folding, dropping) stays shallow.
    fn expression(&mut self, min_power: u8, depth: usize) -> Result<(Expr, usize), ParseError> {
        let (mut left, mut left_depth) = self.prefix(depth)?;
        while let Some((Token::Op(op), _)) = self.peek() {
            let Some((lp, rp, bin)) = infix_power(*op) else {
                break;
            };
            if lp < min_power {
                break;
            }
            self.pos += 1;
            let (right, right_depth) = self.expression(rp, depth + 1)?;
            let span = Span::new(left.span.start as usize, right.span.end as usize);
            self.node(span)?;
            left_depth = left_depth.max(right_depth) + 1;
            if left_depth > self.limits.max_depth {
                return Err(ParseError::TooLarge { span });
            }
            left = Expr {
                kind: ExprKind::Binary(bin, Box::new(left), Box::new(right)),
                span,
            };
        }
        Ok((left, left_depth))
    }

    fn prefix(&mut self, depth: usize) -> Result<(Expr, usize), ParseError> {
        let Some((token, span)) = self.peek().cloned() else {
            return Err(ParseError::Syntax {
                span: self.end_span(),
                message: "expected a number, a name or '(' but the expression ends".into(),
            });
        };
        if depth > self.limits.max_depth {
            return Err(ParseError::TooLarge { span });
        }
        self.node(span)?;
        self.pos += 1;
        match token {
            Token::Number(value) => Ok((Expr::number(value, span), 1)),
            Token::Op('-') => {
                let (inner, inner_depth) = self.expression(PREFIX_POWER, depth + 1)?;
                let span = Span::new(span.start as usize, inner.span.end as usize);
                Ok((
                    Expr {
                        kind: ExprKind::Neg(Box::new(inner)),
                        span,
                    },
                    inner_depth + 1,
                ))
            }
            Token::Op('+') => self.expression(PREFIX_POWER, depth + 1),
            Token::LParen => {
                let inner = self.expression(0, depth + 1)?;
                self.expect_rparen(span)?;
                Ok(inner)
            }
            Token::Ident(name) => {
                if matches!(self.peek(), Some((Token::LParen, _))) {
                    self.pos += 1;
                    self.call(name, span, depth)
                } else {
                    Ok((
                        Expr {
                            kind: ExprKind::Name(name),
                            span,
                        },
                        1,
                    ))
                }
            }
            other => Err(ParseError::Syntax {
                span,
                message: format!(
                    "expected a number, a name or '(', found {}",
                    describe(&other)
                ),
            }),
        }
    }

    fn call(
        &mut self,
        name: String,
        name_span: Span,
        depth: usize,
    ) -> Result<(Expr, usize), ParseError> {
        let Some(function) = Function::lookup(&name) else {
            return Err(ParseError::UnknownFunction {
                span: name_span,
                name,
            });
        };
        let mut args = Vec::new();
        let mut deepest = 0;
        if !matches!(self.peek(), Some((Token::RParen, _))) {
            loop {
                let (arg, arg_depth) = self.expression(0, depth + 1)?;
                deepest = deepest.max(arg_depth);
                args.push(arg);
                match self.peek() {
                    Some((Token::Comma, _)) => self.pos += 1,
                    _ => break,
                }
            }
        }
        let close = self.expect_rparen(name_span)?;
        let span = Span::new(name_span.start as usize, close.end as usize);
        let arity_ok = if function.is_variadic() {
            args.len() >= 2
        } else {
            args.len() == 1
        };
        if !arity_ok {
            return Err(ParseError::WrongArgumentCount {
                span,
                function,
                given: args.len(),
            });
        }
        Ok((
            Expr {
                kind: ExprKind::Call(function, args),
                span,
            },
            deepest + 1,
        ))
    }

    fn expect_rparen(&mut self, open: Span) -> Result<Span, ParseError> {
        match self.peek().cloned() {
            Some((Token::RParen, span)) => {
                self.pos += 1;
                Ok(span)
            }
            Some((token, span)) => Err(ParseError::Syntax {
                span,
                message: format!(
                    "expected ')' to close the '(' at byte {}, found {}",
                    open.start,
                    describe(&token)
                ),
            }),
            None => Err(ParseError::Syntax {
                span: self.end_span(),
                message: "expected ')' but the expression ends".into(),
            }),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plain_numbers_parse_as_the_general_path_does() {
        let limits = ExprLimits::default();
        for text in [
            "2",
            " 0.5 ",
            "10.25",
            ".5",
            "1.",
            "007",
            "\t3\n",
            "123456789.125",
        ] {
            let general = parse_tokens(text, 40, &limits).expect("a number");
            assert_eq!(plain_number(text, 40), Some(general), "{text:?}");
        }
        for text in [
            "1.2.3", ".", "", "  ", "1e5", "-2", "r", "2*r", "1 2", "1,5",
        ] {
            assert_eq!(plain_number(text, 40), None, "{text:?}");
        }
        // Invalid literals still get the general path's error.
        assert!(matches!(
            parse_with("1.2.3", 0, &limits),
            Err(ParseError::Syntax { .. })
        ));
    }
}
