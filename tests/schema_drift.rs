//! `schema/geomc.xsd` and `src/doc/grammar.rs` describe the same format: this test
//! reads the XSD into the grammar's shape and compares the two element by element,
//! starting at `<geometry>` and recursing through every context, so neither can
//! change without the other.
//!
//! Compared for every element: its attributes (names, required flags, enumeration
//! values, and that non-enumerated attributes are plain `xs:string`), whether it
//! takes any attribute, its children (names, order in sequences, minimum and
//! maximum counts) and the particle kind (empty / all / sequence / choice with its
//! counts / choice between sequences). The test also requires documentation on
//! every element and attribute declaration and forbids mixed content, and that
//! docs/format.md's diagnostic table lists every code of src/diag/code.rs.

use std::collections::{BTreeSet, HashMap, HashSet};
use std::fmt;

use geomc::doc::grammar::{Attr, AttrKind, Child, Content, GEOMETRY, Rule};
use roxmltree::{Document, Node};

const XS: &str = "http://www.w3.org/2001/XMLSchema";

fn schema_text() -> String {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/schema/geomc.xsd");
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("cannot read {path}: {e}"))
}

// ---------------------------------------------------------------------------
// The XSD, read into the grammar's shape
// ---------------------------------------------------------------------------

/// Occurrence bounds; `None` as the maximum means unbounded.
#[derive(Clone, Copy, PartialEq, Eq)]
struct Occurs {
    min: u32,
    max: Option<u32>,
}

impl fmt::Display for Occurs {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.max {
            Some(max) => write!(f, "{}..{}", self.min, max),
            None => write!(f, "{}..unbounded", self.min),
        }
    }
}

/// An `xs:attribute` as the grammar sees it.
struct XAttr {
    name: String,
    required: bool,
    /// The enumeration values, when the type is an enumeration.
    enumeration: Option<Vec<String>>,
    /// The declared type when it is neither `xs:string` nor an enumeration.
    other_type: Option<String>,
}

/// An element declaration in one context: its node in the XSD and its counts.
#[derive(Clone, Copy)]
struct XChild<'a, 'i> {
    decl: Node<'a, 'i>,
    occurs: Occurs,
}

/// The particle of a complex type, in the grammar's terms.
enum XContent<'a, 'i> {
    Empty,
    All(Vec<XChild<'a, 'i>>),
    Sequence(Vec<XChild<'a, 'i>>),
    Choice {
        options: Vec<XChild<'a, 'i>>,
        occurs: Occurs,
    },
    Forms(Vec<Vec<XChild<'a, 'i>>>),
}

/// An element's complete shape as the XSD declares it.
struct XRule<'a, 'i> {
    attrs: Vec<XAttr>,
    any_attrs: bool,
    content: XContent<'a, 'i>,
}

struct Schema<'a, 'i> {
    complex_types: HashMap<&'a str, Node<'a, 'i>>,
    simple_types: HashMap<&'a str, Node<'a, 'i>>,
    groups: HashMap<&'a str, Node<'a, 'i>>,
    attribute_groups: HashMap<&'a str, Node<'a, 'i>>,
    elements: HashMap<&'a str, Node<'a, 'i>>,
}

fn is_xs(node: Node, local: &str) -> bool {
    node.is_element() && node.tag_name().namespace() == Some(XS) && node.tag_name().name() == local
}

/// The XSD children of `node`, without annotations.
fn particles<'a, 'i>(node: Node<'a, 'i>) -> impl Iterator<Item = Node<'a, 'i>> {
    node.children()
        .filter(|n| n.is_element() && !is_xs(*n, "annotation"))
}

fn occurs(node: Node) -> Result<Occurs, String> {
    let parse = |attr: &str| -> Result<Option<u32>, String> {
        match node.attribute(attr) {
            None => Ok(Some(1)),
            Some("unbounded") => Ok(None),
            Some(v) => v
                .parse()
                .map(Some)
                .map_err(|_| format!("bad {attr}=\"{v}\"")),
        }
    };
    let min = parse("minOccurs")?.ok_or("minOccurs=\"unbounded\"")?;
    Ok(Occurs {
        min,
        max: parse("maxOccurs")?,
    })
}

