//! Recursive-descent parser of `.rfs` programs. Nesting is bounded so no
//! input can overflow the stack; the first syntax error stops the parse.

use super::ast::{Expr, Function, Program, Stmt};
use super::lexer::{Tok, Token};
use crate::span::Span;

/// Deepest accepted expression nesting.
pub const MAX_DEPTH: usize = 200;

#[derive(Debug, Clone, PartialEq)]
pub struct ParseError {
    pub span: Span,
    pub message: String,
    /// The nesting limit was hit (a different diagnostic code).
    pub too_deep: bool,
}

struct Parser<'t> {
    toks: &'t [Token],
    pos: usize,
    depth: usize,
}

pub fn parse(toks: &[Token]) -> Result<Program, ParseError> {
    let mut p = Parser {
        toks,
        pos: 0,
        depth: 0,
    };
    let mut program = Program::default();
    loop {
        match p.peek().clone() {
            Tok::Eof => return Ok(program),
            Tok::Punct(';') => {
                p.pos += 1;
            }
            Tok::Ident(word) if word == "function" => {
                p.pos += 1;
                program.functions.push(p.function()?);
            }
            Tok::Ident(word) if word == "Geom" => {
                p.pos += 1;
                p.expect('.')?;
                let (field, span) = p.ident("a Geom field name")?;
                p.expect('=')?;
                let value = p.expr()?;
                p.expect(';')?;
                program.geom.push((field, span, value));
            }
            _ => {
                return Err(
                    p.error("expected `Geom.<field> = value;` or `function name(args) { … }`")
                );
            }
        }
    }
}

