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
    let mut i = 0;
    while i < bytes.len() {
        let c = bytes[i];
        if c.is_ascii_whitespace() {
            i += 1;
            continue;
        }
        if text[i..].starts_with("//") {
            while i < bytes.len() && bytes[i] != b'\n' {
                i += 1;
            }
            continue;
        }
        if text[i..].starts_with("/*") {
            let Some(end) = text[i + 2..].find("*/") else {
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
            while i < bytes.len() && (bytes[i].is_ascii_digit() || bytes[i] == b'.') {
                i += 1;
            }
            if i < bytes.len() && (bytes[i] == b'e' || bytes[i] == b'E') {
                let mut k = i + 1;
                if k < bytes.len() && (bytes[k] == b'+' || bytes[k] == b'-') {
                    k += 1;
                }
                if k < bytes.len() && bytes[k].is_ascii_digit() {
                    i = k;
                    while i < bytes.len() && bytes[i].is_ascii_digit() {
                        i += 1;
                    }
                }
            }
            let s = &text[start..i];
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
            while i < bytes.len()
                && (bytes[i].is_ascii_alphanumeric() || bytes[i] == b'_' || bytes[i] == b'$')
            {
                i += 1;
            }
            out.push(Token {
                tok: Tok::Ident(text[start..i].to_string()),
                span: Span::new(start, i),
            });
            continue;
        }
        if c == b'"' || c == b'\'' {
            let Some(len) = text[i + 1..].find(c as char) else {
                return Err(LexError {
                    span: Span::new(i, i + 1),
                    message: "string is never closed".into(),
                });
            };
            let s = &text[i + 1..i + 1 + len];
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
        let ch = text[i..].chars().next().unwrap_or('?');
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