fn documented(node: Node) -> bool {
    node.children()
        .filter(|n| is_xs(*n, "annotation"))
        .flat_map(|a| a.children())
        .filter(|n| is_xs(*n, "documentation"))
        .any(|d| d.text().is_some_and(|t| !t.trim().is_empty()))
}

impl<'a, 'i> Schema<'a, 'i> {
    fn new(doc: &'a Document<'i>) -> Schema<'a, 'i> {
        let root = doc.root_element();
        assert!(is_xs(root, "schema"), "the XSD's root is not xs:schema");
        assert!(
            root.attribute("targetNamespace").is_none(),
            "the XSD must have no target namespace"
        );
        let mut schema = Schema {
            complex_types: HashMap::new(),
            simple_types: HashMap::new(),
            groups: HashMap::new(),
            attribute_groups: HashMap::new(),
            elements: HashMap::new(),
        };
        for node in particles(root) {
            let Some(name) = node.attribute("name") else {
                continue;
            };
            let map = match node.tag_name().name() {
                "complexType" => &mut schema.complex_types,
                "simpleType" => &mut schema.simple_types,
                "group" => &mut schema.groups,
                "attributeGroup" => &mut schema.attribute_groups,
                "element" => &mut schema.elements,
                other => panic!("unexpected top-level xs:{other} '{name}'"),
            };
            assert!(map.insert(name, node).is_none(), "'{name}' declared twice");
        }
        schema
    }

    /// The element declaration a `ref=` points to, or the declaration itself.
    fn resolve_element(&self, decl: Node<'a, 'i>) -> Result<Node<'a, 'i>, String> {
        match decl.attribute("ref") {
            Some(name) => self
                .elements
                .get(name)
                .copied()
                .ok_or_else(|| format!("xs:element ref=\"{name}\" names no global element")),
            None => Ok(decl),
        }
    }

    fn element_name(&self, decl: Node<'a, 'i>) -> String {
        self.resolve_element(decl)
            .ok()
            .and_then(|d| d.attribute("name"))
            .unwrap_or("?")
            .to_string()
    }

    /// The complex type of an element declaration, named or inline.
    fn element_type(&self, decl: Node<'a, 'i>) -> Result<Node<'a, 'i>, String> {
        let decl = self.resolve_element(decl)?;
        if decl.attribute("mixed").is_some() {
            return Err("mixed content is not allowed".into());
        }
        match decl.attribute("type") {
            Some(name) => self
                .complex_types
                .get(name)
                .copied()
                .ok_or_else(|| format!("type=\"{name}\" is not a complex type of the XSD")),
            None => decl
                .children()
                .find(|n| is_xs(*n, "complexType"))
                .ok_or_else(|| "the element has no complex type".to_string()),
        }
    }

    fn rule(&self, decl: Node<'a, 'i>) -> Result<XRule<'a, 'i>, String> {
        let ty = self.element_type(decl)?;
        if ty.attribute("mixed") == Some("true") {
            return Err(format!(
                "type {} has mixed content (text inside elements is invalid)",
                ty.attribute("name").unwrap_or("(inline)")
            ));
        }
        let mut rule = XRule {
            attrs: Vec::new(),
            any_attrs: false,
            content: XContent::Empty,
        };
        let mut have_particle = false;
        for node in particles(ty) {
            match node.tag_name().name() {
                "all" | "sequence" | "choice" | "group" => {
                    if have_particle {
                        return Err("two content particles in one type".into());
                    }
                    have_particle = true;
                    rule.content = self.content(node)?;
                }
                "attribute" | "attributeGroup" | "anyAttribute" => {
                    self.attributes(node, &mut rule)?;
                }
                other => return Err(format!("xs:{other} is not used by this schema's shape")),
            }
        }
        Ok(rule)
    }

    fn attributes(&self, node: Node<'a, 'i>, rule: &mut XRule<'a, 'i>) -> Result<(), String> {
        match node.tag_name().name() {
            "anyAttribute" => {
                if node.attribute("processContents") != Some("skip") {
                    return Err("xs:anyAttribute without processContents=\"skip\"".into());
                }
                rule.any_attrs = true;
            }
            "attributeGroup" => {
                let name = node
                    .attribute("ref")
                    .ok_or("xs:attributeGroup without ref")?;
                let group = self
                    .attribute_groups
                    .get(name)
                    .ok_or_else(|| format!("attribute group '{name}' is not declared"))?;
                for inner in particles(*group) {
                    self.attributes(inner, rule)?;
                }
            }
            _ => rule.attrs.push(self.attribute(node)?),
        }
        Ok(())
    }

