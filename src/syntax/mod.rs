//! XML syntax: the only module that touches the XML parser. It turns text into
//! element trees with byte spans on every name and value (the whole tree, or one
//! top-level element at a time), refusing DTDs, over-deep nesting and oversized
//! input before any later stage sees them.

// User-controlled bytes and values: no panicking index (docs/reliability.md).
#![cfg_attr(not(test), deny(clippy::indexing_slicing))]

mod plain;
mod split;
mod tree;

pub use split::Reparse;
pub use tree::{Attribute, Attributes, Element, Head};
use tree::{Misplaced, Origin};

use crate::diag::{Code, Diagnostic};
use crate::span::{SourceFile, Span};

/// Resource limits of the front end; each has a command-line option that raises it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Limits {
    /// Largest accepted input, in bytes (`--max-file-size`).
    pub max_file_size: usize,
    /// Deepest accepted element nesting, the root being level 1 (`--max-depth`).
    pub max_depth: usize,
    /// Most XML nodes (elements, text, comments) in one document (`--max-nodes`).
    pub max_nodes: u32,
}

impl Default for Limits {
    fn default() -> Limits {
        Limits {
            max_file_size: 256 * 1024 * 1024,
            max_depth: 64,
            max_nodes: 50_000_000,
        }
    }
}

/// Parses `source` into an owned tree, or says why it cannot.
pub fn parse<'s>(source: &'s SourceFile, limits: &Limits) -> Result<Element<'s>, Diagnostic> {
    let document = parse_whole(source, limits)?;
    let root = document.root_element();
    tree::build(root, Origin::whole(&source.text)).map_err(|Misplaced| misplaced(root))
}

/// A parsed document whose elements become [`Element`]s one top-level child at
/// a time: a large file never holds the parser's document and a whole element
/// tree together (they were the first of the front end's memory peaks). Most
/// files are read in runs of the root's children ([`split`]), so not even the
/// parser's document of the whole file is ever alive.
pub struct Document<'s>(Parsed<'s>);

enum Parsed<'s> {
    Whole(roxmltree::Document<'s>),
    Split(split::Split<'s>),
}

impl<'s> Document<'s> {
    /// The root element with its attributes and text, without its children
    /// (see [`Document::heads`] and [`Document::top_level`]).
    pub fn root(&self) -> Result<Element<'s>, Diagnostic> {
        match &self.0 {
            Parsed::Whole(xml) => {
                let root = xml.root_element();
                tree::shallow(root, Origin::whole(xml.input_text()))
                    .map_err(|Misplaced| misplaced(root))
            }
            Parsed::Split(split) => Ok(split.root()),
        }
    }

    /// The [`Head`]s of the root's child elements, in order (a split
    /// document keeps them from its scan).
    pub fn heads(&self) -> std::borrow::Cow<'_, [Head<'_>]> {
        match &self.0 {
            Parsed::Whole(xml) => {
                let root = xml.root_element();
                let mut heads =
                    Vec::with_capacity(root.children().filter(|c| c.is_element()).count());
                heads.extend(root.children().filter(|c| c.is_element()).map(tree::head));
                std::borrow::Cow::Owned(heads)
            }
            Parsed::Split(split) => std::borrow::Cow::Borrowed(split.heads()),
        }
    }

    /// The root's child elements, each built whole when the iterator reaches
    /// it. [`Reparse`] ends a split document's iteration: read the file again
    /// from [`parse_whole`], which reports what the piece could not take.
    pub fn top_level(&self) -> Box<dyn Iterator<Item = Result<Element<'s>, Reparse>> + '_> {
        match &self.0 {
            Parsed::Whole(xml) => {
                let at = Origin::whole(xml.input_text());
                Box::new(
                    xml.root_element()
                        .children()
                        .filter(|c| c.is_element())
                        .map(move |c| tree::build(c, at).map_err(|Misplaced| Reparse)),
                )
            }
            Parsed::Split(split) => Box::new(split.top_level()),
        }
    }

    /// The root's children as runs that can be built apart (on other
    /// threads) and joined in order, the same elements [`Document::top_level`]
    /// gives; `None` for a file parsed whole.
    pub fn runs(&self) -> Option<Runs<'_, 's>> {
        match &self.0 {
            Parsed::Whole(_) => None,
            Parsed::Split(split) => Some(Runs {
                starts: split.run_starts(),
                split,
            }),
        }
    }
}

