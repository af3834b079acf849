//! Runs of plain markup read straight into element trees, without roxmltree.
//!
//! roxmltree's parse of a run and the conversion of its nodes into
//! [`Element`]s were about a fifth of the front end's CPU time on large files;
//! most such files are plain: ASCII elements with quoted attributes and
//! whitespace between them. This reader takes exactly that subset, where an
//! XML parser has nothing to decide (no entity, comment, CDATA section,
//! processing instruction, text, namespace, non-ASCII or control character,
//! nor a value roxmltree would normalise), and gives the trees roxmltree's
//! path gives. Anything else, well-formed or not, makes it give up (`None`)
//! and the run goes to roxmltree as before, which also reports every error:
//! this reader never decides that a file is wrong.

use super::tree::{Attribute, Attributes, Element};
use crate::span::Span;
use std::borrow::Cow;
use std::sync::Arc;

/// The elements of `text[start..end]`, a run of whole elements separated by
/// whitespace, as roxmltree's path builds them; `None` when the run is not
/// plain (see the module) or nests deeper than `max_depth` (the root being
/// level 1, so the run's elements are level 2). `elements`: how many
/// elements the run is expected to hold (only sizes the list).
pub(super) fn read_run(
    text: &str,
    start: usize,
    end: usize,
    max_depth: usize,
    elements: usize,
) -> Option<Vec<Element<'_>>> {
    if !text.get(start..end)?.is_ascii() {
        return None;
    }
    let mut reader = Reader {
        text,
        bytes: text.as_bytes().get(..end)?,
        pos: start,
        // Every element's attributes, in document order: shared by the
        // run's elements once it is read. Sized for a run of the split's
        // usual length (about one per 16 bytes of markup); a longer one grows.
        attributes: Vec::with_capacity(((end - start) / 16).min(4096) + 8),
    };
    // Finished elements: the run's, and the children of the open elements
    // after the index each was opened at (moved into it, sized exactly, when
    // it closes).
    let mut finished: Vec<Element> = Vec::with_capacity(elements);
    let mut open: Vec<(Element, usize)> = Vec::new();
    loop {
        reader.skip_whitespace();
        let Some(&byte) = reader.bytes.get(reader.pos) else {
            if !open.is_empty() {
                return None;
            }
            share(&mut finished, &Arc::new(reader.attributes));
            return Some(finished);
        };
        if byte != b'<' {
            return None;
        }
        if reader.bytes.get(reader.pos + 1) == Some(&b'/') {
            let (mut element, first) = open.pop()?;
            reader.pos += 2;
            // The open element's name, then (after whitespace) `>`: any other
            // end tag is refused as reading a name and comparing would.
            let name = element.name.as_bytes();
            if reader.bytes.get(reader.pos..reader.pos + name.len()) != Some(name) {
                return None;
            }
            reader.pos += name.len();
            reader.skip_whitespace();
            reader.expect(b'>')?;
            element.span = Span::new(element.span.range().start, reader.pos);
            element.children = finished.split_off(first);
            finished.push(element);
            continue;
        }
        if open.len() + 2 > max_depth {
            return None;
        }
        let (element, closed) = reader.start_tag()?;
        if closed {
            finished.push(element);
        } else {
            open.push((element, finished.len()));
        }
    }
}

/// Gives every element of the trees its range of the run's attributes.
fn share<'s>(elements: &mut [Element<'s>], attributes: &Arc<Vec<Attribute<'s>>>) {
    let mut lists = vec![elements];
    while let Some(list) = lists.pop() {
        for element in list {
            element.attributes.share(attributes);
            if !element.children.is_empty() {
                lists.push(&mut element.children);
            }
        }
    }
}

struct Reader<'s> {
    text: &'s str,
    /// The text up to the run's end.
    bytes: &'s [u8],
    pos: usize,
    /// The attributes read so far (see [`read_run`]).
    attributes: Vec<Attribute<'s>>,
}

impl<'s> Reader<'s> {
    fn skip_whitespace(&mut self) -> usize {
        let from = self.pos;
        while self
            .bytes
            .get(self.pos)
            .is_some_and(|b| matches!(b, b' ' | b'\t' | b'\r' | b'\n'))
        {
            self.pos += 1;
        }
        self.pos - from
    }

    fn expect(&mut self, byte: u8) -> Option<()> {
        (self.bytes.get(self.pos) == Some(&byte)).then(|| self.pos += 1)
    }

