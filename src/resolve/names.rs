//! The global name table: every definition's name, its kind and span;
//! duplicates and names that cannot be referenced everywhere are reported here.

use crate::diag::{Code, Diagnostic, Diagnostics};
use crate::doc::Document;
use crate::span::{SourceFile, Span};

/// One definition of a name, in the table's list (sorted by position).
#[derive(Debug, Clone, Copy)]
struct Entry<'d> {
    name: &'d str,
    kind: &'static str,
    span: Span,
    /// The object this definition is (1 + its index, 0 for other kinds);
    /// on a name's first definition, once built: 1 + the first object of
    /// the name, whichever definition that is.
    object: u32,
    /// The name's hash, compared before the name itself.
    hash: u32,
}

/// Every definition's name, kind and span, and the first object of each
/// name: the one table the resolver looks names up in. Names borrow the
/// document's (no string is copied). On files of hundreds of thousands of
/// definitions a hash map of names to definitions was the front end's
/// largest table built before resolution (40-byte buckets written in random
/// order), and a second map gave the objects; here the definitions are one
/// list in source order and the table holds 4-byte indices into it, with
/// the names' hashes beside them so that a probe rarely reads a name.
#[derive(Debug, Default)]
pub struct NameTable<'d> {
    entries: Vec<Entry<'d>>,
    /// Open addressing, linear probing from the name's hash, at most two
    /// thirds full: (1 + the index of a name's first definition in
    /// `entries`, 0 for an empty slot; the name's hash).
    slots: Vec<(u32, u32)>,
    /// 1 + the first object whose name is empty (such a name is defined
    /// nowhere else, but a reference may still give it), 0 for none.
    unnamed_object: u32,
}

/// How many names ahead the build asks for a slot's cache line.
const PREFETCH_AHEAD: usize = 16;

/// The name index's hash, folded to the four bytes a slot keeps.
fn hash(name: &str) -> u32 {
    let h = super::name_index::hash(name);
    (h >> 32) as u32 ^ h as u32
}

