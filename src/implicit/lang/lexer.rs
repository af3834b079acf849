//! Tokens of paper 001's modelling language (an ECMAScript subset), with byte
//! spans. `//` and `/* */` comments are skipped.

use crate::span::Span;

#[derive(Debug, Clone, PartialEq)]
pub enum Tok {
    Num(f64),
    Ident(String),
    Str(String),
    /// One of ( ) { } , ; = + - * / . %
    Punct(char),
    Eof,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Token {
    pub tok: Tok,
    pub span: Span,
}

/// A lexical error: what was found, where.
#[derive(Debug, Clone, PartialEq)]
pub struct LexError {
    pub span: Span,
    pub message: String,
}

pub fn lex(text: &str) -> Result<Vec<Token>, LexError> {
    let bytes = text.as_bytes();
    let mut out = Vec::new();
    // Out of range reads as 0, which no token contains.
    let at = |k: usize| bytes.get(k).copied().unwrap_or(0);
    let rest = |k: usize| text.get(k..).unwrap_or_default();
    let mut i = 0;
    while let Some(&c) = bytes.get(i) {
        if c.is_ascii_whitespace() {
            i += 1;
            continue;
        }
        if rest(i).starts_with("//") {
            while i < bytes.len() && at(i) != b'\n' {
                i += 1;
            }
            continue;
        }
        if rest(i).starts_with("/*") {
            let Some(end) = rest(i + 2).find("*/") else {
                return Err(LexError {
                    span: Span::new(i, i + 2),
                    message: "comment opened here is never closed with */".into(),
                });
            };
            i += end + 4;
            continue;
        }
        let start = i;
        if c.is_ascii_digit() || (c == b'.' && bytes.get(i + 1).is_some_and(u8::is_ascii_digit)) {
            while at(i).is_ascii_digit() || at(i) == b'.' {
                i += 1;
            }
            if at(i) == b'e' || at(i) == b'E' {
                let mut k = i + 1;
                if at(k) == b'+' || at(k) == b'-' {
                    k += 1;
                }
                if at(k).is_ascii_digit() {
                    i = k;
                    while at(i).is_ascii_digit() {
                        i += 1;
                    }
                }
            }
            let s = text.get(start..i).unwrap_or_default();
            let v: f64 = s.parse().map_err(|_| LexError {
                span: Span::new(start, i),
                message: format!("'{s}' is not a number"),
            })?;
            out.push(Token {
                tok: Tok::Num(v),
                span: Span::new(start, i),
            });
            continue;
        }
        if c.is_ascii_alphabetic() || c == b'_' || c == b'$' {
            while at(i).is_ascii_alphanumeric() || at(i) == b'_' || at(i) == b'$' {
                i += 1;
            }
            out.push(Token {
                tok: Tok::Ident(text.get(start..i).unwrap_or_default().to_string()),
                span: Span::new(start, i),
            });
            continue;
        }
        if c == b'"' || c == b'\'' {
            let Some(len) = rest(i + 1).find(c as char) else {
                return Err(LexError {
                    span: Span::new(i, i + 1),
                    message: "string is never closed".into(),
                });
            };
            let s = rest(i + 1).get(..len).unwrap_or_default();
            if s.contains('\n') {
                return Err(LexError {
                    span: Span::new(i, i + 1),
                    message: "string is never closed on its line".into(),
                });
            }
            i += len + 2;
            out.push(Token {
                tok: Tok::Str(s.to_string()),
                span: Span::new(start, i),
            });
            continue;
        }
        if "(){},;=+-*/.%".contains(c as char) {
            i += 1;
            out.push(Token {
                tok: Tok::Punct(c as char),
                span: Span::new(start, i),
            });
            continue;
        }
        let ch = rest(i).chars().next().unwrap_or('?');
        return Err(LexError {
            span: Span::new(i, i + ch.len_utf8()),
            message: format!("unexpected character '{ch}'"),
        });
    }
    out.push(Token {
        tok: Tok::Eof,
        span: Span::new(text.len(), text.len()),
    });
    Ok(out)
}
