//! The global name table: every definition's name, its kind and span;
//! duplicates and names that cannot be referenced everywhere are reported here.

use crate::diag::{Code, Diagnostic, Diagnostics};
use crate::doc::Document;
use crate::span::{SourceFile, Span};
use foldhash::HashMap;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Definition {
    pub kind: &'static str,
    pub span: Span,
}

/// Keys borrow the document's names (hundreds of thousands on large files:
/// no string is copied).
#[derive(Debug, Default)]
pub struct NameTable<'d> {
    pub defs: HashMap<&'d str, Definition>,
}

impl<'d> NameTable<'d> {
    pub fn build(source: &SourceFile, doc: &'d Document, diags: &mut Diagnostics) -> NameTable<'d> {
        let mut table = NameTable::default();
        let mut all: Vec<(&'d str, &'static str, Span)> = Vec::new();
        all.extend(
            doc.parameters
                .iter()
                .map(|p| (p.name.text.as_str(), "parameter", p.name.span)),
        );
        all.extend(
            doc.basis
                .iter()
                .map(|b| (b.name.text.as_str(), "basis coordinate", b.name.span)),
        );
        all.extend(
            doc.coordinate_systems
                .iter()
                .map(|c| (c.name.text.as_str(), "coordinate system", c.name.span)),
        );
        all.extend(
            doc.objects
                .iter()
                .map(|o| (o.name.text.as_str(), o.kind.element(), o.name.span)),
        );
        all.extend(
            doc.subdomains
                .iter()
                .map(|s| (s.name.text.as_str(), "subdomain", s.name.span)),
        );
        all.extend(
            doc.boundaries
                .iter()
                .map(|b| (b.name.text.as_str(), "boundary", b.name.span)),
        );
        all.sort_by_key(|&(_, _, span)| span);
        // Sized once: large files define hundreds of thousands of names.
        table.defs.reserve(all.len());
        for (name, kind, span) in all {
            if name.is_empty() {
                continue;
            }
            if let Some(first) = table.defs.get(name) {
                let line = source.line_col(first.span.start as usize).line;
                diags.push(
                    Diagnostic::new(
                        Code::DuplicateName,
                        span,
                        format!(
                            "the name '{name}' is already used by the {} on line {line}",
                            first.kind
                        ),
                    )
                    .with_help("names are global across all objects; rename one of them"),
                );
                continue;
            }
            if !is_plain_name(name) {
                diags.push(
                    Diagnostic::new(
                        Code::NameNotIdentifier,
                        span,
                        format!("the name '{name}' contains characters that separate names in lists and expressions"),
                    )
                    .with_help(format!(
                        "it can be referenced only by attributes that take one name; consider '{}'",
                        plain_version(name)
                    )),
                );
            }
            table.defs.insert(name, Definition { kind, span });
        }
        table
    }

    pub fn kind_of(&self, name: &str) -> Option<&'static str> {
        self.defs.get(name).map(|d| d.kind)
    }
}

/// Letters, digits, '_' and '-', not starting with a digit or '-'.
pub fn is_plain_name(name: &str) -> bool {
    let mut chars = name.chars();
    matches!(chars.next(), Some(c) if c.is_alphabetic() || c == '_')
        && chars.all(|c| c.is_alphanumeric() || c == '_' || c == '-')
}

fn plain_version(name: &str) -> String {
    let mut out: String = name
        .chars()
        .map(|c| {
            if c.is_alphanumeric() || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect();
    if out.starts_with(|c: char| c.is_ascii_digit() || c == '-') {
        out.insert(0, '_');
    }
    out
}