impl<'d> NameTable<'d> {
    pub fn build(source: &SourceFile, doc: &'d Document, diags: &mut Diagnostics) -> NameTable<'d> {
        let count = doc.parameters.len()
            + doc.basis.len()
            + doc.coordinate_systems.len()
            + doc.objects.len()
            + doc.subdomains.len()
            + doc.boundaries.len();
        let mut entries: Vec<Entry<'d>> = Vec::with_capacity(count);
        let entry = |name: &'d str, kind: &'static str, span: Span, object: u32| Entry {
            name,
            kind,
            span,
            object,
            hash: hash(name),
        };
        entries.extend(
            doc.parameters
                .iter()
                .map(|p| entry(&p.name.text, "parameter", p.name.span, 0)),
        );
        entries.extend(
            doc.basis
                .iter()
                .map(|b| entry(&b.name.text, "basis coordinate", b.name.span, 0)),
        );
        entries.extend(
            doc.coordinate_systems
                .iter()
                .map(|c| entry(&c.name.text, "coordinate system", c.name.span, 0)),
        );
        entries.extend(
            doc.objects
                .iter()
                .enumerate()
                .map(|(i, o)| entry(&o.name.text, o.kind.element(), o.name.span, i as u32 + 1)),
        );
        entries.extend(
            doc.subdomains
                .iter()
                .map(|s| entry(&s.name.text, "subdomain", s.name.span, 0)),
        );
        entries.extend(
            doc.boundaries
                .iter()
                .map(|b| entry(&b.name.text, "boundary", b.name.span, 0)),
        );
        // Stable: a run per list, merged.
        entries.sort_by_key(|e| e.span);
        let size = (count + count / 2 + 1).next_power_of_two();
        let mut table = NameTable {
            entries: Vec::new(),
            slots: vec![(0, 0); size],
            unnamed_object: 0,
        };
        let mask = size - 1;
        for k in 0..entries.len() {
            // The slots are hit in random order: ask for one a few names
            // ahead while this one is probed.
            if let Some(ahead) = entries.get(k + PREFETCH_AHEAD) {
                if let Some(slot) = table.slots.get(ahead.hash as usize & mask) {
                    crate::cache_hint::prefetch(slot);
                }
            }
            let Entry {
                name,
                span,
                object,
                hash,
                ..
            } = entries[k];
            if name.is_empty() {
                table.unnamed_object = first_of(table.unnamed_object, object);
                continue;
            }
            let slot = table.probe(&entries, name, hash);
            let Some(&(first, _)) = table.slots.get(slot) else {
                continue;
            };
            if first != 0 {
                let first = &mut entries[first as usize - 1];
                first.object = first_of(first.object, object);
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
            table.slots[slot] = (k as u32 + 1, hash);
        }
        table.entries = entries;
        table
    }

    /// The slot of `name`: the one holding its first definition, or the
    /// empty slot where its probe sequence ends.
    fn probe(&self, entries: &[Entry<'d>], name: &str, hash: u32) -> usize {
        let mask = self.slots.len().wrapping_sub(1);
        let mut at = hash as usize & mask;
        for _ in 0..self.slots.len() {
            match self.slots[at] {
                (0, _) => return at,
                (k, h)
                    if h == hash && entries.get(k as usize - 1).is_some_and(|e| e.name == name) =>
                {
                    return at;
                }
                _ => at = (at + 1) & mask,
            }
        }
        // Not reached: the table is never full.
        self.slots.len()
    }

    fn first(&self, name: &str) -> Option<&Entry<'d>> {
        if self.slots.is_empty() {
            return None;
        }
        let slot = self.probe(&self.entries, name, hash(name));
        match self.slots.get(slot) {
            None | Some((0, _)) => None,
            Some(&(k, _)) => self.entries.get(k as usize - 1),
        }
    }

    /// The kind of the name's first definition.
    pub fn kind_of(&self, name: &str) -> Option<&'static str> {
        self.first(name).map(|e| e.kind)
    }

    /// The index of the first object named `name` (in `doc.objects`).
    pub fn first_object(&self, name: &str) -> Option<usize> {
        let object = if name.is_empty() {
            self.unnamed_object
        } else {
            self.first(name).map_or(0, |e| e.object)
        };
        (object != 0).then(|| object as usize - 1)
    }
}

/// The earlier of two objects given as 1 + index (0: none).
fn first_of(a: u32, b: u32) -> u32 {
    match (a, b) {
        (0, b) => b,
        (a, 0) => a,
        (a, b) => a.min(b),
    }
}

/// Letters, digits, '_' and '-', not starting with a digit or '-'.
pub fn is_plain_name(name: &str) -> bool {
    // Most names are ASCII: bytes are checked without decoding characters
    // (the name table checks every definition's name).
    if name.is_ascii() {
        let bytes = name.as_bytes();
        return matches!(bytes.first(), Some(c) if c.is_ascii_alphabetic() || *c == b'_')
            && (bytes.iter().skip(1))
                .all(|c| c.is_ascii_alphanumeric() || *c == b'_' || *c == b'-');
    }
    is_plain_by_chars(name)
}

/// [`is_plain_name`] for any text.
fn is_plain_by_chars(name: &str) -> bool {
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ascii_names_are_plain_exactly_when_their_characters_are() {
        // Every name of up to three printable ASCII characters (and a few
        // letters beyond ASCII) gets the same answer from the byte check as
        // from the characters.
        let alphabet: Vec<char> = (' '..='~').chain(['é', 'Ж']).collect();
        let mut names = vec![String::new()];
        for a in &alphabet {
            names.push(a.to_string());
            for b in &alphabet {
                names.push(format!("{a}{b}"));
                names.push(format!("{a}{b}x"));
                names.push(format!("x{a}{b}"));
            }
        }
        let plain = names.iter().filter(|n| is_plain_name(n)).count();
        for name in &names {
            assert_eq!(is_plain_name(name), is_plain_by_chars(name), "{name:?}");
        }
        assert!(is_plain_name("box_1-a") && is_plain_name("_x") && is_plain_name("é1"));
        assert!(!is_plain_name("1a") && !is_plain_name("-a") && !is_plain_name("a b"));
        assert!(!is_plain_name("") && !is_plain_name("a.b"));
        assert_eq!(plain, 11_671);
    }
}
