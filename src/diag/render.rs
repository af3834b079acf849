//! Rendering diagnostics: `file:line:col: error[CODE]: message` with the source
//! line and a caret for people, one JSON object per diagnostic for CI.

use super::{Diagnostic, Severity};
use crate::span::SourceFile;
use std::fmt::Write;

/// Renders one diagnostic for a terminal, without colour.
pub fn render_human(source: &SourceFile, diagnostic: &Diagnostic) -> String {
    let mut out = String::new();
    let severity = diagnostic.severity.as_str();
    let code = diagnostic.code.as_str();
    match diagnostic.span {
        Some(span) => {
            let start = source.line_col(span.start as usize);
            let _ = writeln!(
                out,
                "{}:{}:{}: {severity}[{code}]: {}",
                source.name, start.line, start.column, diagnostic.message
            );
            let line_text = source.lines().line_text(&source.text, start.line);
            let gutter = start.line.to_string();
            let pad = " ".repeat(gutter.len());
            // The caret covers the span's part on its first line, at least one column.
            let end = source.line_col(span.end as usize);
            let width = if end.line == start.line {
                (end.column.saturating_sub(start.column)).max(1)
            } else {
                (line_text.chars().count() as u32 + 1)
                    .saturating_sub(start.column)
                    .max(1)
            };
            let indent: String = line_text
                .chars()
                .take(start.column.saturating_sub(1) as usize)
                .map(|c| if c == '\t' { '\t' } else { ' ' })
                .collect();
            let _ = writeln!(out, "{pad} |");
            let _ = writeln!(out, "{gutter} | {line_text}");
            let _ = writeln!(out, "{pad} | {indent}{}", "^".repeat(width as usize));
        }
        None => {
            let _ = writeln!(
                out,
                "{}: {severity}[{code}]: {}",
                source.name, diagnostic.message
            );
        }
    }
    if let Some(help) = &diagnostic.help {
        let _ = writeln!(out, "  = help: {help}");
    }
    out
}

/// One diagnostic as the JSON object `--format json` prints.
#[derive(Debug, Clone, serde::Serialize)]
pub struct JsonDiagnostic {
    pub file: String,
    pub line: Option<u32>,
    pub column: Option<u32>,
    pub end_line: Option<u32>,
    pub end_column: Option<u32>,
    pub severity: Severity,
    pub code: &'static str,
    pub message: String,
    pub help: Option<String>,
}

pub fn render_json(source: &SourceFile, diagnostic: &Diagnostic) -> JsonDiagnostic {
    let start = diagnostic.span.map(|s| source.line_col(s.start as usize));
    let end = diagnostic.span.map(|s| source.line_col(s.end as usize));
    JsonDiagnostic {
        file: source.name.clone(),
        line: start.map(|p| p.line),
        column: start.map(|p| p.column),
        end_line: end.map(|p| p.line),
        end_column: end.map(|p| p.column),
        severity: diagnostic.severity,
        code: diagnostic.code.as_str(),
        message: diagnostic.message.clone(),
        help: diagnostic.help.clone(),
    }
}
