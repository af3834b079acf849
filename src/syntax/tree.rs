//! The element tree: names, attributes and children with byte spans. Names
//! and attribute values borrow from the source text (a value is owned only
//! when the parser had to expand an entity or normalise whitespace in it), so
//! building the tree allocates little more than its vectors.

use crate::span::Span;
use std::borrow::Cow;
use std::sync::Arc;

#[derive(Debug, Clone, PartialEq)]
pub struct Attribute<'s> {
    pub name: &'s str,
    pub name_span: Span,
    pub value: Cow<'s, str>,
    pub value_span: Span,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Element<'s> {
    pub name: &'s str,
    /// The whole element, from `<` to the end of its closing tag.
    pub span: Span,
    /// The element's name in its start tag.
    pub name_span: Span,
    pub attributes: Attributes<'s>,
    pub children: Vec<Element<'s>>,
    /// Non-whitespace text directly inside the element, with its span.
    pub text: Vec<(String, Span)>,
}

/// An element's attributes, read as a slice: a range of one list shared by
/// all elements of a plain run (`super::plain`), so a run of thousands of
/// elements allocates one list instead of one per element, or a list of the
/// element's own. Two are equal when their attributes are.
#[derive(Clone, Default)]
pub struct Attributes<'s> {
    /// `None` for no attributes, and while a plain run is being read.
    store: Option<Arc<Vec<Attribute<'s>>>>,
    start: u32,
    len: u32,
}

impl<'s> Attributes<'s> {
    /// A list of the element's own.
    pub fn new(list: Vec<Attribute<'s>>) -> Attributes<'s> {
        match u32::try_from(list.len()) {
            Ok(len) if len > 0 => Attributes {
                store: Some(Arc::new(list)),
                start: 0,
                len,
            },
            _ => Attributes::default(),
        }
    }

    /// `len` attributes from `start` of a list not made yet: empty until
    /// [`Attributes::share`] gives it.
    pub(super) fn pending(start: u32, len: u32) -> Attributes<'s> {
        Attributes {
            store: None,
            start,
            len,
        }
    }

    /// Gives a pending range its list (a range of none keeps no list).
    pub(super) fn share(&mut self, store: &Arc<Vec<Attribute<'s>>>) {
        if self.len > 0 {
            self.store = Some(Arc::clone(store));
        }
    }
}

impl<'s> std::ops::Deref for Attributes<'s> {
    type Target = [Attribute<'s>];

    fn deref(&self) -> &[Attribute<'s>] {
        let (start, len) = (self.start as usize, self.len as usize);
        (self.store.as_deref())
            .and_then(|list| list.get(start..start + len))
            .unwrap_or(&[])
    }
}

impl<'a, 's> IntoIterator for &'a Attributes<'s> {
    type Item = &'a Attribute<'s>;
    type IntoIter = std::slice::Iter<'a, Attribute<'s>>;

    fn into_iter(self) -> Self::IntoIter {
        self.iter()
    }
}

impl<'s> FromIterator<Attribute<'s>> for Attributes<'s> {
    fn from_iter<I: IntoIterator<Item = Attribute<'s>>>(iter: I) -> Attributes<'s> {
        Attributes::new(iter.into_iter().collect())
    }
}

impl PartialEq for Attributes<'_> {
    fn eq(&self, other: &Self) -> bool {
        **self == **other
    }
}

impl std::fmt::Debug for Attributes<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_list().entries(self.iter()).finish()
    }
}

impl<'s> Element<'s> {
    pub fn attribute(&self, name: &str) -> Option<&Attribute<'s>> {
        self.attributes.iter().find(|a| a.name == name)
    }

    pub fn children_named<'a>(
        &'a self,
        name: &'a str,
    ) -> impl Iterator<Item = &'a Element<'s>> + 'a {
        self.children.iter().filter(move |c| c.name == name)
    }
}

/// Where a parsed node's text lies in the source: the node's positions plus
/// `shift` are source offsets. A whole-file parse has shift 0; a piece of the
/// file parsed inside a wrapper (`super::split`) is shifted by its place.
#[derive(Debug, Clone, Copy)]
pub(super) struct Origin<'s> {
    pub source: &'s str,
    pub shift: isize,
}

