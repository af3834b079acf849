//! The element tree: names, attributes and children with byte spans. Names
//! and attribute values borrow from the source text (a value is owned only
//! when the parser had to expand an entity or normalise whitespace in it), so
//! building the tree allocates little more than its vectors.

use crate::span::Span;
use std::borrow::Cow;

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
    pub attributes: Vec<Attribute<'s>>,
    pub children: Vec<Element<'s>>,
    /// Non-whitespace text directly inside the element, with its span.
    pub text: Vec<(String, Span)>,
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

/// Converts a parsed roxmltree node into the tree. Iterative, so depth
/// is bounded only by memory (the caller has already checked the depth limit).
pub(super) fn build<'s>(root: roxmltree::Node<'_, 's>) -> Element<'s> {
    // Post-order assembly: each frame keeps its child iterator and collects its
    // finished children.
    let mut stack = vec![(root.children(), shell(root))];
    loop {
        let Some((children, element)) = stack.last_mut() else {
            unreachable!("the stack holds the root until it is returned")
        };
        match children.next() {
            Some(child) if child.is_element() => stack.push((child.children(), shell(child))),
            Some(child) if child.is_text() => push_text(element, child),
            Some(_) => {}
            None => {
                let Some((_, finished)) = stack.pop() else {
                    unreachable!("the loop only pops a frame it has just seen")
                };
                match stack.last_mut() {
                    Some(parent) => parent.1.children.push(finished),
                    None => return finished,
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
pub(super) fn shallow<'s>(node: roxmltree::Node<'_, 's>) -> Element<'s> {
    let mut element = shell_with(node, 0);
    for child in node.children().filter(|c| c.is_text()) {
        push_text(&mut element, child);
    }
    element
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

fn push_text(element: &mut Element, node: roxmltree::Node) {
    let text = node.text().unwrap_or("");
    if !text.trim().is_empty() {
        element
            .text
            .push((text.trim().to_string(), Span::from_range(node.range())));
    }
}

fn shell<'s>(node: roxmltree::Node<'_, 's>) -> Element<'s> {
    // Sized exactly: no growth by doubling (the root of a large file has
    // hundreds of thousands of children).
    shell_with(node, node.children().filter(|c| c.is_element()).count())
}

fn shell_with<'s>(node: roxmltree::Node<'_, 's>, children: usize) -> Element<'s> {
    let range = node.range();
    let name = node.tag_name().name();
    let name_start = range.start + 1;
    Element {
        name_span: Span::new(name_start, name_start + name.len()),
        name,
        span: Span::from_range(range),
        attributes: node
            .attributes()
            // Namespaced attributes (xsi:noNamespaceSchemaLocation) belong to
            // the XML tooling, not to the format.
            .filter(|a| a.namespace().is_none())
            .map(|a| Attribute {
                name: a.name(),
                name_span: Span::from_range(a.range_qname()),
                value: match a.value_storage() {
                    roxmltree::StringStorage::Borrowed(text) => Cow::Borrowed(*text),
                    other => Cow::Owned(other.as_str().to_string()),
                },
                value_span: Span::from_range(a.range_value()),
            })
            .collect(),
        children: Vec::with_capacity(children),
        text: Vec::new(),
    }
}