    fn attribute(&self, node: Node<'a, 'i>) -> Result<XAttr, String> {
        let name = node.attribute("name").ok_or("xs:attribute without name")?;
        if !documented(node) {
            return Err(format!("attribute '{name}' has no xs:documentation"));
        }
        let required = match node.attribute("use") {
            None | Some("optional") => false,
            Some("required") => true,
            Some(other) => return Err(format!("attribute '{name}' has use=\"{other}\"")),
        };
        let mut attr = XAttr {
            name: name.to_string(),
            required,
            enumeration: None,
            other_type: None,
        };
        let simple = match node.attribute("type") {
            Some("xs:string") => None,
            Some(ty) => match self.simple_types.get(ty) {
                Some(simple) => Some(*simple),
                None => {
                    attr.other_type = Some(ty.to_string());
                    None
                }
            },
            None => node.children().find(|n| is_xs(*n, "simpleType")),
        };
        if let Some(simple) = simple {
            let restriction = simple
                .children()
                .find(|n| is_xs(*n, "restriction"))
                .ok_or_else(|| format!("attribute '{name}': simple type without xs:restriction"))?;
            let values: Vec<String> = restriction
                .children()
                .filter(|n| is_xs(*n, "enumeration"))
                .filter_map(|n| n.attribute("value"))
                .map(str::to_string)
                .collect();
            if values.is_empty() {
                attr.other_type = Some(format!(
                    "a restriction of {}",
                    restriction.attribute("base").unwrap_or("?")
                ));
            } else {
                attr.enumeration = Some(values);
            }
        }
        Ok(attr)
    }

    fn element_child(&self, node: Node<'a, 'i>) -> Result<XChild<'a, 'i>, String> {
        if !is_xs(node, "element") {
            return Err(format!(
                "xs:{} where an xs:element was expected",
                node.tag_name().name()
            ));
        }
        Ok(XChild {
            decl: node,
            occurs: occurs(node)?,
        })
    }

    fn element_children(&self, node: Node<'a, 'i>) -> Result<Vec<XChild<'a, 'i>>, String> {
        particles(node).map(|n| self.element_child(n)).collect()
    }

    fn content(&self, node: Node<'a, 'i>) -> Result<XContent<'a, 'i>, String> {
        let own = occurs(node)?;
        let local = node.tag_name().name();
        let one = Occurs {
            min: 1,
            max: Some(1),
        };
        match local {
            "all" | "sequence" => {
                if own != one {
                    return Err(format!("xs:{local} with occurrences {own}"));
                }
                let children = self.element_children(node)?;
                Ok(match (local, children.is_empty()) {
                    (_, true) => XContent::Empty,
                    ("all", false) => XContent::All(children),
                    _ => XContent::Sequence(children),
                })
            }
            "choice" => self.choice(node, own),
            "group" => {
                let name = node.attribute("ref").ok_or("xs:group without ref")?;
                let group = self
                    .groups
                    .get(name)
                    .ok_or_else(|| format!("group '{name}' is not declared"))?;
                let mut inner = particles(*group);
                let (Some(choice), None) = (inner.next(), inner.next()) else {
                    return Err(format!("group '{name}' must hold exactly one xs:choice"));
                };
                if !is_xs(choice, "choice") || occurs(choice)? != one {
                    return Err(format!("group '{name}' must hold one plain xs:choice"));
                }
                self.choice(choice, own)
            }
            other => Err(format!("xs:{other} as a content particle")),
        }
    }

