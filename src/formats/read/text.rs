//! A byte-level scanner for the text formats (ASCII STL, OBJ, ASCII MSH):
//! whitespace-separated tokens with their byte offsets, so every error can
//! point at line:column without the reader keeping a line index.

use super::error_at;
use crate::diag::{Code, Diagnostic};

/// Tokens of a text, left to right.
pub struct Scanner<'a> {
    pub bytes: &'a [u8],
    pub pos: usize,
}

/// A token and where it starts.
#[derive(Debug, Clone, Copy)]
pub struct Token<'a> {
    pub text: &'a [u8],
    pub start: usize,
}

impl Token<'_> {
    pub fn end(&self) -> usize {
        self.start + self.text.len()
    }

    pub fn lossy(&self) -> String {
        String::from_utf8_lossy(self.text).into_owned()
    }

    pub fn is(&self, word: &str) -> bool {
        self.text == word.as_bytes()
    }
}

impl<'a> Scanner<'a> {
    pub fn new(bytes: &'a [u8]) -> Scanner<'a> {
        Scanner { bytes, pos: 0 }
    }

    /// The next token, skipping whitespace and line ends; `None` at the end.
    pub fn next_token(&mut self) -> Option<Token<'a>> {
        let b = self.bytes;
        while b.get(self.pos).is_some_and(u8::is_ascii_whitespace) {
            self.pos += 1;
        }
        let start = self.pos;
        let rest = b.get(start..).filter(|r| !r.is_empty())?;
        let len = rest
            .iter()
            .position(u8::is_ascii_whitespace)
            .unwrap_or(rest.len());
        self.pos += len;
        Some(Token {
            text: rest.get(..len).unwrap_or(rest),
            start,
        })
    }

    /// The next token on the current line only.
    pub fn next_on_line(&mut self) -> Option<Token<'a>> {
        let b = self.bytes;
        while b
            .get(self.pos)
            .is_some_and(|&c| c != b'\n' && c.is_ascii_whitespace())
        {
            self.pos += 1;
        }
        if b.get(self.pos).is_none_or(|&c| c == b'\n') {
            return None;
        }
        self.next_token()
    }

    /// Skips to just after the next line end.
    pub fn skip_line(&mut self) {
        while self.bytes.get(self.pos).is_some_and(|&c| c != b'\n') {
            self.pos += 1;
        }
        if self.pos < self.bytes.len() {
            self.pos += 1;
        }
    }

    /// The rest of the current line (without its line end), and moves past it.
    pub fn rest_of_line(&mut self) -> Token<'a> {
        let start = self.pos;
        while self.bytes.get(self.pos).is_some_and(|&c| c != b'\n') {
            self.pos += 1;
        }
        let line = self.bytes.get(start..self.pos).unwrap_or_default();
        let text = line.trim_ascii_end();
        if self.pos < self.bytes.len() {
            self.pos += 1;
        }
        Token { text, start }
    }

    /// The next token, or an error saying what was expected at the end of the file.
    pub fn expect(&mut self, what: &str) -> Result<Token<'a>, Diagnostic> {
        self.next_token().ok_or_else(|| self.truncated(what))
    }

    pub fn truncated(&self, what: &str) -> Diagnostic {
        let end = self.bytes.len();
        error_at(
            Code::MeshTruncated,
            end.saturating_sub(1),
            end,
            format!("the file ends where {what} was expected"),
        )
        .with_help("the file is truncated: write it again, or check that the copy is complete")
    }

    pub fn real(&mut self, what: &str) -> Result<f64, Diagnostic> {
        let t = self.expect(what)?;
        real(t, what)
    }

    pub fn unsigned(&mut self, what: &str) -> Result<u64, Diagnostic> {
        let t = self.expect(what)?;
        unsigned(t, what)
    }

    pub fn integer(&mut self, what: &str) -> Result<i64, Diagnostic> {
        let t = self.expect(what)?;
        integer(t, what)
    }

    /// Expects a keyword, e.g. `$EndNodes`.
    pub fn keyword(&mut self, word: &str) -> Result<Token<'a>, Diagnostic> {
        let t = self.expect(&format!("`{word}`"))?;
        if t.is(word) {
            Ok(t)
        } else {
            Err(syntax(t, &format!("`{word}`")))
        }
    }
}

pub fn syntax(t: Token, expected: &str) -> Diagnostic {
    error_at(
        Code::MeshSyntax,
        t.start,
        t.end(),
        format!("expected {expected}, found `{}`", shorten(&t.lossy())),
    )
}

fn shorten(s: &str) -> String {
    if s.chars().count() > 40 {
        format!("{}…", s.chars().take(40).collect::<String>())
    } else {
        s.to_string()
    }
}

/// A finite real number; NaN and infinities are their own error.
pub fn real(t: Token, what: &str) -> Result<f64, Diagnostic> {
    let v: f64 = std::str::from_utf8(t.text)
        .ok()
        .and_then(|s| s.parse().ok())
        .ok_or_else(|| syntax(t, &format!("a number ({what})")))?;
    if !v.is_finite() {
        return Err(error_at(
            Code::MeshNonFinite,
            t.start,
            t.end(),
            format!("{what} is `{}`, not a finite number", t.lossy()),
        )
        .with_help("meshes need finite coordinates: fix or remove the element in the tool that wrote the file"));
    }
    Ok(v)
}

pub fn unsigned(t: Token, what: &str) -> Result<u64, Diagnostic> {
    std::str::from_utf8(t.text)
        .ok()
        .and_then(|s| s.parse().ok())
        .ok_or_else(|| syntax(t, &format!("a non-negative integer ({what})")))
}

pub fn integer(t: Token, what: &str) -> Result<i64, Diagnostic> {
    std::str::from_utf8(t.text)
        .ok()
        .and_then(|s| s.parse().ok())
        .ok_or_else(|| syntax(t, &format!("an integer ({what})")))
}