/// The runs of a split document's top-level elements (see [`Document::runs`]).
pub struct Runs<'a, 's> {
    split: &'a split::Split<'s>,
    /// The index of each run's first child.
    starts: Vec<usize>,
}

impl<'s> Runs<'_, 's> {
    pub fn len(&self) -> usize {
        self.starts.len()
    }

    pub fn is_empty(&self) -> bool {
        self.starts.is_empty()
    }

    /// The elements of run `i`, in order. [`Reparse`] as from
    /// [`Document::top_level`] (also for an `i` out of range).
    pub fn elements(&self, i: usize) -> Result<Vec<Element<'s>>, Reparse> {
        let first = *self.starts.get(i).ok_or(Reparse)?;
        self.split.run(first)
    }
}

/// Parses `source`, refusing what [`Limits`] and the format forbid (size, DTDs,
/// node count, nesting), or says why it cannot. The root's children are read
/// in runs when the file allows it ([`split`]).
pub fn parse_document<'s>(
    source: &'s SourceFile,
    limits: &Limits,
) -> Result<Document<'s>, Diagnostic> {
    check_text(source, limits)?;
    Ok(Document(match split::Split::scan(&source.text, limits) {
        Some(split) => Parsed::Split(split),
        None => Parsed::Whole(parse_checked(source, limits)?),
    }))
}

/// [`parse_document`] of the whole file at once: every XML error, the node
/// limit and the nesting limit are reported exactly here.
pub fn parse_whole_document<'s>(
    source: &'s SourceFile,
    limits: &Limits,
) -> Result<Document<'s>, Diagnostic> {
    Ok(Document(Parsed::Whole(parse_whole(source, limits)?)))
}

fn parse_whole<'s>(
    source: &'s SourceFile,
    limits: &Limits,
) -> Result<roxmltree::Document<'s>, Diagnostic> {
    check_text(source, limits)?;
    parse_checked(source, limits)
}

/// [`parse_whole`] after [`check_text`].
fn parse_checked<'s>(
    source: &'s SourceFile,
    limits: &Limits,
) -> Result<roxmltree::Document<'s>, Diagnostic> {
    let document = roxmltree::Document::parse_with_options(&source.text, split::options(limits))
        .map_err(|error| xml_error(source, &error, limits))?;
    check_depth(document.root_element(), limits)?;
    Ok(document)
}

/// The size limit and the refusal of DTDs, before any parser sees the text.
fn check_text(source: &SourceFile, limits: &Limits) -> Result<(), Diagnostic> {
    let text = source.text.as_str();
    if text.len() > limits.max_file_size {
        return Err(Diagnostic::new(
            Code::FileTooLarge,
            None,
            format!(
                "the file is {} bytes, over the limit of {} bytes",
                text.len(),
                limits.max_file_size
            ),
        )
        .with_help("raise the limit with --max-file-size BYTES"));
    }
    // Refuse a DTD before the parser sees it: no entity is ever declared or expanded.
    if let Some(pos) = find_doctype(text) {
        return Err(Diagnostic::new(
            Code::DtdRefused,
            Span::new(pos, pos + "<!DOCTYPE".len()),
            "the document has a document type declaration (<!DOCTYPE …>); geomc never reads DTDs or expands their entities",
        )
        .with_help("remove the <!DOCTYPE …> block"));
    }
    Ok(())
}

/// The guard of [`tree::Misplaced`] as a diagnostic (never seen).
fn misplaced(node: roxmltree::Node) -> Diagnostic {
    let start = node.range().start;
    lost_position(Span::new(start, start + 1))
}

/// A whole-file parse that could not place a name in the file (never seen:
/// the guard of a [`Reparse`] from [`parse_whole_document`]).
pub fn lost_position(span: impl Into<Option<Span>>) -> Diagnostic {
    Diagnostic::new(
        Code::XmlSyntax,
        span,
        "a name in the file could not be located by geomc's XML reader",
    )
    .with_help("report this file: geomc's XML reader lost a position")
}

