//! The structural check: walks the element tree against the [grammar](super::grammar)
//! and reports unknown, missing, duplicate and out-of-order elements and attributes,
//! text where none belongs, and enumeration values outside their set.

use super::grammar::{AttrKind, Child, Content, Rule, same_name};
use crate::diag::{Code, Diagnostic, Diagnostics, did_you_mean};
use crate::syntax::{Element, Head};

/// Checks `root` (and everything below it) against `rule`.
pub fn check(root: &Element, rule: &'static Rule, diags: &mut Diagnostics) {
    check_reusing(root, rule, diags, &mut Scratch::default());
}

/// The lists a [`check_reusing`] works in, kept from one call to the next:
/// a check of a large file's elements used to allocate a few per element.
#[derive(Default)]
pub struct Scratch<'e, 's> {
    pending: Vec<(&'e Element<'s>, &'static Rule)>,
    heads: Vec<Head<'e>>,
    known: Vec<Head<'e>>,
    known_rules: Vec<(usize, &'static Rule)>,
}

/// [`check`] in the lists of `scratch`.
pub fn check_reusing<'e, 's>(
    root: &'e Element<'s>,
    rule: &'static Rule,
    diags: &mut Diagnostics,
    scratch: &mut Scratch<'e, 's>,
) {
    let Scratch {
        pending,
        heads,
        known,
        known_rules,
    } = scratch;
    pending.clear();
    pending.push((root, rule));
    while let Some((element, rule)) = pending.pop() {
        heads.clear();
        heads.extend(element.children.iter().map(head));
        check_heads_into(element, heads, rule, diags, known, known_rules);
        for &(i, child_rule) in known_rules.iter().rev() {
            if let Some(child) = element.children.get(i) {
                pending.push((child, child_rule));
            }
        }
    }
}

/// Checks `element` itself against `rule` with its children given as
/// [`Head`]s (the driver checks a large file's root this way, then each child
/// as it is built): its attributes, its text, and the names, counts and order
/// of the children, but nothing inside them. Returns the indices of the
/// children whose rules are known, with their rules.
pub fn check_element_heads(
    element: &Element,
    children: &[Head],
    rule: &'static Rule,
    diags: &mut Diagnostics,
) -> Vec<(usize, &'static Rule)> {
    let mut known_rules = Vec::with_capacity(children.len());
    let mut known = Vec::with_capacity(children.len());
    check_heads_into(element, children, rule, diags, &mut known, &mut known_rules);
    known_rules
}

/// Checks `element` itself against `rule`: its attributes, its text, and the
/// names, counts and order of its `children`, but nothing inside them.
/// Leaves in `known_rules` the indices of the children whose rules are known,
/// with their rules (`known`: their heads, a scratch list).
fn check_heads_into<'h>(
    element: &Element,
    children: &[Head<'h>],
    rule: &'static Rule,
    diags: &mut Diagnostics,
    known: &mut Vec<Head<'h>>,
    known_rules: &mut Vec<(usize, &'static Rule)>,
) {
    check_attributes(element, rule, diags);
    for (text, span) in &element.text {
        diags.push(
            Diagnostic::new(
                Code::UnexpectedText,
                *span,
                format!(
                    "unexpected text '{}' inside <{}>",
                    abbreviate(text),
                    element.name
                ),
            )
            .with_help("put data in attributes; use an XML comment <!-- … --> for notes"),
        );
    }
    check_children(element, children, rule, diags, known, known_rules);
}

/// A child's [`Head`] for [`check_heads_into`], which reads only its name
/// and name span: its `name=` is not looked up.
fn head<'e>(element: &'e Element) -> Head<'e> {
    Head {
        name: element.name,
        name_span: element.name_span,
        name_attribute: None,
    }
}

fn abbreviate(text: &str) -> String {
    let mut out: String = text.chars().take(40).collect();
    if text.chars().count() > 40 {
        out.push('…');
    }
    out
}

fn check_attributes(element: &Element, rule: &Rule, diags: &mut Diagnostics) {
    // The rule's attributes found (bit k: `rule.attrs[k]`), so a required
    // one found needs no second search of the element's attributes.
    let mut seen: u64 = 0;
    for attr in &element.attributes {
        let found = rule
            .attrs
            .iter()
            .enumerate()
            .find(|(_, a)| same_name(a.name, attr.name));
        match found {
            Some((k, spec)) => {
                seen |= 1u64.checked_shl(k as u32).unwrap_or(0);
                if let AttrKind::Enum(values) = spec.kind
                    && !values.contains(&attr.value.trim())
                {
                    let listed = values
                        .iter()
                        .map(|v| format!("\"{v}\""))
                        .collect::<Vec<_>>()
                        .join(", ");
                    diags.push(
                        Diagnostic::new(
                            Code::InvalidValue,
                            attr.value_span,
                            format!(
                                "{}=\"{}\" on <{}> is not one of {listed}",
                                attr.name, attr.value, element.name
                            ),
                        )
                        .with_help(format!("use one of {listed}")),
                    );
                }
                if spec.kind == AttrKind::Name && attr.value.trim().is_empty() {
                    diags.push(
                        Diagnostic::new(
                            Code::InvalidValue,
                            attr.value_span,
                            format!("<{}> has an empty name", element.name),
                        )
                        .with_help("give the object a name of letters, digits, '_' and '-'"),
                    );
                }
            }
            None if rule.any_attrs => {}
            None => {
                let names = rule.attrs.iter().map(|a| a.name);
                let mut d = Diagnostic::new(
                    Code::UnknownAttribute,
                    attr.name_span,
                    format!("unknown attribute '{}' on <{}>", attr.name, element.name),
                );
                d.help = Some(match did_you_mean(attr.name, names) {
                    Some(best) => format!("did you mean '{best}'?"),
                    None if rule.attrs.is_empty() => {
                        format!("<{}> takes no attributes", element.name)
                    }
                    None => format!(
                        "<{}> takes {}",
                        element.name,
                        rule.attrs
                            .iter()
                            .map(|a| a.name)
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                });
                diags.push(d);
            }
        }
    }
    for (k, spec) in rule.attrs.iter().enumerate().filter(|(_, a)| a.required) {
        let marked = seen & 1u64.checked_shl(k as u32).unwrap_or(0) != 0;
        // Not marked: absent, or past the 64 marks, or a repeated name.
        if !marked
            && !element
                .attributes
                .iter()
                .any(|a| same_name(a.name, spec.name))
        {
            diags.push(
                Diagnostic::new(
                    Code::MissingAttribute,
                    element.name_span,
                    format!("<{}> needs the attribute '{}'", element.name, spec.name),
                )
                .with_help(format!("add {}=\"…\"", spec.name)),
            );
        }
    }
}

/// Reports problems with the children and leaves in `known_rules` the
/// indices of the ones whose rules are known, with their rules.
fn check_children<'h>(
    element: &Element,
    children: &[Head<'h>],
    rule: &'static Rule,
    diags: &mut Diagnostics,
    known: &mut Vec<Head<'h>>,
    known_rules: &mut Vec<(usize, &'static Rule)>,
) {
    known_rules.clear();
    known.clear();
    for (i, child) in children.iter().enumerate() {
        if let Some(child_rule) = rule.child_rule(child.name) {
            known_rules.push((i, child_rule));
            // The same name, but the grammar's string: the counts and order
            // below compare it with the rules' names, mostly the same string.
            known.push(Head {
                name: child_rule.name,
                ..*child
            });
        } else {
            let allowed = rule.child_rules();
            let mut d = Diagnostic::new(
                Code::UnknownElement,
                child.name_span,
                format!("unknown element <{}> inside <{}>", child.name, element.name),
            );
            d.help = Some(
                match did_you_mean(child.name, allowed.iter().map(|r| r.name)) {
                    Some(best) => format!("did you mean <{best}>?"),
                    None if allowed.is_empty() => {
                        format!("<{}> has no child elements", element.name)
                    }
                    None => format!(
                        "<{}> may contain {}",
                        element.name,
                        allowed
                            .iter()
                            .map(|r| format!("<{}>", r.name))
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                },
            );
            diags.push(d);
        }
    }
    match rule.content {
        Content::Empty => {}
        Content::All(children) => {
            for spec in children {
                check_count(element, known, spec, diags);
            }
        }
        Content::Sequence(children) => {
            for spec in children {
                check_count(element, known, spec, diags);
            }
            check_order(element, known, children, diags);
        }
        Content::Choice { min, max, .. } => {
            let n = known.len() as u32;
            if n < min {
                let options = rule
                    .child_rules()
                    .iter()
                    .map(|r| format!("<{}>", r.name))
                    .collect::<Vec<_>>()
                    .join(", ");
                diags.push(
                    Diagnostic::new(
                        Code::MissingElement,
                        element.name_span,
                        format!(
                            "<{}> needs at least {min} child element{} ({options}), found {n}",
                            element.name,
                            plural(min)
                        ),
                    )
                    .with_help(format!("add {} of {options}", min - n)),
                );
            }
            if let Some(max) = max
                && n > max
                && let Some(extra) = known.get(max as usize)
            {
                diags.push(
                    Diagnostic::new(
                        Code::DuplicateElement,
                        extra.name_span,
                        format!(
                            "<{}> may hold at most {max} child element{}, found {n}",
                            element.name,
                            plural(max)
                        ),
                    )
                    .with_help("remove the extra elements, or combine them with <union>"),
                );
            }
        }
        Content::Forms(forms) => check_forms(element, known, forms, diags),
    }
}

fn plural(n: u32) -> &'static str {
    if n == 1 { "" } else { "s" }
}

fn check_count(element: &Element, known: &[Head], spec: &Child, diags: &mut Diagnostics) {
    let found = known.iter().filter(|c| same_name(c.name, spec.rule.name));
    // The element past the most allowed, then how many there are in all.
    let extra = spec.max.and_then(|max| found.clone().nth(max as usize));
    let n = found.count() as u32;
    if n < spec.min {
        let need = if spec.min == 1 {
            "a".to_string()
        } else {
            spec.min.to_string()
        };
        diags.push(
            Diagnostic::new(
                Code::MissingElement,
                element.name_span,
                format!(
                    "<{}> needs {need} <{}> element{}, found {n}",
                    element.name,
                    spec.rule.name,
                    plural(spec.min)
                ),
            )
            .with_help(format!(
                "add <{} …/> inside <{}>",
                spec.rule.name, element.name
            )),
        );
    }
    if let (Some(max), Some(extra)) = (spec.max, extra) {
        diags.push(
            Diagnostic::new(
                Code::DuplicateElement,
                extra.name_span,
                format!(
                    "<{}> may have {} <{}> element{}, found {n}",
                    element.name,
                    if max == 1 {
                        "only one".to_string()
                    } else {
                        format!("at most {max}")
                    },
                    spec.rule.name,
                    plural(max)
                ),
            )
            .with_help(format!("remove the extra <{}>", spec.rule.name)),
        );
    }
}

/// In a sequence, each child must come no earlier than the children before it.
fn check_order(element: &Element, known: &[Head], children: &[Child], diags: &mut Diagnostics) {
    let position = |name: &str| children.iter().position(|c| same_name(c.rule.name, name));
    let mut latest: Option<(usize, &Head)> = None;
    for child in known {
        let Some(p) = position(child.name) else {
            continue;
        };
        if let Some((q, previous)) = latest
            && p < q
        {
            diags.push(
                Diagnostic::new(
                    Code::OutOfOrder,
                    child.name_span,
                    format!(
                        "<{}> must come before <{}> inside <{}>",
                        child.name, previous.name, element.name
                    ),
                )
                .with_help(format!(
                    "order the children of <{}> as {}",
                    element.name,
                    children
                        .iter()
                        .map(|c| format!("<{}>", c.rule.name))
                        .collect::<Vec<_>>()
                        .join(", ")
                )),
            );
            continue;
        }
        latest = Some((p, child));
    }
}

fn check_forms(element: &Element, known: &[Head], forms: &[&[Child]], diags: &mut Diagnostics) {
    let in_form = |form: &[Child], name: &str| form.iter().any(|c| same_name(c.rule.name, name));
    let describe = |form: &[Child]| {
        form.iter()
            .map(|c| format!("<{}>", c.rule.name))
            .collect::<Vec<_>>()
            .join(" + ")
    };
    // The form is chosen by the first child; a child of another form conflicts.
    let Some(first) = known.first() else {
        let options = forms
            .iter()
            .map(|f| describe(f))
            .collect::<Vec<_>>()
            .join(", or ");
        diags.push(
            Diagnostic::new(
                Code::MissingElement,
                element.name_span,
                format!("<{}> is empty; it needs {options}", element.name),
            )
            .with_help(format!("give <{}> one of its forms", element.name)),
        );
        return;
    };
    let Some(form) = forms.iter().find(|f| in_form(f, first.name)) else {
        return;
    };
    let mut conflict = false;
    for child in known.iter().filter(|c| !in_form(form, c.name)) {
        conflict = true;
        diags.push(
            Diagnostic::new(
                Code::ConflictingForms,
                child.name_span,
                format!(
                    "<{}> cannot be combined with <{}> in <{}>",
                    child.name, first.name, element.name
                ),
            )
            .with_help(format!(
                "give <{}> as {} only",
                element.name,
                describe(form)
            )),
        );
    }
    if !conflict {
        for spec in form.iter() {
            check_count(element, known, spec, diags);
        }
        check_order(element, known, form, diags);
    }
}