impl<'s> Origin<'s> {
    pub fn whole(source: &'s str) -> Origin<'s> {
        Origin { source, shift: 0 }
    }

    fn at(&self, pos: usize) -> usize {
        pos.wrapping_add_signed(self.shift)
    }

    fn span(&self, range: std::ops::Range<usize>) -> Span {
        Span::new(self.at(range.start), self.at(range.end))
    }

    /// The source's text at a parsed node's `range`, when it is `expected`
    /// (names and unexpanded values are slices of the source, not of the
    /// parser's input, so they outlive a wrapper's buffer).
    fn text(&self, start: usize, expected: &str) -> Option<&'s str> {
        let start = self.at(start);
        self.source
            .get(start..start + expected.len())
            .filter(|t| *t == expected)
    }

    /// An element's (local) name as a slice of the source.
    fn element_name(&self, node: roxmltree::Node) -> Option<&'s str> {
        let rest = self.source.get(self.at(node.range().start + 1)..)?;
        let len = rest
            .find(|c: char| c.is_ascii_whitespace() || c == '/' || c == '>')
            .unwrap_or(rest.len());
        let local = rest.get(..len)?.rsplit(':').next()?;
        (local == node.tag_name().name()).then_some(local)
    }
}

/// A parsed name that is not in the source where the parser put it (never
/// seen: a guard, since names must be slices of the source, not of a buffer).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Misplaced;

/// Converts a parsed roxmltree node into the tree. Iterative, so depth
/// is bounded only by memory (the caller has already checked the depth limit).
pub(super) fn build<'s>(
    root: roxmltree::Node<'_, '_>,
    at: Origin<'s>,
) -> Result<Element<'s>, Misplaced> {
    // Post-order assembly: each frame keeps its child iterator and collects its
    // finished children.
    let mut stack = vec![(root.children(), shell(root, at)?)];
    loop {
        let Some((children, element)) = stack.last_mut() else {
            unreachable!("the stack holds the root until it is returned")
        };
        match children.next() {
            Some(child) if child.is_element() => {
                let shell = shell(child, at)?;
                stack.push((child.children(), shell));
            }
            Some(child) if child.is_text() => push_text(element, child, at),
            Some(_) => {}
            None => {
                let Some((_, finished)) = stack.pop() else {
                    unreachable!("the loop only pops a frame it has just seen")
                };
                match stack.last_mut() {
                    Some(parent) => parent.1.children.push(finished),
                    None => return Ok(finished),
                }
            }
        }
    }
}

/// What the checks of a parent read of a child element before building it:
/// its name, the span of that name, and its `name=` attribute. The root of a
/// large file has hundreds of thousands of children; heads of them are a few
/// words each, where whole shells (attribute vectors included) were a tenth of
/// the front end's time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Head<'a> {
    pub name: &'a str,
    pub name_span: Span,
    /// The value of the child's `name=` attribute, untrimmed.
    pub name_attribute: Option<&'a str>,
}

impl Head<'_> {
    /// `*self == element.head()`, but names and values that are the same
    /// slice of the text are equal without comparing their bytes: the scan's
    /// heads and the plain reader's elements borrow the same source, and the
    /// comparisons were 1% of reading a large file.
    pub fn is_of(&self, element: &Element) -> bool {
        let head = element.head();
        self.name_span == head.name_span
            && same_text(self.name, head.name)
            && match (self.name_attribute, head.name_attribute) {
                (Some(a), Some(b)) => same_text(a, b),
                (a, b) => a.is_none() && b.is_none(),
            }
    }
}

/// `a == b`, at once when both are the same slice.
fn same_text(a: &str, b: &str) -> bool {
    (std::ptr::eq(a.as_ptr(), b.as_ptr()) && a.len() == b.len()) || a == b
}

impl<'s> Element<'s> {
    /// This element's [`Head`].
    pub fn head(&self) -> Head<'_> {
        Head {
            name: self.name,
            name_span: self.name_span,
            name_attribute: self.attribute("name").map(|a| a.value.as_ref()),
        }
    }
}

/// The element with its attributes and non-whitespace text, without children.
pub(super) fn shallow<'s>(
    node: roxmltree::Node<'_, '_>,
    at: Origin<'s>,
) -> Result<Element<'s>, Misplaced> {
    let mut element = shell_with(node, 0, at)?;
    for child in node.children().filter(|c| c.is_text()) {
        push_text(&mut element, child, at);
    }
    Ok(element)
}