    fn choice(&self, node: Node<'a, 'i>, own: Occurs) -> Result<XContent<'a, 'i>, String> {
        let items: Vec<Node> = particles(node).collect();
        if !items.is_empty() && items.iter().all(|n| is_xs(*n, "sequence")) {
            if own
                != (Occurs {
                    min: 1,
                    max: Some(1),
                })
            {
                return Err(format!("a choice between sequences with occurrences {own}"));
            }
            let forms = items
                .into_iter()
                .map(|seq| {
                    if occurs(seq)?
                        != (Occurs {
                            min: 1,
                            max: Some(1),
                        })
                    {
                        return Err("a form's xs:sequence with occurrences".to_string());
                    }
                    self.element_children(seq)
                })
                .collect::<Result<_, _>>()?;
            return Ok(XContent::Forms(forms));
        }
        let options = self.element_children(node)?;
        for option in &options {
            if option.occurs
                != (Occurs {
                    min: 1,
                    max: Some(1),
                })
            {
                return Err(format!(
                    "choice option '{}' has its own occurrences {} (put them on the xs:choice)",
                    self.element_name(option.decl),
                    option.occurs
                ));
            }
        }
        Ok(XContent::Choice {
            options,
            occurs: own,
        })
    }
}

// ---------------------------------------------------------------------------
// The comparison
// ---------------------------------------------------------------------------

fn content_kind(content: &Content) -> &'static str {
    match content {
        Content::Empty => "empty",
        Content::All(_) => "xs:all",
        Content::Sequence(_) => "xs:sequence",
        Content::Choice { .. } => "a repeated xs:choice",
        Content::Forms(_) => "an xs:choice between sequences",
    }
}

fn xcontent_kind(content: &XContent) -> &'static str {
    match content {
        XContent::Empty => "empty",
        XContent::All(_) => "xs:all",
        XContent::Sequence(_) => "xs:sequence",
        XContent::Choice { .. } => "a repeated xs:choice",
        XContent::Forms(_) => "an xs:choice between sequences",
    }
}

fn child_occurs(child: &Child) -> Occurs {
    Occurs {
        min: child.min,
        max: child.max,
    }
}

struct Comparison<'s, 'a, 'i> {
    schema: &'s Schema<'a, 'i>,
    /// (grammar rule, XSD declaration) pairs already compared: the boolean tree
    /// is recursive, and each pair needs comparing once.
    visited: HashSet<(usize, usize)>,
    errors: Vec<String>,
}

