//! The root's children parsed a few at a time instead of the whole file at
//! once: roxmltree's document of a large file is several times its size, and
//! it was alive beside the typed document (the front end's memory peak).
//!
//! A scan finds the root's start tag, each child element's extent and its
//! [`Head`], and the root's end. The prolog and root start tag (closed by
//! hand) are parsed by roxmltree, then runs of consecutive children: a plain
//! run by [`super::plain`], any other inside a wrapper element by roxmltree
//! with the same options. The
//! split is taken only when the text between the children is whitespace;
//! anything the scan does not expect (comments or text at the top level,
//! prefixed names, entities in a `name=` value) or any error of a piece means
//! the whole file is parsed as before, so diagnostics never depend on the split.

use super::plain;
use super::tree::{self, Element, Head, Misplaced, Origin};
use super::{Limits, check_depth};
use crate::span::Span;
use std::collections::VecDeque;
use std::ops::Range;

/// A piece of the file could not be read on its own (an XML error, a name
/// bound by the root's namespace declarations, nesting over the limit, or a
/// mismatch with the scan): parse the whole file, which reports it as before.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Reparse;

/// A file whose root's children are parsed in runs (see the module).
pub(super) struct Split<'s> {
    text: &'s str,
    root: Element<'s>,
    heads: Vec<Head<'s>>,
    /// Byte ranges of the root's child elements, in order.
    children: Vec<Range<usize>>,
    limits: Limits,
}

/// Bytes of children parsed at once: large enough that a parse's fixed costs
/// do not count, small enough that its document stays a few hundred kB.
const RUN_BYTES: usize = 64 * 1024;

/// The wrapper of a run of children (its name is never read).
const OPEN: &str = "<r>";
const CLOSE: &str = "</r>";

impl<'s> Split<'s> {
    /// Scans `text`; `None` when the file must be parsed whole.
    pub fn scan(text: &'s str, limits: &Limits) -> Option<Split<'s>> {
        // Each node starts at a byte of its own, so a file shorter than the
        // node limit cannot reach it in any piece: the limit's error comes only
        // from the whole parse.
        if text.len().saturating_add(OPEN.len() + CLOSE.len() + 2) >= limits.max_nodes as usize {
            return None;
        }
        let bytes = text.as_bytes();
        let root_start = prolog_end(bytes)?;
        let (tag_end, self_closing) = start_tag_end(bytes, root_start)?;
        if self_closing {
            return None;
        }
        let root_name = name_at(text, root_start + 1)?;
        let root = parse_root(text, tag_end, root_name, limits)?;
        let (heads, children, pos) = scan_children(text, tag_end, HALVES_FROM)?;
        let end = root_end(text, pos, root_name)?;
        let mut root = root;
        root.span = Span::new(root_start, end);
        Some(Split {
            text,
            root,
            heads,
            children,
            limits: *limits,
        })
    }

    pub fn root(&self) -> Element<'s> {
        self.root.clone()
    }

    pub fn heads(&self) -> &[Head<'s>] {
        &self.heads
    }

    pub fn top_level(&self) -> Runs<'_, 's> {
        Runs {
            split: self,
            next: 0,
            ready: VecDeque::new(),
        }
    }

    /// The index of the first child of every run, in order: the runs
    /// [`Split::top_level`] parses one after another, so they can be parsed
    /// apart (on other threads) and joined in this order.
    pub fn run_starts(&self) -> Vec<usize> {
        let mut starts = Vec::with_capacity(self.text.len() / RUN_BYTES + 1);
        let mut first = 0;
        while first < self.children.len() {
            starts.push(first);
            first = self.run_end(first);
        }
        starts
    }

    /// The index after the last child of the run starting at `first`.
    fn run_end(&self, first: usize) -> usize {
        let Some(start) = self.children.get(first).map(|c| c.start) else {
            return first;
        };
        let mut last = first;
        while let Some(next) = self.children.get(last + 1) {
            if next.end - start > RUN_BYTES {
                break;
            }
            last += 1;
        }
        last + 1
    }