/// The first "<!DOCTYPE", in any case. "<!" has no case variants, so only
/// its occurrences (found by memchr's vectorised substring search: the
/// standard library's took about 1% of reading a large file) can start one.
fn find_doctype(text: &str) -> Option<usize> {
    let bytes = text.as_bytes();
    let needle = b"<!DOCTYPE";
    memchr::memmem::find_iter(bytes, b"<!").find(|&pos| {
        bytes
            .get(pos..pos + needle.len())
            .is_some_and(|w| w.eq_ignore_ascii_case(needle))
    })
}

/// Depth check without recursion, so a hostile file cannot overflow the stack.
/// Visits elements depth-first, last child first; the stack holds one child
/// iterator per level, so it stays as small as the nesting.
fn check_depth(root: roxmltree::Node, limits: &Limits) -> Result<(), Diagnostic> {
    let mut stack = vec![root.children().rev()];
    let mut next = Some(root);
    loop {
        let node = match next.take() {
            Some(node) => node,
            None => match stack.last_mut() {
                Some(children) => match children.find(|c| c.is_element()) {
                    Some(node) => node,
                    None => {
                        stack.pop();
                        continue;
                    }
                },
                None => return Ok(()),
            },
        };
        // The root is level 1 and its children iterator is already on the stack.
        let depth = if node == root { 1 } else { stack.len() + 1 };
        if depth > limits.max_depth {
            let range = node.range();
            let name_end = range.start + 1 + node.tag_name().name().len();
            return Err(Diagnostic::new(
                Code::NestingTooDeep,
                Span::new(range.start, name_end),
                format!(
                    "element <{}> is nested {depth} levels deep, over the limit of {}",
                    node.tag_name().name(),
                    limits.max_depth
                ),
            )
            .with_help("flatten the nesting, or raise the limit with --max-depth N"));
        }
        if node != root {
            stack.push(node.children().rev());
        }
    }
}

fn xml_error(source: &SourceFile, error: &roxmltree::Error, limits: &Limits) -> Diagnostic {
    use roxmltree::Error as E;
    match error {
        E::NodesLimitReached => Diagnostic::new(
            Code::TooManyNodes,
            None,
            format!("the document has more than {} XML nodes", limits.max_nodes),
        )
        .with_help("raise the limit with --max-nodes N"),
        E::DtdDetected => Diagnostic::new(
            Code::DtdRefused,
            None,
            "the document has a document type declaration; geomc never reads DTDs",
        )
        .with_help("remove the <!DOCTYPE …> block"),
        E::UnknownEntityReference(name, _) => Diagnostic::new(
            Code::XmlSyntax,
            position_span(source, error.pos()),
            format!("unknown entity reference '&{name};': geomc knows only XML's five predefined entities"),
        )
        .with_help("write the character itself, or one of &lt; &gt; &amp; &quot; &apos;"),
        _ => {
            let message = error.to_string();
            // roxmltree appends " at L:C"; the position goes into the span instead.
            let message = match message.rfind(" at ") {
                Some(i) => message[..i].to_string(),
                None => message,
            };
            Diagnostic::new(
                Code::XmlSyntax,
                position_span(source, error.pos()),
                lowercase_first(&message),
            )
            .with_help("fix the XML at this position")
        }
    }
}

fn position_span(source: &SourceFile, pos: roxmltree::TextPos) -> Span {
    let offset = source
        .lines()
        .offset_of(
            &source.text,
            crate::span::LineCol {
                line: pos.row,
                column: pos.col,
            },
        )
        .unwrap_or(0);
    let end = source.text[offset..]
        .chars()
        .next()
        .map_or(offset, |c| offset + c.len_utf8());
    Span::new(offset, end)
}

fn lowercase_first(text: &str) -> String {
    let mut chars = text.chars();
    match chars.next() {
        Some(first) => first.to_lowercase().chain(chars).collect(),
        None => String::new(),
    }
}
