//! Paper 001's modelling language (`.rfs` files): lexer → parser → expansion
//! of the result function into one IR expression.

// User-controlled bytes and values: no panicking index (docs/reliability.md).
#![cfg_attr(not(test), deny(clippy::indexing_slicing))]

pub mod ast;
pub mod expand;
pub mod lexer;
pub mod parser;

use super::ImplicitModel;
use crate::diag::{Code, Diagnostic, Diagnostics};
use crate::span::SourceFile;

/// Compiles an `.rfs` program; the model is `None` when there are errors.
pub fn compile(source: &SourceFile) -> (Option<ImplicitModel>, Diagnostics) {
    let mut diags = Diagnostics::default();
    let tokens = match lexer::lex(&source.text) {
        Ok(t) => t,
        Err(e) => {
            diags.push(Diagnostic::new(Code::RfsSyntax, e.span, e.message));
            return (None, diags);
        }
    };
    let program = match parser::parse(&tokens) {
        Ok(p) => p,
        Err(e) => {
            let code = if e.too_deep {
                Code::RfsTooLarge
            } else {
                Code::RfsSyntax
            };
            diags.push(Diagnostic::new(code, e.span, e.message));
            return (None, diags);
        }
    };
    let geom = expand::read_geom(&program, &mut diags);
    // Geom.optiterations is applied by `ImplicitModel::polygonize` (W131 is
    // no longer emitted).
    let expanded = if diags.has_errors() {
        None
    } else {
        expand::expand(&program, &geom, &mut diags)
    };
    diags.sort();
    let model = expanded.map(|(ctx, root)| ImplicitModel { geom, ctx, root });
    (model, diags)
}