    /// The elements of the run starting at `first` (one of
    /// [`Split::run_starts`]).
    pub fn run(&self, first: usize) -> Result<Vec<Element<'s>>, Reparse> {
        if let Some(elements) = self.plain_run(first)? {
            return Ok(elements);
        }
        let mut elements = Vec::with_capacity(self.run_end(first) - first);
        self.parse_run_whole(first, &mut elements)?;
        Ok(elements)
    }

    /// Reads the run of children starting at `first` (plain, or else by
    /// roxmltree) into `out`; returns the index after its last child.
    fn parse_run(
        &self,
        first: usize,
        out: &mut impl Extend<Element<'s>>,
    ) -> Result<usize, Reparse> {
        match self.plain_run(first)? {
            Some(elements) => {
                let next = first + elements.len();
                out.extend(elements);
                Ok(next)
            }
            None => self.parse_run_whole(first, out),
        }
    }

    /// The elements of the run starting at `first` as [`plain::read_run`]
    /// reads them, checked against the scan as roxmltree's are; `None` when
    /// the run is not plain.
    fn plain_run(&self, first: usize) -> Result<Option<Vec<Element<'s>>>, Reparse> {
        let start = self.children.get(first).ok_or(Reparse)?.start;
        let last = self.run_end(first) - 1;
        let end = self.children.get(last).ok_or(Reparse)?.end;
        let Some(elements) = plain::read_run(
            self.text,
            start,
            end,
            self.limits.max_depth,
            last + 1 - first,
        ) else {
            return Ok(None);
        };
        let heads = self.heads.get(first..=last).ok_or(Reparse)?;
        if heads.len() != elements.len() || !heads.iter().zip(&elements).all(|(h, e)| h.is_of(e)) {
            return Err(Reparse);
        }
        Ok(Some(elements))
    }

    /// Parses the run of children starting at `first` with roxmltree, in a
    /// wrapper; returns the index after its last child.
    fn parse_run_whole(
        &self,
        first: usize,
        out: &mut impl Extend<Element<'s>>,
    ) -> Result<usize, Reparse> {
        let start = self.children.get(first).ok_or(Reparse)?.start;
        let last = self.run_end(first) - 1;
        let end = self.children.get(last).ok_or(Reparse)?.end;
        let piece = self.text.get(start..end).ok_or(Reparse)?;
        let mut buffer = String::with_capacity(OPEN.len() + piece.len() + CLOSE.len());
        buffer.push_str(OPEN);
        buffer.push_str(piece);
        buffer.push_str(CLOSE);
        let document = roxmltree::Document::parse_with_options(&buffer, options(&self.limits))
            .map_err(|_| Reparse)?;
        let wrapper = document.root_element();
        check_depth(wrapper, &self.limits).map_err(|_| Reparse)?;
        let at = Origin {
            source: self.text,
            shift: start as isize - OPEN.len() as isize,
        };
        let mut index = first;
        for node in wrapper.children() {
            if node.is_element() {
                let element = tree::build(node, at).map_err(|Misplaced| Reparse)?;
                if !self.heads.get(index).is_some_and(|h| h.is_of(&element)) {
                    return Err(Reparse);
                }
                out.extend(Some(element));
                index += 1;
            } else if !node.text().is_some_and(|t| t.trim().is_empty()) {
                return Err(Reparse);
            }
        }
        if index != last + 1 {
            return Err(Reparse);
        }
        Ok(index)
    }
}

/// Root contents from which the scan of the children runs in two halves
/// side by side (below it a thread costs more than it saves).
const HALVES_FROM: usize = 1 << 20;

/// What a scan of the root's children found: their heads and extents, and
/// where it stopped.
struct Scanned<'s> {
    heads: Vec<Head<'s>>,
    children: Vec<Range<usize>>,
    /// At the root's end tag (`</`), or at `stop` when the scan was told to.
    at: usize,
    ended: bool,
}

/// The heads and extents of the root's children from `from` (where a child
/// may start) up to the root's end tag, and that tag's position. Between two
/// children the scan's only state is its position, so when the contents are
/// at least `halves_from` bytes long a second scan starts at a child's start
/// guessed in the middle, beside the first: if the first arrives exactly
/// there, the halves join; if it passes it (the guess was inside a child), it
/// goes on alone. The result is that of one scan from `from` either way.
fn scan_children(
    text: &str,
    from: usize,
    halves_from: usize,
) -> Option<(Vec<Head<'_>>, Vec<Range<usize>>, usize)> {
    let guess = (text.len() - from >= halves_from)
        .then(|| guess_child_start(text.as_bytes(), from + (text.len() - from) / 2))
        .flatten();
    match guess {
        Some(middle) => scan_halves(text, from, middle),
        None => {
            let whole = scan_from(text, from, usize::MAX, text.len())?;
            Some((whole.heads, whole.children, whole.at))
        }
    }
}

/// [`scan_children`] in two halves, the second from `middle`.
fn scan_halves(
    text: &str,
    from: usize,
    middle: usize,
) -> Option<(Vec<Head<'_>>, Vec<Range<usize>>, usize)> {
    // The first half makes room for the whole, so the second's joins it
    // without a copy of the first into fresh pages on this thread.
    let (first, second) = rayon::join(
        || scan_from(text, from, middle, text.len()),
        || scan_from(text, middle, usize::MAX, text.len()),
    );
    let mut first = first?;
    let rest = match second {
        _ if first.ended => return Some((first.heads, first.children, first.at)),
        Some(second) if first.at == middle => second,
        _ => scan_from(text, first.at, usize::MAX, text.len())?,
    };
    first.heads.extend(rest.heads);
    first.children.extend(rest.children);
    Some((first.heads, first.children, rest.at))
}

