//! The owned element tree: names, attributes and children with byte spans.

use crate::span::Span;

#[derive(Debug, Clone, PartialEq)]
pub struct Attribute {
    pub name: String,
    pub name_span: Span,
    pub value: String,
    pub value_span: Span,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Element {
    pub name: String,
    /// The whole element, from `<` to the end of its closing tag.
    pub span: Span,
    /// The element's name in its start tag.
    pub name_span: Span,
    pub attributes: Vec<Attribute>,
    pub children: Vec<Element>,
    /// Non-whitespace text directly inside the element, with its span.
    pub text: Vec<(String, Span)>,
}

impl Element {
    pub fn attribute(&self, name: &str) -> Option<&Attribute> {
        self.attributes.iter().find(|a| a.name == name)
    }

    pub fn children_named<'a>(&'a self, name: &'a str) -> impl Iterator<Item = &'a Element> + 'a {
        self.children.iter().filter(move |c| c.name == name)
    }
}

/// Converts a parsed roxmltree node into the owned tree. Iterative, so depth
/// is bounded only by memory (the caller has already checked the depth limit).
pub(super) fn build(root: roxmltree::Node) -> Element {
    // Post-order assembly: each frame keeps its child iterator and collects its
    // finished children.
    let mut stack = vec![(root.children(), shell(root))];
    loop {
        let Some((children, element)) = stack.last_mut() else {
            unreachable!("the stack holds the root until it is returned")
        };
        match children.next() {
            Some(child) if child.is_element() => stack.push((child.children(), shell(child))),
            Some(child) if child.is_text() => {
                let text = child.text().unwrap_or("");
                if !text.trim().is_empty() {
                    element
                        .text
                        .push((text.trim().to_string(), Span::from_range(child.range())));
                }
            }
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

fn shell(node: roxmltree::Node) -> Element {
    let range = node.range();
    let name = node.tag_name().name().to_string();
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
                name: a.name().to_string(),
                name_span: Span::from_range(a.range_qname()),
                value: a.value().to_string(),
                value_span: Span::from_range(a.range_value()),
            })
            .collect(),
        children: Vec::new(),
        text: Vec::new(),
    }
}