impl<'a, 'i> Comparison<'_, 'a, 'i> {
    fn error(&mut self, path: &str, message: impl fmt::Display) {
        self.errors.push(format!("{path}: {message}"));
    }

    fn element(&mut self, path: &str, rule: &'static Rule, decl: Node<'a, 'i>) {
        let key = (rule as *const Rule as usize, decl.id().get_usize());
        if !self.visited.insert(key) {
            return;
        }
        let name = self.schema.element_name(decl);
        if name != rule.name {
            self.error(
                path,
                format!("grammar.rs has <{}>, the XSD <{name}>", rule.name),
            );
            return;
        }
        let Ok(resolved) = self.schema.resolve_element(decl) else {
            self.error(path, "unresolved element reference");
            return;
        };
        if !documented(resolved) {
            self.error(path, "the XSD declaration has no xs:documentation");
        }
        let xrule = match self.schema.rule(decl) {
            Ok(x) => x,
            Err(e) => return self.error(path, e),
        };
        self.attributes(path, rule, &xrule);
        self.content(path, rule, &xrule.content);
    }

    fn attributes(&mut self, path: &str, rule: &Rule, xrule: &XRule) {
        if rule.any_attrs != xrule.any_attrs {
            let (g, x) = if rule.any_attrs {
                ("takes any attribute", "does not")
            } else {
                ("does not take any attribute", "does (xs:anyAttribute)")
            };
            self.error(
                path,
                format!("in grammar.rs the element {g}, in the XSD it {x}"),
            );
        }
        let mut seen = BTreeSet::new();
        for x in &xrule.attrs {
            if !seen.insert(x.name.as_str()) {
                self.error(
                    path,
                    format!("attribute '{}' is declared twice in the XSD", x.name),
                );
            }
            if rule.attr(&x.name).is_none() {
                self.error(
                    path,
                    format!("attribute '{}' is in the XSD but not in grammar.rs", x.name),
                );
            }
        }
        for attr in rule.attrs {
            match xrule.attrs.iter().find(|x| x.name == attr.name) {
                None => self.error(
                    path,
                    format!(
                        "attribute '{}' is in grammar.rs but not in the XSD",
                        attr.name
                    ),
                ),
                Some(x) => self.attribute(path, attr, x),
            }
        }
    }

    fn attribute(&mut self, path: &str, attr: &Attr, x: &XAttr) {
        let word = |required: bool| if required { "required" } else { "optional" };
        if attr.required != x.required {
            self.error(
                path,
                format!(
                    "attribute '{}' is {} in grammar.rs but {} in the XSD",
                    attr.name,
                    word(attr.required),
                    word(x.required)
                ),
            );
        }
        if let Some(other) = &x.other_type {
            self.error(
                path,
                format!(
                    "attribute '{}' has type {other} in the XSD; only xs:string and enumerations are used \
                     (expressions and names are checked by geomc)",
                    attr.name
                ),
            );
        }
        match (attr.kind, &x.enumeration) {
            (AttrKind::Enum(values), Some(xvalues)) => {
                let g: BTreeSet<&str> = values.iter().copied().collect();
                let s: BTreeSet<&str> = xvalues.iter().map(String::as_str).collect();
                if g != s || xvalues.len() != s.len() {
                    self.error(
                        path,
                        format!(
                            "attribute '{}' takes {g:?} in grammar.rs but {xvalues:?} in the XSD",
                            attr.name
                        ),
                    );
                }
            }
            (AttrKind::Enum(values), None) => self.error(
                path,
                format!(
                    "attribute '{}' is an enumeration {values:?} in grammar.rs but not in the XSD",
                    attr.name
                ),
            ),
            (kind, Some(xvalues)) => self.error(
                path,
                format!(
                    "attribute '{}' is {kind:?} in grammar.rs but an enumeration {xvalues:?} in the XSD",
                    attr.name
                ),
            ),
            (_, None) => {}
        }
    }

    fn content(&mut self, path: &str, rule: &'static Rule, x: &XContent<'a, 'i>) {
        match (&rule.content, x) {
            (Content::Empty, XContent::Empty) => {}
            (Content::All(children), XContent::All(xchildren)) => {
                self.children(path, children, xchildren, false);
            }
            (Content::Sequence(children), XContent::Sequence(xchildren)) => {
                self.children(path, children, xchildren, true);
            }
            (
                Content::Choice { options, min, max },
                XContent::Choice {
                    options: xoptions,
                    occurs,
                },
            ) => {
                let g = Occurs {
                    min: *min,
                    max: *max,
                };
                if g != *occurs {
                    self.error(
                        path,
                        format!(
                            "the choice occurs {g} times in grammar.rs but {occurs} in the XSD"
                        ),
                    );
                }
                let as_children: Vec<Child> = options
                    .iter()
                    .map(|rule| Child {
                        rule,
                        min: 1,
                        max: Some(1),
                    })
                    .collect();
                self.children(path, &as_children, xoptions, false);
            }
            (Content::Forms(forms), XContent::Forms(xforms)) => {
                if forms.len() != xforms.len() {
                    self.error(
                        path,
                        format!(
                            "grammar.rs has {} forms, the XSD {}",
                            forms.len(),
                            xforms.len()
                        ),
                    );
                }
                for (i, (form, xform)) in forms.iter().zip(xforms).enumerate() {
                    self.children(&format!("{path}[form {}]", i + 1), form, xform, true);
                }
            }
            (g, x) => self.error(
                path,
                format!(
                    "the content is {} in grammar.rs but {} in the XSD",
                    content_kind(g),
                    xcontent_kind(x)
                ),
            ),
        }
    }

    /// Compares two lists of children; `ordered` lists must agree in order too.
    /// Matching children are compared recursively.
    fn children(
        &mut self,
        path: &str,
        children: &[Child],
        xchildren: &[XChild<'a, 'i>],
        ordered: bool,
    ) {
        let base = path.split("[form").next().unwrap_or(path).to_string();
        let names: Vec<&str> = children.iter().map(|c| c.rule.name).collect();
        let xnames: Vec<String> = xchildren
            .iter()
            .map(|x| self.schema.element_name(x.decl))
            .collect();
        for (i, x) in xnames.iter().enumerate() {
            if xnames[..i].contains(x) {
                self.error(path, format!("child <{x}> is declared twice in the XSD"));
            }
            if !names.contains(&x.as_str()) {
                self.error(
                    &format!("{base}/{x}"),
                    "the element is in the XSD but not in grammar.rs",
                );
            }
        }
        for child in children {
            let child_path = format!("{base}/{}", child.rule.name);
            let Some(i) = xnames.iter().position(|x| x == child.rule.name) else {
                self.error(
                    &child_path,
                    "the element is in grammar.rs but not in the XSD",
                );
                continue;
            };
            let x = xchildren[i];
            let g = child_occurs(child);
            if g != x.occurs {
                self.error(
                    &child_path,
                    format!("occurs {g} times in grammar.rs but {} in the XSD", x.occurs),
                );
            }
            self.element(&child_path, child.rule, x.decl);
        }
        if ordered {
            let common: Vec<&str> = names
                .iter()
                .copied()
                .filter(|n| xnames.iter().any(|x| x == n))
                .collect();
            let xcommon: Vec<&str> = xnames
                .iter()
                .map(String::as_str)
                .filter(|x| names.contains(x))
                .collect();
            if common != xcommon {
                self.error(
                    path,
                    format!("the children are ordered {common:?} in grammar.rs but {xcommon:?} in the XSD"),
                );
            }
        }
    }
}