/// The first `<` at or after `pos` that follows whitespace and starts a name:
/// maybe a child of the root (checked by the scan arriving there).
fn guess_child_start(bytes: &[u8], mut pos: usize) -> Option<usize> {
    loop {
        pos += memchr::memchr(b'<', bytes.get(pos..)?)?;
        let before = bytes.get(pos.checked_sub(1)?)?;
        let after = bytes.get(pos + 1)?;
        if before.is_ascii_whitespace() && (after.is_ascii_alphabetic() || *after == b'_') {
            return Some(pos);
        }
        pos += 1;
    }
}

/// Children whose average length sizes the scan's lists (see [`room_for`]).
const SAMPLED_CHILDREN: usize = 32;

/// How many children the bytes `from..room_to` hold if they are as long on
/// average as the `scanned` children found in `from..at`, with an eighth more
/// (and at most one per 8 bytes, the shortest plausible child with
/// whitespace): lists grown by doubling copied themselves into fresh pages
/// several times over.
fn room_for(scanned: usize, from: usize, at: usize, room_to: usize) -> usize {
    let per_child = (at - from).div_ceil(scanned.max(1)).max(1);
    let bytes = room_to.saturating_sub(from);
    (bytes / per_child + bytes / per_child / 8 + 1).min(bytes / 8 + 1)
}

/// Room for `room` heads and extents in all. Out of line, once per scan: in
/// [`scan_from`]'s loop it changed what the compiler inlined there.
#[inline(never)]
fn make_room(heads: &mut Vec<Head>, children: &mut Vec<Range<usize>>, room: usize) {
    heads.reserve_exact(room.saturating_sub(heads.len()));
    children.reserve_exact(room.saturating_sub(children.len()));
}

/// Scans children from `pos` until the root's end tag, or until a child
/// would start at or after `stop`; `None` where the file must be parsed whole.
/// The lists are sized for the children up to `room_to` once the first few
/// are seen.
fn scan_from(text: &str, mut pos: usize, stop: usize, room_to: usize) -> Option<Scanned<'_>> {
    let bytes = text.as_bytes();
    let from = pos;
    let mut heads = Vec::new();
    let mut children = Vec::new();
    loop {
        if heads.len() == SAMPLED_CHILDREN {
            make_room(
                &mut heads,
                &mut children,
                room_for(SAMPLED_CHILDREN, from, pos, room_to),
            );
        }
        pos = skip_whitespace(bytes, pos);
        if pos >= stop {
            break;
        }
        match bytes.get(pos..pos + 2)? {
            b"</" => {
                return Some(Scanned {
                    heads,
                    children,
                    at: pos,
                    ended: true,
                });
            }
            [b'<', c] if !matches!(c, b'!' | b'?') => {
                let (head, tag_end, self_closing) = scan_head(text, pos)?;
                let end = if self_closing {
                    tag_end
                } else {
                    element_end(bytes, tag_end)?
                };
                heads.push(head);
                children.push(pos..end);
                pos = end;
            }
            _ => return None,
        }
    }
    Some(Scanned {
        heads,
        children,
        at: pos,
        ended: false,
    })
}

/// The root's children, each built whole when the iterator reaches it (a run
/// of them is parsed at a time).
pub struct Runs<'a, 's> {
    split: &'a Split<'s>,
    next: usize,
    ready: VecDeque<Element<'s>>,
}

impl<'s> Iterator for Runs<'_, 's> {
    type Item = Result<Element<'s>, Reparse>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.ready.is_empty() {
            if self.next >= self.split.children.len() {
                return None;
            }
            match self.split.parse_run(self.next, &mut self.ready) {
                Ok(next) => self.next = next,
                Err(reparse) => {
                    self.next = self.split.children.len();
                    return Some(Err(reparse));
                }
            }
        }
        self.ready.pop_front().map(Ok)
    }
}

pub(super) fn options<'a>(limits: &Limits) -> roxmltree::ParsingOptions<'a> {
    roxmltree::ParsingOptions {
        allow_dtd: false,
        nodes_limit: limits.max_nodes,
        ..roxmltree::ParsingOptions::default()
    }
}

