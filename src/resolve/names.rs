//! The global name table: every definition's name, its kind and span;
//! duplicates and names that cannot be referenced everywhere are reported here.

use crate::diag::{Code, Diagnostic, Diagnostics};
use crate::doc::{Document, Name};
use crate::span::{SourceFile, Span};
use std::collections::HashMap;

/// The lists of named definitions, in the order the table numbers them:
/// definition `n` is item `n - start` of the list whose numbers start at
/// `start`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum List {
    Parameters,
    Basis,
    Systems,
    Objects,
    Subdomains,
    Boundaries,
}

const LISTS: [List; 6] = [
    List::Parameters,
    List::Basis,
    List::Systems,
    List::Objects,
    List::Subdomains,
    List::Boundaries,
];

/// One definition, read from the document's lists.
#[derive(Debug, Clone, Copy)]
struct Definition<'d> {
    name: &'d Name,
    kind: &'static str,
    /// 1 + the object's index if the definition is an object, 0 otherwise.
    object: u32,
}

/// Every definition's name, kind and span, and the first object of each
/// name: the one table the resolver looks names up in. It keeps no copy of
/// any definition: a slot holds a definition's number (in list order), and
/// its name, kind and span are read from the document. On files of hundreds
/// of thousands of definitions a hash map of names to definitions was the
/// front end's largest table built before resolution, and then a list of
/// every definition sorted by position (9.6 MB on the 100,000-primitive
/// file, written and sorted on the main thread); the findings, which need
/// the position order, are few and sorted on their own.
#[derive(Debug)]
pub struct NameTable<'d> {
    doc: &'d Document,
    /// Where each list's numbers start, then the number of definitions.
    starts: [u32; 7],
    /// Open addressing, linear probing from the name's hash, at most two
    /// thirds full: (1 + the number of a name's first definition by
    /// position, 0 for an empty slot; the name's hash).
    slots: Vec<(u32, u32)>,
    /// 1 + the first object of the name in a slot (0: none), for the names
    /// defined more than once; a name defined once is its first object if
    /// it is an object.
    first_objects: HashMap<u32, u32, foldhash::fast::FixedState>,
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

/// What the build found to report: a later definition of a name (its
/// number), or a name that is not plain (the slot of its first definition).
#[derive(Debug, Clone, Copy)]
enum Finding {
    Repeated { later: u32, slot: usize },
    NotPlain { slot: usize },
}