/// Every difference between `root` and the XSD text, one message each.
fn differences(root: &'static Rule, xsd: &str) -> Vec<String> {
    let doc = Document::parse(xsd).expect("the XSD is not well-formed XML");
    let schema = Schema::new(&doc);
    let mut comparison = Comparison {
        schema: &schema,
        visited: HashSet::new(),
        errors: Vec::new(),
    };
    match schema.elements.get(root.name) {
        None => comparison.error(root.name, "the XSD declares no global element of this name"),
        Some(decl) => {
            if schema.elements.len() != 1 {
                let mut names: Vec<&&str> = schema.elements.keys().collect();
                names.sort();
                comparison.error(
                    root.name,
                    format!("the XSD must declare only the root globally, it declares {names:?}"),
                );
            }
            comparison.element(root.name, root, *decl);
        }
    }
    // Every element declaration of the XSD must have been reached from the root.
    let reached: HashSet<usize> = comparison.visited.iter().map(|(_, decl)| *decl).collect();
    for node in doc.descendants().filter(|n| is_xs(*n, "element")) {
        if !reached.contains(&node.id().get_usize()) {
            let name = node.attribute("name").unwrap_or("?");
            comparison.error(
                root.name,
                format!("the XSD declares <{name}> where grammar.rs has no element (unreachable from the root)"),
            );
        }
    }
    comparison.errors
}

#[test]
fn xsd_matches_grammar() {
    let errors = differences(&GEOMETRY, &schema_text());
    assert!(
        errors.is_empty(),
        "schema/geomc.xsd and src/doc/grammar.rs differ:\n  {}",
        errors.join("\n  ")
    );
}

// ---------------------------------------------------------------------------
// The comparison catches drift: mutate either side and expect a message.
// ---------------------------------------------------------------------------

/// Applies one textual change to the XSD (which must occur exactly once) and
/// returns the differences found.
fn mutated_xsd(from: &str, to: &str) -> Vec<String> {
    let xsd = schema_text();
    assert_eq!(
        xsd.matches(from).count(),
        1,
        "mutation anchor {from:?} is not unique"
    );
    differences(&GEOMETRY, &xsd.replacen(from, to, 1))
}

fn assert_caught(errors: &[String], expected: &str) {
    assert!(
        errors.iter().any(|e| e.contains(expected)),
        "expected a difference containing {expected:?}, got {errors:#?}"
    );
}