/// The root's start tag closed by hand and parsed: the XML declaration,
/// prolog and the root's attributes and namespaces get roxmltree's checks.
fn parse_root<'s>(
    text: &'s str,
    tag_end: usize,
    root_name: &str,
    limits: &Limits,
) -> Option<Element<'s>> {
    let head = text.get(..tag_end)?;
    let mut buffer = String::with_capacity(tag_end + root_name.len() + 3);
    buffer.push_str(head);
    buffer.push_str("</");
    buffer.push_str(root_name);
    buffer.push('>');
    let document = roxmltree::Document::parse_with_options(&buffer, options(limits)).ok()?;
    tree::shallow(document.root_element(), Origin::whole(text)).ok()
}

/// Where the root element starts: after an optional byte order mark, XML
/// declaration and whitespace (anything else in the prolog: parse whole).
fn prolog_end(bytes: &[u8]) -> Option<usize> {
    let mut pos = if bytes.starts_with("\u{feff}".as_bytes()) {
        3
    } else {
        0
    };
    if bytes.get(pos..)?.starts_with(b"<?xml") {
        pos += memchr::memmem::find(bytes.get(pos..)?, b"?>")? + 2;
    }
    pos = skip_whitespace(bytes, pos);
    match bytes.get(pos..pos + 2)? {
        [b'<', c] if !matches!(c, b'!' | b'?' | b'/') => Some(pos),
        _ => None,
    }
}

fn skip_whitespace(bytes: &[u8], mut pos: usize) -> usize {
    while bytes
        .get(pos)
        .is_some_and(|b| matches!(b, b' ' | b'\t' | b'\r' | b'\n'))
    {
        pos += 1;
    }
    pos
}

/// The end (after `>`) of the start tag at `pos`, and whether it is `/>`.
/// Quoted attribute values may hold `>`.
fn start_tag_end(bytes: &[u8], pos: usize) -> Option<(usize, bool)> {
    tag_end_from(bytes, pos + 1)
}

/// [`start_tag_end`] from `i`, a position inside the tag outside quotes.
fn tag_end_from(bytes: &[u8], mut i: usize) -> Option<(usize, bool)> {
    loop {
        // Outside quotes only these four bytes matter; a quoted value is
        // skipped whole to its closing quote.
        i += bytes
            .get(i..)?
            .iter()
            .position(|&b| TAG_STOPS.get(usize::from(b)) == Some(&true))?;
        match *bytes.get(i)? {
            b'<' => return None,
            b'>' => return Some((i + 1, bytes.get(i - 1) == Some(&b'/'))),
            quote => i += 1 + find_short(quote, bytes.get(i + 1..)?)? + 1,
        }
    }
}

/// The bytes that end a start tag's stretch outside quotes: `<`, `>` and the quotes.
// Built at compile time: every index is below 256.
#[allow(clippy::indexing_slicing)]
const TAG_STOPS: [bool; 256] = {
    let mut table = [false; 256];
    table[b'<' as usize] = true;
    table[b'>' as usize] = true;
    table[b'"' as usize] = true;
    table[b'\'' as usize] = true;
    table
};

/// The first `byte` in `rest`, looked for byte by byte over the first few
/// bytes (names, values and gaps between tags are mostly short: a memchr
/// call costs more there), then by memchr.
fn find_short(byte: u8, rest: &[u8]) -> Option<usize> {
    const SHORT: usize = 16;
    let (head, tail) = rest.split_at(SHORT.min(rest.len()));
    match head.iter().position(|&b| b == byte) {
        Some(at) => Some(at),
        None => Some(SHORT + memchr::memchr(byte, tail)?),
    }
}

/// The end (after its end tag's `>`) of the element whose start tag ends at
/// `pos` (not self-closing). Comments, CDATA sections and processing
/// instructions inside are skipped; roxmltree checks everything else when the
/// run is parsed. Only the bytes [`Marks`] finds are looked at one by one.
fn element_end(bytes: &[u8], pos: usize) -> Option<usize> {
    let mut depth = 1usize;
    let mut marks = Marks::new(bytes, pos);
    loop {
        let open = marks.find(b'<')?;
        let rest = bytes.get(open..)?;
        match *rest.get(1)? {
            b'/' => {
                let close = marks.find(b'>')?;
                depth -= 1;
                if depth == 0 {
                    return Some(close + 1);
                }
            }
            b'!' if rest.starts_with(b"<!--") => {
                let end = open + 4 + memchr::memmem::find(rest.get(4..)?, b"-->")? + 3;
                marks = Marks::new(bytes, end);
            }
            b'!' if rest.starts_with(b"<![CDATA[") => {
                marks = Marks::new(bytes, open + memchr::memmem::find(rest, b"]]>")? + 3);
            }
            b'!' => return None,
            b'?' => marks = Marks::new(bytes, open + memchr::memmem::find(rest, b"?>")? + 2),
            _ => {
                // A start tag: its `>` outside quotes; a `<` there is an error.
                let self_closing = loop {
                    let at = marks.next()?;
                    match *bytes.get(at)? {
                        b'<' => return None,
                        b'>' => break at.checked_sub(1).and_then(|i| bytes.get(i)) == Some(&b'/'),
                        quote @ (b'"' | b'\'') => drop(marks.find(quote)?),
                        _ => {}
                    }
                };
                if !self_closing {
                    depth += 1;
                }
            }
        }
    }
}