    /// A name of ASCII letters, digits, `_`, `-` and `.` not starting with a
    /// digit, `-` or `.`, followed by whitespace, `/`, `>` or `=` (a `:`, i.e.
    /// a prefix, gives `None`).
    fn name(&mut self) -> Option<&'s str> {
        let start = self.pos;
        let rest = self.bytes.get(start..)?;
        if !rest
            .first()
            .is_some_and(|b| b.is_ascii_alphabetic() || *b == b'_')
        {
            return None;
        }
        let len = rest
            .iter()
            .position(|&b| !is_name_byte(b))
            .unwrap_or(rest.len());
        if !matches!(
            rest.get(len),
            None | Some(b' ' | b'\t' | b'\r' | b'\n' | b'/' | b'>' | b'=')
        ) {
            return None;
        }
        self.pos += len;
        self.text.get(start..self.pos)
    }

    /// The start tag at `pos` (a `<`) as an element without children, and
    /// whether it closed itself (`/>`); its attributes are pushed onto the
    /// run's list and the element holds their range (pending until shared).
    fn start_tag(&mut self) -> Option<(Element<'s>, bool)> {
        let tag_start = self.pos;
        self.pos += 1;
        let name = self.name()?;
        let first = self.attributes.len();
        let closed = loop {
            let spaced = self.skip_whitespace() > 0;
            match self.bytes.get(self.pos)? {
                b'>' => {
                    self.pos += 1;
                    break false;
                }
                b'/' => {
                    self.pos += 1;
                    self.expect(b'>')?;
                    break true;
                }
                // An attribute must follow whitespace.
                _ if !spaced => return None,
                _ => {
                    let attribute = self.attribute()?;
                    // A repeated attribute and a namespace declaration are
                    // roxmltree's to judge.
                    if attribute.name == "xmlns"
                        || (self.attributes.get(first..)?.iter())
                            .any(|a| same_name(a.name, attribute.name))
                    {
                        return None;
                    }
                    self.attributes.push(attribute);
                }
            }
        };
        let name_start = tag_start + 1;
        let attributes = Attributes::pending(
            u32::try_from(first).ok()?,
            u32::try_from(self.attributes.len() - first).ok()?,
        );
        Some((
            Element {
                name,
                span: Span::new(tag_start, self.pos),
                name_span: Span::new(name_start, name_start + name.len()),
                attributes,
                children: Vec::new(),
                text: Vec::new(),
            },
            closed,
        ))
    }

    /// `name = "value"` at `pos`; `None` for a value roxmltree would expand
    /// or normalise (`&`, tab, line ends), or refuse (`<`, control characters).
    fn attribute(&mut self) -> Option<Attribute<'s>> {
        let name_start = self.pos;
        let name = self.name()?;
        let name_span = Span::new(name_start, self.pos);
        self.skip_whitespace();
        self.expect(b'=')?;
        self.skip_whitespace();
        let quote = *self.bytes.get(self.pos)?;
        if quote != b'"' && quote != b'\'' {
            return None;
        }
        let value_start = self.pos + 1;
        let length = value_length(self.bytes.get(value_start..)?, quote)?;
        let value = self.text.get(value_start..value_start + length)?;
        self.pos = value_start + length + 1;
        Some(Attribute {
            name,
            name_span,
            value: Cow::Borrowed(value),
            value_span: Span::new(value_start, value_start + length),
        })
    }
}

/// `a == b`, by length and first byte before the bytes: an element's
/// attributes mostly differ there (`x`, `y`, `z`), and a `memcmp` call per
/// pair was most of the repeated-name check.
fn same_name(a: &str, b: &str) -> bool {
    a.len() == b.len() && a.as_bytes().first() == b.as_bytes().first() && a == b
}

/// Bytes of a name after its first: ASCII letters, digits, `_`, `-`, `.`.
fn is_name_byte(b: u8) -> bool {
    NAME_BYTES.get(usize::from(b)) == Some(&true)
}

// Built at compile time: every index is below 256.
#[allow(clippy::indexing_slicing)]
const NAME_BYTES: [bool; 256] = {
    let mut table = [false; 256];
    let mut b = 0;
    while b < 256 {
        let c = b as u8;
        table[b] = c.is_ascii_alphanumeric() || matches!(c, b'_' | b'-' | b'.');
        b += 1;
    }
    table
};

/// The length of a quoted value up to its closing `quote`, in one pass;
/// `None` at a byte roxmltree would expand (`&`) or refuse (`<`, control
/// characters, which include the tab and line ends it would normalise).
fn value_length(rest: &[u8], quote: u8) -> Option<usize> {
    let mut at = 0;
    loop {
        at += rest
            .get(at..)?
            .iter()
            .position(|&b| VALUE_STOPS.get(usize::from(b)) == Some(&true))?;
        match *rest.get(at)? {
            b if b == quote => return Some(at),
            b'"' | b'\'' => at += 1,
            _ => return None,
        }
    }
}