impl<'d> NameTable<'d> {
    pub fn build(source: &SourceFile, doc: &'d Document, diags: &mut Diagnostics) -> NameTable<'d> {
        let lengths = [
            doc.parameters.len(),
            doc.basis.len(),
            doc.coordinate_systems.len(),
            doc.objects.len(),
            doc.subdomains.len(),
            doc.boundaries.len(),
        ];
        let count: usize = lengths.iter().sum();
        let mut starts = [0u32; 7];
        for (k, length) in lengths.iter().enumerate() {
            starts[k + 1] = starts[k].saturating_add(u32::try_from(*length).unwrap_or(u32::MAX));
        }
        let size = (count + count / 2 + 1).next_power_of_two();
        let mut table = NameTable {
            doc,
            starts,
            slots: vec![(0, 0); size],
            first_objects: HashMap::default(),
            unnamed_object: 0,
        };
        let mut findings = Vec::new();
        table.insert_all(
            &doc.parameters,
            List::Parameters,
            |p| &p.name,
            &mut findings,
        );
        table.insert_all(&doc.basis, List::Basis, |b| &b.name, &mut findings);
        let systems = &doc.coordinate_systems;
        table.insert_all(systems, List::Systems, |c| &c.name, &mut findings);
        table.insert_all(&doc.objects, List::Objects, |o| &o.name, &mut findings);
        table.insert_all(
            &doc.subdomains,
            List::Subdomains,
            |s| &s.name,
            &mut findings,
        );
        table.insert_all(
            &doc.boundaries,
            List::Boundaries,
            |b| &b.name,
            &mut findings,
        );
        table.report(source, &findings, diags);
        table
    }

    /// Enters the definitions of one list, numbered from its start.
    fn insert_all<T>(
        &mut self,
        items: &'d [T],
        list: List,
        name_of: impl Fn(&'d T) -> &'d Name,
        findings: &mut Vec<Finding>,
    ) {
        let start = self.starts[list as usize];
        let mask = self.slots.len().wrapping_sub(1);
        // The slots are hit in random order: ask for one a few names ahead
        // while this one is probed (its hash kept until then).
        let mut ahead = [0u32; PREFETCH_AHEAD];
        let hash_ahead = |k: usize, slots: &[(u32, u32)]| -> u32 {
            let h = items.get(k).map_or(0, |item| hash(&name_of(item).text));
            if let Some(slot) = slots.get(h as usize & mask) {
                crate::cache_hint::prefetch(slot);
            }
            h
        };
        for (k, h) in ahead.iter_mut().enumerate() {
            *h = hash_ahead(k, &self.slots);
        }
        for (k, item) in items.iter().enumerate() {
            let h = std::mem::replace(
                &mut ahead[k % PREFETCH_AHEAD],
                hash_ahead(k + PREFETCH_AHEAD, &self.slots),
            );
            let number = start.saturating_add(k as u32);
            let object = if list == List::Objects {
                k as u32 + 1
            } else {
                0
            };
            self.insert(name_of(item), h, number, object, findings);
        }
    }

    /// Enters definition `number` of the name `name` (hash `h`).
    fn insert(
        &mut self,
        name: &Name,
        h: u32,
        number: u32,
        object: u32,
        findings: &mut Vec<Finding>,
    ) {
        if name.text.is_empty() {
            self.unnamed_object = first_of(self.unnamed_object, object);
            return;
        }
        let slot = self.probe(&name.text, h);
        let Some(&(held, _)) = self.slots.get(slot) else {
            return;
        };
        if held == 0 {
            self.slots[slot] = (number + 1, h);
            if !is_plain_name(&name.text) {
                findings.push(Finding::NotPlain { slot });
            }
            return;
        }
        let first = held - 1;
        let before = self.first_object_at(slot);
        self.first_objects
            .insert(slot as u32, first_of(before, object));
        // The first definition is the first by position (the lists are
        // each in document order, but one list's items may come before
        // another's); of equal positions, the first numbered.
        let first_span = self.definition(first).map(|d| d.name.span);
        let later = if first_span.is_some_and(|s| name.span < s) {
            self.slots[slot].0 = number + 1;
            first
        } else {
            number
        };
        findings.push(Finding::Repeated { later, slot });
    }

    /// Reports the findings in the order of their definitions' positions.
    fn report(&self, source: &SourceFile, findings: &[Finding], diags: &mut Diagnostics) {
        let mut located: Vec<(Span, u32, Diagnostic)> = Vec::with_capacity(findings.len());
        for finding in findings {
            let (number, slot) = match *finding {
                Finding::Repeated { later, slot } => (later, slot),
                Finding::NotPlain { slot } => (self.first_at(slot).unwrap_or(0), slot),
            };
            let (Some(this), Some(first)) = (
                self.definition(number),
                self.first_at(slot).and_then(|f| self.definition(f)),
            ) else {
                continue;
            };
            let (name, span) = (&this.name.text, this.name.span);
            let diagnostic = match finding {
                Finding::Repeated { .. } => {
                    let line = source.line_col(first.name.span.start as usize).line;
                    Diagnostic::new(
                        Code::DuplicateName,
                        span,
                        format!(
                            "the name '{name}' is already used by the {} on line {line}",
                            first.kind
                        ),
                    )
                    .with_help("names are global across all objects; rename one of them")
                }
                Finding::NotPlain { .. } => Diagnostic::new(
                    Code::NameNotIdentifier,
                    span,
                    format!("the name '{name}' contains characters that separate names in lists and expressions"),
                )
                .with_help(format!(
                    "it can be referenced only by attributes that take one name; consider '{}'",
                    plain_version(name)
                )),
            };
            located.push((span, number, diagnostic));
        }
        located.sort_by_key(|&(span, number, _)| (span, number));
        for (_, _, diagnostic) in located {
            diags.push(diagnostic);
        }
    }

    /// Definition `number`, read from its list.
    fn definition(&self, number: u32) -> Option<Definition<'d>> {
        let k = self.starts[1..].iter().position(|&end| number < end)?;
        let i = (number - self.starts[k]) as usize;
        let doc = self.doc;
        let (name, kind) = match LISTS[k] {
            List::Parameters => (&doc.parameters.get(i)?.name, "parameter"),
            List::Basis => (&doc.basis.get(i)?.name, "basis coordinate"),
            List::Systems => (&doc.coordinate_systems.get(i)?.name, "coordinate system"),
            List::Objects => {
                let object = doc.objects.get(i)?;
                (&object.name, object.kind.element())
            }
            List::Subdomains => (&doc.subdomains.get(i)?.name, "subdomain"),
            List::Boundaries => (&doc.boundaries.get(i)?.name, "boundary"),
        };
        let object = if LISTS[k] == List::Objects {
            i as u32 + 1
        } else {
            0
        };
        Some(Definition { name, kind, object })
    }

    /// The number of the first definition in `slot`, if any.
    fn first_at(&self, slot: usize) -> Option<u32> {
        match self.slots.get(slot) {
            None | Some((0, _)) => None,
            Some(&(held, _)) => Some(held - 1),
        }
    }

    /// 1 + the first object of the name in `slot` (0: none).
    fn first_object_at(&self, slot: usize) -> u32 {
        match self.first_objects.get(&(slot as u32)) {
            Some(&object) => object,
            None => (self.first_at(slot))
                .and_then(|first| self.definition(first))
                .map_or(0, |d| d.object),
        }
    }

    /// The slot of `name`: the one holding its first definition, or the
    /// empty slot where its probe sequence ends.
    fn probe(&self, name: &str, hash: u32) -> usize {
        let mask = self.slots.len().wrapping_sub(1);
        let mut at = hash as usize & mask;
        for _ in 0..self.slots.len() {
            match self.slots[at] {
                (0, _) => return at,
                (k, h)
                    if h == hash && self.definition(k - 1).is_some_and(|d| d.name.text == name) =>
                {
                    return at;
                }
                _ => at = (at + 1) & mask,
            }
        }
        // Not reached: the table is never full.
        self.slots.len()
    }

    /// The slot of the name's first definition, if the name is defined.
    fn slot_of(&self, name: &str) -> Option<usize> {
        if self.slots.is_empty() {
            return None;
        }
        let slot = self.probe(name, hash(name));
        self.first_at(slot).map(|_| slot)
    }

    /// The kind of the name's first definition.
    pub fn kind_of(&self, name: &str) -> Option<&'static str> {
        let first = self.first_at(self.slot_of(name)?)?;
        self.definition(first).map(|d| d.kind)
    }

    /// The index of the first object named `name` (in `doc.objects`).
    pub fn first_object(&self, name: &str) -> Option<usize> {
        let object = if name.is_empty() {
            self.unnamed_object
        } else {
            self.slot_of(name)
                .map_or(0, |slot| self.first_object_at(slot))
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