/// The positions, in order from a start, of the bytes that can matter to
/// [`element_end`]: `<`, `>`, `"` and `'` (and `#`, `&`, which share their
/// test and are passed over). Eight bytes are tested at once in a `u64`, so
/// the text between them costs a few instructions per word, not per byte.
struct Marks<'a> {
    bytes: &'a [u8],
    /// The position of the word `found` describes.
    word: usize,
    /// Bit 7 of byte `k` set: the byte at `word + k` is a mark not yet given.
    found: u64,
}

impl<'a> Marks<'a> {
    fn new(bytes: &'a [u8], from: usize) -> Marks<'a> {
        Marks {
            bytes,
            word: from,
            found: marks_in(bytes, from),
        }
    }

    #[inline]
    fn next(&mut self) -> Option<usize> {
        while self.found == 0 {
            self.word += 8;
            if self.word >= self.bytes.len() {
                return None;
            }
            self.found = marks_in(self.bytes, self.word);
        }
        let at = self.word + (self.found.trailing_zeros() / 8) as usize;
        self.found &= self.found - 1;
        Some(at)
    }

    /// The next mark that is `byte`. Inlined like `next`: out of line it
    /// cost `scan_from` about 60 M instructions on a 100k-primitive file.
    #[inline]
    fn find(&mut self, byte: u8) -> Option<usize> {
        loop {
            let at = self.next()?;
            if self.bytes.get(at) == Some(&byte) {
                return Some(at);
            }
        }
    }
}

/// The marks among the eight bytes from `at` (fewer at the end, padded with
/// zeros, which are no mark), as bit 7 of each byte.
fn marks_in(bytes: &[u8], at: usize) -> u64 {
    const ONES: u64 = 0x0101_0101_0101_0101;
    let word = match bytes.get(at..at + 8) {
        Some(word) => word.try_into().map_or(0, u64::from_le_bytes),
        None => {
            let mut padded = [0u8; 8];
            let rest = bytes.get(at..).unwrap_or_default();
            for (to, from) in padded.iter_mut().zip(rest) {
                *to = *from;
            }
            u64::from_le_bytes(padded)
        }
    };
    // `<` and `>` differ only in bit 1; `"`, `'`, `#` and `&` only in bits 0 and 2.
    zero_bytes((word | (ONES * 0x02)) ^ (ONES * u64::from(b'>')))
        | zero_bytes((word | (ONES * 0x05)) ^ (ONES * u64::from(b'\'')))
}

/// Bit 7 set in each byte of `v` that is zero, exactly (no carry crosses a byte).
fn zero_bytes(v: u64) -> u64 {
    const LOW7: u64 = 0x7f7f_7f7f_7f7f_7f7f;
    !(((v & LOW7) + LOW7) | v | LOW7)
}

/// The name starting at `pos`, up to whitespace, `/` or `>`; `None` for a
/// prefixed name (roxmltree's name would be its local part).
fn name_at(text: &str, pos: usize) -> Option<&str> {
    let rest = text.as_bytes().get(pos..)?;
    let len = rest
        .iter()
        .position(|&b| b.is_ascii_whitespace() || b == b'/' || b == b'>')
        .unwrap_or(rest.len());
    let name = text.get(pos..pos + len)?;
    (!name.is_empty() && !name.bytes().any(|b| b == b':')).then_some(name)
}

/// The [`Head`] of the child element at `pos`, read from its start tag, the
/// tag's end (after `>`) and whether it closed itself. A `name=` value
/// roxmltree would change (entities, whitespace normalisation) gives `None`:
/// parse whole. Anything else this does not expect in the tag is left to
/// [`tag_end_from`] (and to the parse of the run).
fn scan_head(text: &str, pos: usize) -> Option<(Head<'_>, usize, bool)> {
    let bytes = text.as_bytes();
    let name = name_at(text, pos + 1)?;
    let mut i = pos + 1 + name.len();
    let mut name_attribute = None;
    loop {
        i = skip_whitespace(bytes, i);
        match bytes.get(i)? {
            b'>' | b'/' => break,
            _ => {}
        }
        let attr_len = bytes
            .get(i..)?
            .iter()
            .position(|&b| b.is_ascii_whitespace() || b == b'=')?;
        let attr = bytes.get(i..i + attr_len)?;
        i = skip_whitespace(bytes, i + attr_len);
        if bytes.get(i) != Some(&b'=') {
            return None;
        }
        i = skip_whitespace(bytes, i + 1);
        let quote = *bytes.get(i)?;
        if quote != b'"' && quote != b'\'' {
            return None;
        }
        let value_len = find_short(quote, bytes.get(i + 1..)?)?;
        if attr == b"name" {
            let value = text.get(i + 1..i + 1 + value_len)?;
            let normalised = |b: &u8| matches!(b, b'&' | b'\t' | b'\n' | b'\r' | b'<');
            if value.as_bytes().iter().any(normalised) || name_attribute.is_some() {
                return None;
            }
            name_attribute = Some(value);
        }
        i += value_len + 2;
    }
    let (tag_end, self_closing) = tag_end_from(bytes, i)?;
    let name_start = pos + 1;
    Some((
        Head {
            name,
            name_span: Span::new(name_start, name_start + name.len()),
            name_attribute,
        },
        tag_end,
        self_closing,
    ))
}

/// The end of the file when `pos` is the root's end tag and only whitespace
/// follows it; that end tag's end is the root's end.
fn root_end(text: &str, pos: usize, root_name: &str) -> Option<usize> {
    let bytes = text.as_bytes();
    let after_name = pos + 2 + root_name.len();
    if text.get(pos + 2..after_name)? != root_name {
        return None;
    }
    let close = skip_whitespace(bytes, after_name);
    if bytes.get(close) != Some(&b'>') {
        return None;
    }
    (skip_whitespace(bytes, close + 1) == bytes.len()).then_some(close + 1)
}

#[cfg(test)]
mod fixture_edits;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::span::SourceFile;
    use crate::test_rng::TestRng;