#[test]
fn catches_xsd_mutations() {
    // A required attribute made optional.
    assert_caught(
        &mutated_xsd(
            r#"<xs:attribute name="equation" type="xs:string" use="required">"#,
            r#"<xs:attribute name="equation" type="xs:string" use="optional">"#,
        ),
        "geometry/surface/implicit: attribute 'equation' is required in grammar.rs but optional in the XSD",
    );
    // An attribute renamed.
    let errors = mutated_xsd(
        r#"<xs:attribute name="begin" "#,
        r#"<xs:attribute name="start" "#,
    );
    assert_caught(
        &errors,
        "geometry/edge: attribute 'begin' is in grammar.rs but not in the XSD",
    );
    assert_caught(
        &errors,
        "geometry/edge: attribute 'start' is in the XSD but not in grammar.rs",
    );
    // A count changed.
    assert_caught(
        &mutated_xsd(
            r#"<xs:element name="vertex" type="PointType" minOccurs="3" maxOccurs="3">
        <xs:annotation><xs:documentation>A corner"#,
            r#"<xs:element name="vertex" type="PointType" minOccurs="3" maxOccurs="4">
        <xs:annotation><xs:documentation>A corner"#,
        ),
        "geometry/triangle/vertex: occurs 3..3 times in grammar.rs but 3..4 in the XSD",
    );
    // An enumeration value added.
    assert_caught(
        &mutated_xsd(
            r#"<xs:enumeration value="1"/>"#,
            r#"<xs:enumeration value="1"/><xs:enumeration value="2"/>"#,
        ),
        "geometry: attribute 'version' takes",
    );
    // Deep in the recursive boolean tree: the solid's attribute.
    assert_caught(
        &mutated_xsd(
            r#"<xs:attribute name="ref" type="xs:string" use="required">
      <xs:annotation><xs:documentation>The name of a solid"#,
            r#"<xs:attribute name="ref" type="xs:string" use="optional">
      <xs:annotation><xs:documentation>The name of a solid"#,
        ),
        "geometry/subdomain/solid: attribute 'ref' is required",
    );
    // The boolean group's counts on a subdomain.
    assert_caught(
        &mutated_xsd(
            r#"<xs:group ref="SolidTree" minOccurs="0" maxOccurs="1"/>"#,
            r#"<xs:group ref="SolidTree" minOccurs="0" maxOccurs="2"/>"#,
        ),
        "geometry/subdomain: the choice occurs 0..1 times in grammar.rs but 0..2 in the XSD",
    );
    // An expression type with a pattern instead of xs:string.
    assert_caught(
        &mutated_xsd(
            r#"<xs:attribute name="count" type="xs:string" use="required">"#,
            r#"<xs:attribute name="count" type="xs:integer" use="required">"#,
        ),
        "geometry/replicate: attribute 'count' has type xs:integer",
    );
    // The any-attribute wildcard dropped.
    assert_caught(
        &mutated_xsd(r#"<xs:anyAttribute processContents="skip"/>"#, ""),
        "geometry/basis_coordinate/coordinate/value: in grammar.rs the element takes any attribute",
    );
}

#[test]
fn catches_order_and_kind_changes() {
    // Ellipse children swapped: center must come first.
    let xsd = schema_text();
    let center = r#"<xs:element name="center" type="PointType">
        <xs:annotation><xs:documentation>The ellipse's centre.</xs:documentation></xs:annotation>
      </xs:element>
"#;
    assert_eq!(
        xsd.matches(center).count(),
        2,
        "anchor for the ellipse's centre"
    );
    let start = xsd.find(center).unwrap();
    let radius_end = xsd[start..].find("</xs:sequence>").unwrap() + start;
    let radius = &xsd[start + center.len()..radius_end];
    let swapped = format!(
        "{}{radius}      {}{}",
        &xsd[..start],
        center.trim_start(),
        &xsd[radius_end..]
    );
    assert_caught(
        &differences(&GEOMETRY, &swapped),
        "geometry/ellipse: the children are ordered [\"center\", \"radius_vertex\"] in grammar.rs but [\"radius_vertex\", \"center\"] in the XSD",
    );
    // A circle's xs:all turned into an xs:sequence.
    let circle = r#"<xs:complexType name="CircleType">
    <xs:all>"#;
    let at = xsd.find(circle).unwrap();
    let close = xsd[at..].find("</xs:all>").unwrap() + at;
    let mut changed = xsd.clone();
    changed.replace_range(close..close + "</xs:all>".len(), "</xs:sequence>");
    changed.replace_range(
        at..at + circle.len(),
        &circle.replace("xs:all", "xs:sequence"),
    );
    assert_caught(
        &differences(&GEOMETRY, &changed),
        "geometry/circle: the content is xs:all in grammar.rs but xs:sequence in the XSD",
    );
}

/// Leaks a copy of `rule` with another content or attributes: the grammar's
/// rules are statics, so a mutated grammar is built from leaked copies.
fn leak(rule: Rule) -> &'static Rule {
    Box::leak(Box::new(rule))
}