/// Bytes a value's scan stops at: the quotes, `&`, `<` and control characters.
#[allow(clippy::indexing_slicing)]
const VALUE_STOPS: [bool; 256] = {
    let mut table = [false; 256];
    let mut b = 0;
    while b < 256 {
        let c = b as u8;
        table[b] = c < b' ' || matches!(c, b'"' | b'\'' | b'&' | b'<');
        b += 1;
    }
    table
};

#[cfg(test)]
mod tests {
    use super::super::split::options;
    use super::super::tree::{self, Origin};
    use super::*;
    use crate::syntax::Limits;
    use crate::test_rng::TestRng;

    /// The run as the split's roxmltree path reads it: inside a wrapper,
    /// whitespace only between the elements, nesting within `max_depth`.
    fn by_roxmltree(text: &str, max_depth: usize) -> Option<Vec<Element<'_>>> {
        let wrapped = format!("<r>{text}</r>");
        let limits = Limits {
            max_depth,
            ..Limits::default()
        };
        let document = roxmltree::Document::parse_with_options(&wrapped, options(&limits)).ok()?;
        let wrapper = document.root_element();
        super::super::check_depth(wrapper, &limits).ok()?;
        let at = Origin {
            source: text,
            shift: -3,
        };
        let mut elements = Vec::new();
        for node in wrapper.children() {
            if node.is_element() {
                elements.push(tree::build(node, at).ok()?);
            } else if !node.text().is_some_and(|t| t.trim().is_empty()) {
                return None;
            }
        }
        Some(elements)
    }

    fn plain(text: &str, max_depth: usize) -> Option<Vec<Element<'_>>> {
        read_run(text, 0, text.len(), max_depth, 0)
    }

    const PLAIN: &str = "\n  <sphere name=\"p0\"><center x=\"0\" y = '1.5' z=\"a>b\"/><radius value=\"r*2\"></radius></sphere>\n\
        \t<subdomain name=\"d0\" material=\"steel\" ><union><solid ref=\"p0\"/><solid ref='p_1.x-y'/></union></subdomain >\r\n\
        <parallelepiped name=\"p1\"><first_point x=\"2\" y=\"0\" z=\"0\"   /><second_point x=\"2.5\" y=\"0.5\" z=\"0.5\"/></parallelepiped>  ";

    #[test]
    fn plain_runs_read_as_roxmltree_reads_them() {
        let read = plain(PLAIN, 64).expect("the run is plain");
        assert_eq!(Some(&read), by_roxmltree(PLAIN, 64).as_ref());
        assert_eq!(read.len(), 3);
        let center = &read[0].children[0];
        assert_eq!(center.attributes[1].value, "1.5");
        assert_eq!(center.attributes[2].value, "a>b");
        let at = PLAIN.find("1.5").expect("in the text");
        assert_eq!(center.attributes[1].value_span, Span::new(at, at + 3));
        assert_eq!(read[1].children[0].children.len(), 2);
        assert_eq!(read[1].children[0].children[1].children.len(), 0);
        let end = PLAIN.find("</subdomain >").expect("in the text") + "</subdomain >".len();
        assert_eq!(read[1].span.range().end, end);
        // Nesting: the union's solids are level 4.
        assert_eq!(plain(PLAIN, 4), by_roxmltree(PLAIN, 4));
        assert_eq!(plain(PLAIN, 3), None);
        assert_eq!(by_roxmltree(PLAIN, 3), None);
    }

    #[test]
    fn what_roxmltree_must_judge_is_left_to_it() {
        for text in [
            "<a x=\"1 &amp; 2\"/>",
            "<a x=\"1\t2\"/>",
            "<a x=\"1\n2\"/>",
            "<a><!-- note --></a>",
            "<a><![CDATA[x]]></a>",
            "<a><?pi x?></a>",
            "<a>text</a>",
            "<a xmlns=\"u\"/>",
            "<p:a xmlns:p=\"u\"/>",
            "<a p:x=\"1\" xmlns:p=\"u\"/>",
            "<a x=\"é\"/>",
            "<é/>",
        ] {
            assert!(by_roxmltree(text, 64).is_some(), "{text}");
            assert_eq!(plain(text, 64), None, "{text}");
        }
        for text in [
            "<a x=\"1\" x=\"2\"/>",
            "<a x=\"1\"y=\"2\"/>",
            "<a x=\"<\"/>",
            "<a x=1/>",
            "<a></b>",
            "<a>",
            "</a>",
            "<a/ >",
            "<1a/>",
            "<a\u{1}/>",
            "<a x=\"\u{1}\"/>",
        ] {
            assert_eq!(by_roxmltree(text, 64), None, "{text}");
            assert_eq!(plain(text, 64), None, "{text}");
        }
    }

    /// Random edits of a plain run: whatever this reader accepts, roxmltree
    /// reads to the same trees.
    #[test]
    fn edited_runs_it_accepts_are_what_roxmltree_reads() {
        let alphabet: &[u8] = b"<>/=\"' \t\n\r&!?:-._aZ09x\x01";
        let mut rng = TestRng::new(0x2545_f491_4f6c_dd1d);
        let (mut accepted, mut refused_by_both) = (0, 0);
        for _ in 0..8_000 {
            let Some(text) = rng.edit(PLAIN, alphabet, 3) else {
                continue;
            };
            let depth = 3 + rng.below(3);
            match plain(&text, depth) {
                Some(read) => {
                    accepted += 1;
                    assert_eq!(Some(read), by_roxmltree(&text, depth), "{text:?}");
                }
                None if by_roxmltree(&text, depth).is_none() => refused_by_both += 1,
                None => {}
            }
        }
        // Both sides of the line are exercised.
        assert!(accepted > 500, "{accepted} {refused_by_both}");
        assert!(refused_by_both > 500, "{accepted} {refused_by_both}");
    }

    /// A random run of nested elements, each with 0–3 attributes named and
    /// valued by its number; returns the text and how many elements it has.
    fn nested_run(rng: &mut TestRng) -> (String, usize) {
        let (mut text, mut open, mut count) = (String::new(), Vec::new(), 0);
        for _ in 0..1 + rng.below(60) {
            if !open.is_empty() && rng.below(3) == 0 {
                let name: String = open.pop().unwrap_or_default();
                text.push_str(&format!("</{name}>"));
                continue;
            }
            let name = format!("e{count}");
            text.push_str(&format!("<{name}"));
            for k in 0..rng.below(4) {
                text.push_str(&format!(" a{k}_{count}=\"{count}.{k}\""));
            }
            count += 1;
            if open.len() < 6 && rng.below(2) == 0 {
                text.push('>');
                open.push(name);
            } else {
                text.push_str("/>");
            }
            text.push_str(["", " ", "\n  "][rng.below(3)]);
        }
        while let Some(name) = open.pop() {
            text.push_str(&format!("</{name}>"));
        }
        (text, count)
    }

    /// The attributes of an element: every attribute of its start tag, in
    /// order, as an independent reading of the text gives them.
    fn start_tag_attributes(text: &str, element: &Element) -> Vec<(String, String)> {
        let tag = &text[element.span.range().start..];
        let tag = &tag[..tag.find('>').expect("a start tag ends")];
        let mut pairs = Vec::new();
        for part in tag.split_whitespace().skip(1) {
            if let Some((name, value)) = part.trim_end_matches('/').split_once('=') {
                pairs.push((name.to_string(), value.trim_matches('"').to_string()));
            }
        }
        pairs
    }

    /// The run's attributes are one list shared by its elements: every
    /// element, at every depth, holds exactly its start tag's attributes
    /// (the ranges follow document order through the nesting), and the
    /// trees are roxmltree's.
    #[test]
    fn every_element_holds_the_attributes_of_its_start_tag() {
        let mut rng = TestRng::new(0x9e37_79b9_7f4a_7c15);
        let (mut elements, mut attributes) = (0, 0);
        for _ in 0..400 {
            let (text, count) = nested_run(&mut rng);
            let read = plain(&text, 16).expect("the run is plain");
            assert_eq!(Some(&read), by_roxmltree(&text, 16).as_ref(), "{text}");
            let mut stack: Vec<&Element> = read.iter().collect();
            let mut seen = 0;
            while let Some(element) = stack.pop() {
                seen += 1;
                let held: Vec<(String, String)> = (element.attributes.iter())
                    .map(|a| (a.name.to_string(), a.value.to_string()))
                    .collect();
                assert_eq!(held, start_tag_attributes(&text, element), "{text}");
                for a in &element.attributes {
                    assert_eq!(&text[a.value_span.range()], a.value);
                }
                attributes += held.len();
                stack.extend(&element.children);
            }
            assert_eq!(seen, count, "{text}");
            elements += seen;
        }
        assert!(
            elements > 4_000 && attributes > 4_000,
            "{elements} {attributes}"
        );
    }

    /// Attributes compare by their contents, not by the list they share.
    #[test]
    fn attributes_equal_by_contents_not_by_list() {
        let text = "<a x=\"1\" y=\"2\"/><b x=\"1\" y=\"2\"/><c/>";
        let read = plain(text, 4).expect("plain");
        let own = by_roxmltree(text, 4).expect("well-formed");
        assert_eq!(read[0].attributes.len(), 2);
        assert_eq!(read[0].attributes[1].value, "2");
        assert_ne!(read[0].attributes, read[1].attributes);
        assert_eq!(read[0].attributes, own[0].attributes);
        assert!(read[2].attributes.is_empty());
        assert_eq!(read[2].attributes, Attributes::default());
        assert_eq!(Attributes::new(Vec::new()), Attributes::default());
        assert!(Attributes::pending(0, 2).is_empty());
    }
}