impl Parser<'_> {
    /// The current token; the lexer ends every list with `Eof`, and the
    /// parser never moves past it, so the fallbacks are never taken.
    fn peek(&self) -> &Tok {
        static EOF: Tok = Tok::Eof;
        self.toks.get(self.pos).map_or(&EOF, |t| &t.tok)
    }

    fn span(&self) -> Span {
        self.toks
            .get(self.pos)
            .or(self.toks.last())
            .map_or(Span::new(0, 0), |t| t.span)
    }

    fn describe(&self) -> String {
        match self.peek() {
            Tok::Num(v) => format!("number {v}"),
            Tok::Ident(s) => format!("'{s}'"),
            Tok::Str(s) => format!("string \"{s}\""),
            Tok::Punct(c) => format!("'{c}'"),
            Tok::Eof => "end of file".into(),
        }
    }

    fn error(&self, expected: &str) -> ParseError {
        ParseError {
            span: self.span(),
            message: format!("{expected}, found {}", self.describe()),
            too_deep: false,
        }
    }

    fn eat(&mut self, c: char) -> bool {
        if *self.peek() == Tok::Punct(c) {
            self.pos += 1;
            true
        } else {
            false
        }
    }

    fn expect(&mut self, c: char) -> Result<(), ParseError> {
        if self.eat(c) {
            Ok(())
        } else {
            Err(self.error(&format!("expected '{c}'")))
        }
    }

    fn ident(&mut self, what: &str) -> Result<(String, Span), ParseError> {
        if let Tok::Ident(s) = self.peek().clone() {
            let span = self.span();
            self.pos += 1;
            Ok((s, span))
        } else {
            Err(self.error(&format!("expected {what}")))
        }
    }

    fn keyword(&self, word: &str) -> bool {
        matches!(self.peek(), Tok::Ident(s) if s == word)
    }

    fn function(&mut self) -> Result<Function, ParseError> {
        let (name, span) = self.ident("a function name")?;
        self.expect('(')?;
        let mut params = Vec::new();
        if !self.eat(')') {
            loop {
                params.push(self.ident("a parameter name")?);
                if self.eat(')') {
                    break;
                }
                self.expect(',')?;
            }
        }
        self.expect('{')?;
        let mut body = Vec::new();
        while !self.eat('}') {
            if *self.peek() == Tok::Eof {
                return Err(self.error(&format!("expected '}}' closing function {name}")));
            }
            if self.eat(';') {
                continue;
            }
            body.push(self.statement()?);
        }
        Ok(Function {
            name,
            span,
            params,
            body,
        })
    }

    fn statement(&mut self) -> Result<Stmt, ParseError> {
        if self.keyword("var") {
            self.pos += 1;
            let mut decls = Vec::new();
            loop {
                let (name, span) = self.ident("a variable name")?;
                self.expect('=')?;
                decls.push((name, span, self.expr()?));
                if !self.eat(',') {
                    break;
                }
            }
            self.expect(';')?;
            return Ok(Stmt::Var(decls));
        }
        if self.keyword("return") {
            let span = self.span();
            self.pos += 1;
            let e = self.expr()?;
            self.expect(';')?;
            return Ok(Stmt::Return(e, span));
        }
        let (name, span) = self.ident("a statement (var, return or an assignment)")?;
        self.expect('=')?;
        let e = self.expr()?;
        self.expect(';')?;
        Ok(Stmt::Assign(name, span, e))
    }

    fn expr(&mut self) -> Result<Expr, ParseError> {
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            return Err(ParseError {
                span: self.span(),
                message: format!("expression nested deeper than {MAX_DEPTH} levels"),
                too_deep: true,
            });
        }
        let r = self.additive();
        self.depth -= 1;
        r
    }

    fn additive(&mut self) -> Result<Expr, ParseError> {
        let mut lhs = self.term()?;
        while let Tok::Punct(op @ ('+' | '-')) = *self.peek() {
            self.pos += 1;
            let rhs = self.term()?;
            let span = Span::new(lhs.span().start as usize, rhs.span().end as usize);
            lhs = Expr::Binary(op, Box::new(lhs), Box::new(rhs), span);
        }
        Ok(lhs)
    }

    fn term(&mut self) -> Result<Expr, ParseError> {
        let mut lhs = self.unary()?;
        while let Tok::Punct(op @ ('*' | '/' | '%')) = *self.peek() {
            self.pos += 1;
            let rhs = self.unary()?;
            let span = Span::new(lhs.span().start as usize, rhs.span().end as usize);
            lhs = Expr::Binary(op, Box::new(lhs), Box::new(rhs), span);
        }
        Ok(lhs)
    }

    fn unary(&mut self) -> Result<Expr, ParseError> {
        let start = self.span();
        if self.eat('-') {
            let inner = self.nested(Self::unary)?;
            let span = Span::new(start.start as usize, inner.span().end as usize);
            return Ok(Expr::Neg(Box::new(inner), span));
        }
        if self.eat('+') {
            return self.nested(Self::unary);
        }
        self.primary()
    }

    fn nested(&mut self, f: fn(&mut Self) -> Result<Expr, ParseError>) -> Result<Expr, ParseError> {
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            return Err(ParseError {
                span: self.span(),
                message: format!("expression nested deeper than {MAX_DEPTH} levels"),
                too_deep: true,
            });
        }
        let r = f(self);
        self.depth -= 1;
        r
    }

    fn primary(&mut self) -> Result<Expr, ParseError> {
        let span = self.span();
        match self.peek().clone() {
            Tok::Num(v) => {
                self.pos += 1;
                Ok(Expr::Num(v, span))
            }
            Tok::Str(s) => {
                self.pos += 1;
                Ok(Expr::Str(s, span))
            }
            Tok::Punct('(') => {
                self.pos += 1;
                let e = self.expr()?;
                self.expect(')')?;
                Ok(e)
            }
            Tok::Ident(name) => {
                self.pos += 1;
                let (callee, callee_span) = if self.eat('.') {
                    let (field, fspan) = self.ident(&format!("a field name after '{name}.'"))?;
                    let full = Span::new(span.start as usize, fspan.end as usize);
                    if *self.peek() != Tok::Punct('(') {
                        return Ok(Expr::Member(name, field, full));
                    }
                    (format!("{name}.{field}"), full)
                } else {
                    (name, span)
                };
                if !self.eat('(') {
                    return Ok(Expr::Name(callee, callee_span));
                }
                let mut args = Vec::new();
                if !self.eat(')') {
                    loop {
                        args.push(self.expr()?);
                        if self.eat(')') {
                            break;
                        }
                        self.expect(',')?;
                    }
                }
                let end = self
                    .toks
                    .get(self.pos.wrapping_sub(1))
                    .map_or(span.end, |t| t.span.end) as usize;
                Ok(Expr::Call {
                    callee,
                    callee_span,
                    args,
                    span: Span::new(span.start as usize, end),
                })
            }
            _ => Err(self.error("expected a number, a name, a call or '('")),
        }
    }
}