/// The root with one top-level option replaced.
fn root_with(replace: &str, by: &'static Rule) -> &'static Rule {
    let Content::Choice { options, min, max } = GEOMETRY.content else {
        panic!("the root's content is a choice");
    };
    let options: Vec<&'static Rule> = options
        .iter()
        .map(|r| if r.name == replace { by } else { *r })
        .collect();
    leak(Rule {
        name: GEOMETRY.name,
        attrs: GEOMETRY.attrs,
        any_attrs: GEOMETRY.any_attrs,
        content: Content::Choice {
            options: Box::leak(options.into_boxed_slice()),
            min,
            max,
        },
    })
}

#[test]
fn catches_grammar_mutations() {
    let xsd = schema_text();
    let sphere = GEOMETRY.child_rule("sphere").unwrap();
    let center = sphere.child_rule("center").unwrap();

    // An attribute added to a nested element.
    let mut attrs = center.attrs.to_vec();
    attrs.push(Attr {
        name: "w",
        required: false,
        kind: AttrKind::Expr,
    });
    let new_center = leak(Rule {
        name: "center",
        attrs: Box::leak(attrs.into_boxed_slice()),
        any_attrs: false,
        content: Content::Empty,
    });
    let Content::All(children) = sphere.content else {
        panic!("a sphere's content is xs:all");
    };
    let children: Vec<Child> = children
        .iter()
        .map(|c| {
            if c.rule.name == "center" {
                Child {
                    rule: new_center,
                    ..*c
                }
            } else {
                *c
            }
        })
        .collect();
    let new_sphere = leak(Rule {
        name: "sphere",
        attrs: sphere.attrs,
        any_attrs: false,
        content: Content::All(Box::leak(children.clone().into_boxed_slice())),
    });
    assert_caught(
        &differences(root_with("sphere", new_sphere), &xsd),
        "geometry/sphere/center: attribute 'w' is in grammar.rs but not in the XSD",
    );

    // A child removed.
    let without_radius: Vec<Child> = children
        .into_iter()
        .filter(|c| c.rule.name != "radius")
        .collect();
    let new_sphere = leak(Rule {
        name: "sphere",
        attrs: sphere.attrs,
        any_attrs: false,
        content: Content::All(Box::leak(without_radius.into_boxed_slice())),
    });
    assert_caught(
        &differences(root_with("sphere", new_sphere), &xsd),
        "geometry/sphere/radius: the element is in the XSD but not in grammar.rs",
    );

    // A required flag flipped on the root.
    let mut root_attrs = GEOMETRY.attrs.to_vec();
    root_attrs[0].required = false;
    let root = leak(Rule {
        name: "geometry",
        attrs: Box::leak(root_attrs.into_boxed_slice()),
        any_attrs: false,
        content: GEOMETRY.content,
    });
    assert_caught(
        &differences(root, &xsd),
        "geometry: attribute 'version' is optional in grammar.rs but required in the XSD",
    );
}

// ---------------------------------------------------------------------------
// docs/format.md's code table is generated from src/diag/code.rs: keep it so.
// ---------------------------------------------------------------------------

#[test]
fn format_md_lists_every_code() {
    use geomc::diag::{Code, Severity};
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/docs/format.md");
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("cannot read {path}: {e}"));
    let rows: Vec<&str> = text
        .lines()
        .filter(|l| l.starts_with("| E") || l.starts_with("| W"))
        .filter(|l| l.split('|').nth(1).is_some_and(|c| c.trim().len() == 4))
        .collect();
    let mut missing = Vec::new();
    for code in Code::ALL {
        let severity = match code.severity() {
            Severity::Error => "error",
            Severity::Warning => "warning",
        };
        let row = format!("| {} | {severity} | {} |", code.as_str(), code.title());
        if !rows.contains(&row.as_str()) {
            missing.push(row);
        }
    }
    assert!(
        missing.is_empty(),
        "docs/format.md's diagnostic table lacks these rows (regenerate it from src/diag/code.rs):\n{}",
        missing.join("\n")
    );
    let table_rows = rows
        .iter()
        .filter(|r| r.contains("| error |") || r.contains("| warning |"));
    assert_eq!(
        table_rows.count(),
        Code::ALL.len(),
        "docs/format.md's diagnostic table has rows for codes that src/diag/code.rs lacks"
    );
}