    /// The children as a whole-file parse builds them.
    fn whole_children(text: &str) -> Vec<Element<'_>> {
        let document = roxmltree::Document::parse(text).expect("test XML parses");
        document
            .root_element()
            .children()
            .filter(|c| c.is_element())
            .map(|c| tree::build(c, Origin::whole(text)).expect("names are in the text"))
            .collect()
    }

    fn split_children<'s>(split: &Split<'s>) -> Vec<Element<'s>> {
        split
            .top_level()
            .collect::<Result<_, _>>()
            .expect("every run parses")
    }

    #[test]
    fn runs_build_the_children_of_a_whole_parse() {
        let text = "<?xml version=\"1.0\"?>\n<geometry version=\"1\" name='a &amp; b'>\n  \
            <sphere name=\"s1\"><center x=\"1\" y=\"2&lt;3\" z=\"3\"/><!-- a > b --><radius value=\"r\"/></sphere>\n\
            <subdomain name='d1' material='&#x31;'  ><solid ref=\"s1\"/><![CDATA[ <x> ]]></subdomain>\n\
            <parameters><parameter name=\"r\" value=\"0.5\"/>text</parameters>\n</geometry >\n";
        let split = Split::scan(text, &Limits::default()).expect("a plain file splits");
        let children = split_children(&split);
        assert_eq!(children, whole_children(text));
        assert_eq!(children.len(), 3);
        assert_eq!(children[0].children[0].attributes[1].value, "2<3");
        let at = text.find(">text<").expect("the test has text") + 1;
        assert_eq!(
            children[2].text,
            vec![("text".to_string(), Span::new(at, at + 4))]
        );
        let root = split.root();
        assert_eq!(
            root.attribute("name").map(|a| a.value.as_ref()),
            Some("a & b")
        );
        assert_eq!(root.span, Span::new(22, text.len() - 1));
        assert_eq!(children[1].attributes[1].value, "1");
        assert_eq!(split.heads()[1].name_attribute, Some("d1"));
        let source = SourceFile::new("t.xml", text);
        let whole = roxmltree::Document::parse(&source.text).expect("parses");
        let heads: Vec<Head> = (whole.root_element().children())
            .filter(|c| c.is_element())
            .map(tree::head)
            .collect();
        assert_eq!(heads, split.heads());
    }

    #[test]
    fn many_children_are_parsed_in_several_runs() {
        let mut text = String::from("<geometry>");
        for i in 0..5000 {
            text.push_str(&format!(
                "\n <sphere name=\"s{i}\"><center x=\"{i}\" y=\"0\" z=\"0\"/></sphere>"
            ));
        }
        text.push_str("\n</geometry>");
        assert!(text.len() > 3 * RUN_BYTES);
        let split = Split::scan(&text, &Limits::default()).expect("a plain file splits");
        assert_eq!(split.heads().len(), 5000);
        let children = split_children(&split);
        assert_eq!(children.len(), 5000);
        assert_eq!(children, whole_children(&text));
        assert_eq!(children[4999].attributes[0].value, "s4999");
    }

    #[test]
    fn scans_in_halves_find_what_one_scan_finds() {
        // Children with nested elements on lines of their own: a guessed
        // middle may be a child's start or lie inside a child.
        let mut text = String::from("<geometry>");
        for i in 0..300 {
            text.push_str(&format!("\n <transform name=\"t{i}\">"));
            for j in 0..i % 4 {
                text.push_str(&format!("\n  <shift x=\"{j}\"/>"));
            }
            text.push_str("\n </transform>");
        }
        text.push_str("\n</geometry>");
        let from = "<geometry>".len();
        let one = scan_children(&text, from, usize::MAX).expect("scans");
        assert_eq!(one.0.len(), 300);
        assert_eq!(one.0[299].name_attribute, Some("t299"));
        assert_eq!(one.2, text.len() - "</geometry>".len());
        let mut kinds = std::collections::BTreeSet::new();
        for at in from..text.len() {
            let Some(middle) = guess_child_start(text.as_bytes(), at) else {
                continue;
            };
            kinds.insert(one.1.iter().any(|c| c.start == middle));
            assert_eq!(scan_halves(&text, from, middle).as_ref(), Some(&one));
        }
        assert_eq!(kinds, [false, true].into());
        assert_eq!(scan_children(&text, from, 0), Some(one));
    }

    #[test]
    fn the_scans_lists_are_sized_from_their_first_children() {
        // 32 children of 20 bytes in 640 bytes: room for 100 children of
        // 2,000 bytes and an eighth, capped at one per 8 bytes.
        assert_eq!(room_for(32, 0, 640, 2_000), 100 + 12 + 1);
        assert_eq!(room_for(32, 1_000, 1_640, 3_000), 100 + 12 + 1);
        assert_eq!(room_for(32, 0, 32, 800), 101);
        assert_eq!(room_for(0, 5, 5, 4), 1);
        let mut text = String::from("<geometry>");
        for i in 0..4_000 {
            text.push_str(&format!(
                "\n <sphere name=\"s{i:04}\"><radius value=\"1\"/></sphere>"
            ));
        }
        text.push_str("\n</geometry>");
        let from = "<geometry>".len();
        let middle = guess_child_start(text.as_bytes(), text.len() / 2).expect("a child");
        let (heads, children, _) = scan_halves(&text, from, middle).expect("scans");
        assert_eq!((heads.len(), children.len()), (4_000, 4_000));
        // Sized once for the whole (the second half joined without growing):
        // a list grown by doubling would hold 4,096.
        let sampled_to = children[SAMPLED_CHILDREN - 1].end;
        let whole = room_for(SAMPLED_CHILDREN, from, sampled_to, text.len());
        assert_eq!(heads.capacity(), whole);
        assert_eq!(children.capacity(), whole);
        assert!((4_000..4_600).contains(&whole), "{whole}");
    }

    /// Random edits of a file of many children: whenever the scan splits it
    /// and every run reads, the children and heads are those of a whole
    /// parse, and when the whole parse refuses the file some run refuses too.
    #[test]
    fn edited_files_split_only_as_a_whole_parse_reads_them() {
        let mut plain = String::from("<geometry version=\"1\">");
        for i in 0..12 {
            plain.push_str(&format!(
                "\n <sphere name=\"s{i}\"><center x=\"{i}\" y='a>b' z=\"0\"/><radius value=\"r\"></radius></sphere>\
                 \n <subdomain name='d{i}'><solid ref=\"s{i}\"/></subdomain>"
            ));
        }
        plain.push_str("\n</geometry>\n");
        let alphabet: &[u8] = b"<>/=\"' \t\n&!?-[]:_aZ09";
        let mut rng = TestRng::new(0x9e37_79b9_7f4a_7c15);
        // Runs of a few children each, so that edits fall in several runs.
        let limits = Limits::default();
        let (mut split_and_read, mut refused) = (0, 0);
        for _ in 0..3_000 {
            let Some(text) = rng.edit(&plain, alphabet, 2) else {
                continue;
            };
            let whole = roxmltree::Document::parse_with_options(&text, options(&limits)).ok();
            let Some(split) = Split::scan(&text, &limits) else {
                continue;
            };
            match split.top_level().collect::<Result<Vec<_>, _>>() {
                Ok(children) => {
                    split_and_read += 1;
                    assert!(whole.is_some(), "{text:?}");
                    assert_eq!(children, whole_children(&text), "{text:?}");
                    let root = whole.as_ref().map(|d| d.root_element());
                    let heads: Option<Vec<Head>> = root.map(|r| {
                        r.children()
                            .filter(|c| c.is_element())
                            .map(tree::head)
                            .collect()
                    });
                    assert_eq!(heads.as_deref(), Some(split.heads()), "{text:?}");
                }
                Err(Reparse) => refused += 1,
            }
        }
        assert!(split_and_read > 300, "{split_and_read} {refused}");
        assert!(refused > 500, "{split_and_read} {refused}");
    }

    #[test]
    fn marks_are_every_byte_of_their_set_in_order() {
        let bytes: Vec<u8> = (0..=255u8)
            .chain(b"a<b>c\"d'e#f&".iter().copied())
            .collect();
        for from in 0..bytes.len() {
            let mut marks = Marks::new(&bytes, from);
            let found: Vec<usize> = std::iter::from_fn(|| marks.next()).collect();
            let expected: Vec<usize> = (from..bytes.len())
                .filter(|&i| matches!(bytes[i], b'<' | b'>' | b'"' | b'\'' | b'#' | b'&'))
                .collect();
            assert_eq!(found, expected, "from {from}");
        }
        let mut marks = Marks::new(b"<a x='\"'>", 1);
        assert_eq!(marks.find(b'\''), Some(5));
        assert_eq!(marks.find(b'>'), Some(8));
        assert_eq!(marks.find(b'>'), None);
    }

    #[test]
    fn element_ends_skip_quotes_comments_and_sections() {
        for (text, end) in [
            ("<a><b x='>' y=\"</a>\"/></a> <c/>", Some(26)),
            ("<a><!-- </a> --><![CDATA[</a>]]><?p </a>?></a>", Some(46)),
            ("<a><b>t > u</b></a>", Some(19)),
            ("<a><b x=\"1\"<c/></b></a>", None),
            ("<a><!DOCTYPE x></a>", None),
            ("<a><b></a>", None),
        ] {
            assert_eq!(element_end(text.as_bytes(), 3), end, "{text}");
        }
    }

    #[test]
    fn start_tags_end_at_the_first_close_outside_quotes() {
        for (tag, end) in [
            ("<a x=\"1>2\"/> <b/>", Some((12, true))),
            ("<a x='\"'> </a>", Some((9, false))),
            ("<a x=\"<\" y='>'>", Some((15, false))),
            ("<a x=\"/\">", Some((9, false))),
            ("<a/>", Some((4, true))),
            ("<a <b>", None),
            ("<a x=\"1>", None),
            ("<a x='1'", None),
        ] {
            assert_eq!(start_tag_end(tag.as_bytes(), 0), end, "{tag}");
        }
    }

    #[test]
    fn unusual_top_levels_are_parsed_whole() {
        let limits = Limits::default();
        for text in [
            "<geometry><!-- note --><sphere name=\"s\"/></geometry>",
            "<geometry>text<sphere name=\"s\"/></geometry>",
            "<!-- c --><geometry><sphere name=\"s\"/></geometry>",
            "<geometry><sphere name=\"s\"/></geometry><!-- after -->",
            "<g:geometry xmlns:g=\"u\"><sphere name=\"s\"/></g:geometry>",
            "<geometry><x:sphere xmlns:x=\"u\" name=\"s\"/></geometry>",
            "<geometry><sphere name=\"s\ttab\"/></geometry>",
            "<geometry><sphere name=\"&#x31;\"/></geometry>",
            "<geometry><sphere name=\"s\" name=\"t\"/></geometry>",
            "<geometry/>",
        ] {
            assert!(Split::scan(text, &limits).is_none(), "{text}");
        }
        let few_nodes = Limits {
            max_nodes: 40,
            ..limits
        };
        assert!(Split::scan("<geometry><sphere name=\"s\"/></geometry>", &few_nodes).is_none());
    }

    #[test]
    fn pieces_the_whole_file_would_read_differently_ask_for_a_reparse() {
        let limits = Limits::default();
        // A prefix bound on the root, an XML error inside a child, nesting over the limit.
        let deep = Limits {
            max_depth: 2,
            ..limits
        };
        for (text, limits) in [
            (
                "<geometry xmlns:p=\"u\"><sphere p:name=\"s\"/></geometry>",
                limits,
            ),
            (
                "<geometry><sphere name=\"s\"><center></centre></sphere></geometry>",
                limits,
            ),
            (
                "<geometry><sphere name=\"s\">&bogus;</sphere></geometry>",
                limits,
            ),
            (
                "<geometry><sphere name=\"s\" x=\"1\" x=\"2\"/></geometry>",
                limits,
            ),
            (
                "<geometry><sphere name=\"s\"><center/></sphere></geometry>",
                deep,
            ),
        ] {
            let Some(split) = Split::scan(text, &limits) else {
                panic!("the scan alone accepts {text}");
            };
            let first = split.top_level().next();
            assert_eq!(first, Some(Err(Reparse)), "{text}");
        }
    }
}