/// The [`Head`] of an element node.
pub(super) fn head<'a>(node: roxmltree::Node<'a, '_>) -> Head<'a> {
    let name = node.tag_name().name();
    let name_start = node.range().start + 1;
    Head {
        name,
        name_span: Span::new(name_start, name_start + name.len()),
        name_attribute: node
            .attributes()
            .find(|a| a.namespace().is_none() && a.name() == "name")
            .map(|a| a.value()),
    }
}

fn push_text(element: &mut Element, node: roxmltree::Node, at: Origin) {
    let text = node.text().unwrap_or("");
    if !text.trim().is_empty() {
        element
            .text
            .push((text.trim().to_string(), at.span(node.range())));
    }
}

fn shell<'s>(node: roxmltree::Node<'_, '_>, at: Origin<'s>) -> Result<Element<'s>, Misplaced> {
    // Sized exactly: no growth by doubling (the root of a large file has
    // hundreds of thousands of children).
    shell_with(node, node.children().filter(|c| c.is_element()).count(), at)
}

fn shell_with<'s>(
    node: roxmltree::Node<'_, '_>,
    children: usize,
    at: Origin<'s>,
) -> Result<Element<'s>, Misplaced> {
    let range = node.range();
    let name = at.element_name(node).ok_or(Misplaced)?;
    let name_start = at.at(range.start + 1);
    let mut attributes = Vec::new();
    // Namespaced attributes (xsi:noNamespaceSchemaLocation) belong to the XML
    // tooling, not to the format.
    for a in node.attributes().filter(|a| a.namespace().is_none()) {
        let qname = a.range_qname();
        let value_range = a.range_value();
        attributes.push(Attribute {
            name: at.text(qname.start, a.name()).ok_or(Misplaced)?,
            name_span: at.span(qname),
            value: match a.value_storage() {
                roxmltree::StringStorage::Borrowed(text) => at
                    .text(value_range.start, text)
                    .map_or_else(|| Cow::Owned(text.to_string()), Cow::Borrowed),
                other => Cow::Owned(other.as_str().to_string()),
            },
            value_span: at.span(value_range),
        });
    }
    Ok(Element {
        name_span: Span::new(name_start, name_start + name.len()),
        name,
        span: at.span(range),
        attributes: Attributes::new(attributes),
        children: Vec::with_capacity(children),
        text: Vec::new(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn element<'s>(name: &'s str, at: usize, attributes: &[(&'s str, &'s str)]) -> Element<'s> {
        Element {
            name,
            span: Span::new(at - 1, at + 40),
            name_span: Span::new(at, at + name.len()),
            attributes: (attributes.iter())
                .map(|&(name, value)| Attribute {
                    name,
                    name_span: Span::default(),
                    value: Cow::Borrowed(value),
                    value_span: Span::default(),
                })
                .collect(),
            children: Vec::new(),
            text: Vec::new(),
        }
    }

    /// `is_of` is the heads' equality, for slices of one text and for equal
    /// texts elsewhere.
    #[test]
    fn a_head_is_of_an_element_exactly_when_it_equals_its_head() {
        let text = "sphere s1 sphere s2 box";
        let copy = String::from(text);
        let (a, b) = (text, copy.as_str());
        let heads = [
            Head {
                name: &a[..6],
                name_span: Span::new(1, 7),
                name_attribute: Some(&a[7..9]),
            },
            Head {
                name: &b[..6],
                name_span: Span::new(1, 7),
                name_attribute: Some(&b[17..19]),
            },
            Head {
                name: &a[10..16],
                name_span: Span::new(1, 7),
                name_attribute: None,
            },
            Head {
                name: &a[20..23],
                name_span: Span::new(1, 4),
                name_attribute: Some(""),
            },
            Head {
                name: &b[10..16],
                name_span: Span::new(2, 8),
                name_attribute: Some(&a[7..9]),
            },
        ];
        let elements = [
            element(&a[..6], 1, &[("name", &a[7..9])]),
            element(&b[10..16], 1, &[("r", "1"), ("name", &b[7..9])]),
            element(&a[..6], 1, &[("name", &a[17..19])]),
            element(&a[10..16], 1, &[]),
            element(&b[20..23], 1, &[("name", "")]),
            element(&a[..6], 2, &[("name", &b[7..9])]),
            element(&a[..5], 1, &[("name", &a[7..9])]),
        ];
        let mut same = 0;
        for head in &heads {
            for element in &elements {
                assert_eq!(
                    head.is_of(element),
                    *head == element.head(),
                    "{head:?} {element:?}"
                );
                same += usize::from(head.is_of(element));
            }
        }
        assert_eq!(same, 6);
    }
}
