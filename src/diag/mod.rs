//! Diagnostics: what every stage reports instead of failing on the first problem.
//! A diagnostic has a stable [`Code`], a severity, a span in the input, a message
//! that names the bad value, and an optional help line that suggests the fix.

mod code;
mod render;
mod suggest;

pub use code::Code;
pub use render::{JsonDiagnostic, render_human, render_json};
pub use suggest::did_you_mean;

use crate::span::Span;

#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Severity {
    Error,
    Warning,
}

impl Severity {
    pub fn as_str(self) -> &'static str {
        match self {
            Severity::Error => "error",
            Severity::Warning => "warning",
        }
    }
}

#[derive(Debug, Clone, PartialEq)]
pub struct Diagnostic {
    pub code: Code,
    pub severity: Severity,
    /// Where in the input; `None` for problems of the command line or of the
    /// file as a whole.
    pub span: Option<Span>,
    pub message: String,
    pub help: Option<String>,
}

impl Diagnostic {
    pub fn new(code: Code, span: impl Into<Option<Span>>, message: impl Into<String>) -> Self {
        Diagnostic {
            code,
            severity: code.severity(),
            span: span.into(),
            message: message.into(),
            help: None,
        }
    }

    pub fn with_help(mut self, help: impl Into<String>) -> Self {
        self.help = Some(help.into());
        self
    }

    pub fn is_error(&self) -> bool {
        self.severity == Severity::Error
    }
}

/// An ordered collection of diagnostics, as each stage returns them.
#[derive(Debug, Clone, Default)]
pub struct Diagnostics {
    pub items: Vec<Diagnostic>,
}

impl Diagnostics {
    pub fn push(&mut self, diagnostic: Diagnostic) {
        self.items.push(diagnostic);
    }

    pub fn error(
        &mut self,
        code: Code,
        span: impl Into<Option<Span>>,
        message: impl Into<String>,
    ) -> &mut Diagnostic {
        self.items.push(Diagnostic::new(code, span, message));
        let last = self.items.len() - 1;
        &mut self.items[last]
    }

    pub fn has_errors(&self) -> bool {
        self.items.iter().any(Diagnostic::is_error)
    }

    pub fn error_count(&self) -> usize {
        self.items.iter().filter(|d| d.is_error()).count()
    }

    pub fn warning_count(&self) -> usize {
        self.items.len() - self.error_count()
    }

    pub fn extend(&mut self, other: Diagnostics) {
        self.items.extend(other.items);
    }

    /// Sorts by position (diagnostics without a span first), keeping the
    /// reporting order among equal positions, and drops exact duplicates.
    pub fn sort(&mut self) {
        self.items
            .sort_by_key(|d| d.span.map_or((0, 0), |s| (s.start as u64 + 1, s.end)));
        self.items.dedup();
    }
}

impl std::ops::AddAssign<Diagnostic> for Diagnostics {
    fn add_assign(&mut self, diagnostic: Diagnostic) {
        self.push(diagnostic);
    }
}
