//! The name table: the first definition of each name with its kind, the
//! first object of each name, and the findings on repeated and non-plain
//! names.

use super::NameTable;
use crate::diag::{Code, Diagnostics};
use crate::doc::Document;
use crate::span::SourceFile;
use crate::syntax::{self, Limits};

fn document(xml: &str) -> (SourceFile, Document) {
    let source = SourceFile::new("names.xml".to_string(), xml.to_string());
    let root = syntax::parse(&source, &Limits::default()).expect("parses");
    let mut read = Diagnostics::default();
    let doc = crate::doc::build(&source, &root, &mut read);
    (source, doc)
}

fn sphere(name: &str) -> String {
    format!(
        "<sphere name=\"{name}\"><center x=\"0\" y=\"0\" z=\"0\"/><radius value=\"1\"/></sphere>\n"
    )
}

#[test]
fn the_first_definition_gives_the_kind_and_the_first_object_the_object() {
    let xml = format!(
        "<geometry version=\"1\">\n<parameters><parameter name=\"a\" value=\"1\"/></parameters>\n{}{}{}<subdomain name=\"b\"><solid ref=\"b\"/></subdomain>\n{}</geometry>\n",
        sphere("a"),
        sphere("b"),
        sphere("a"),
        sphere("c d"),
    );
    let (source, doc) = document(&xml);
    let mut diags = Diagnostics::default();
    let names = NameTable::build(&source, &doc, &mut diags);
    assert_eq!(names.kind_of("a"), Some("parameter"));
    assert_eq!(names.first_object("a"), Some(0));
    assert_eq!(names.kind_of("b"), Some("sphere"));
    assert_eq!(names.first_object("b"), Some(1));
    assert_eq!(names.kind_of("c d"), Some("sphere"));
    assert_eq!(names.first_object("c d"), Some(3));
    assert_eq!(names.kind_of("c"), None);
    assert_eq!(names.first_object("zz"), None);
    assert_eq!(names.first_object(""), None);
    let found: Vec<(Code, u32, &str)> = (diags.items.iter())
        .map(|d| (d.code, d.span.map_or(0, |s| s.start), d.message.as_str()))
        .collect();
    let object = |i: usize| doc.objects[i].name.span.start;
    assert_eq!(
        found,
        [
            (
                Code::DuplicateName,
                object(0),
                "the name 'a' is already used by the parameter on line 2"
            ),
            (
                Code::DuplicateName,
                object(2),
                "the name 'a' is already used by the parameter on line 2"
            ),
            (
                Code::DuplicateName,
                doc.subdomains[0].name.span.start,
                "the name 'b' is already used by the sphere on line 4"
            ),
            (
                Code::NameNotIdentifier,
                object(3),
                "the name 'c d' contains characters that separate names in lists and expressions"
            ),
        ]
    );
}

#[test]
fn many_names_find_what_a_scan_of_the_document_finds() {
    // 3,000 objects; every third is named after a smaller index (mostly an
    // earlier object's or a parameter's name: 887 repeated names in all),
    // and the subdomains add names of their own.
    let mut xml = String::from("<geometry version=\"1\">\n<parameters>");
    for k in 0..40 {
        xml += &format!("<parameter name=\"n{}\" value=\"1\"/>", k * 50);
    }
    xml += "</parameters>\n";
    for i in 0..3_000 {
        let name = if i % 3 == 2 {
            format!("n{}", i / 7)
        } else {
            format!("n{i}")
        };
        xml += &sphere(&name);
        if i % 11 == 0 {
            xml += &format!("<subdomain name=\"s{i}\"><solid ref=\"n{i}\"/></subdomain>\n");
        }
    }
    xml += "</geometry>\n";
    let (source, doc) = document(&xml);
    let mut diags = Diagnostics::default();
    let names = NameTable::build(&source, &doc, &mut diags);
    let mut expected_duplicates = 0;
    let mut seen = std::collections::HashSet::new();
    for p in &doc.parameters {
        seen.insert(p.name.text.as_str());
    }
    for o in &doc.objects {
        if !seen.insert(o.name.text.as_str()) {
            expected_duplicates += 1;
        }
    }
    let probes = (doc.objects.iter().map(|o| o.name.text.clone()))
        .chain(["n3000", "m1", "s0", "s11", "s1", ""].map(String::from));
    for name in probes {
        let first = doc.objects.iter().position(|o| o.name.text == name);
        assert_eq!(names.first_object(&name), first, "{name}");
        let parameter = doc.parameters.iter().any(|p| p.name.text == name);
        let subdomain = doc.subdomains.iter().any(|s| s.name.text == name);
        let kind = match (parameter, first, subdomain) {
            (true, _, _) => Some("parameter"),
            (false, Some(_), _) => Some("sphere"),
            (false, None, true) => Some("subdomain"),
            _ => None,
        };
        assert_eq!(names.kind_of(&name), kind, "{name}");
    }
    assert_eq!(expected_duplicates, 887);
    let duplicates = (diags.items.iter())
        .filter(|d| d.code == Code::DuplicateName)
        .count();
    assert_eq!(duplicates, expected_duplicates);
}

#[test]
fn a_definition_of_a_later_list_that_comes_first_is_the_first() {
    // The table numbers the lists in a fixed order (parameters before
    // objects before subdomains), but the first definition of a name is the
    // first by position, and the findings come in the order of position.
    let xml = format!(
        "<geometry version=\"1\">\n{}{}{}{}{}{}{}</geometry>\n",
        "<subdomain name=\"x\"><solid ref=\"x\"/></subdomain>\n",
        "<subdomain name=\"a b\"><solid ref=\"x\"/></subdomain>\n",
        sphere("x"),
        sphere("a b"),
        "<parameters><parameter name=\"x\" value=\"1\"/><parameter name=\"q\" value=\"2\"/></parameters>\n",
        sphere("q"),
        sphere("x"),
    );
    let (source, doc) = document(&xml);
    let mut diags = Diagnostics::default();
    let names = NameTable::build(&source, &doc, &mut diags);
    assert_eq!(names.kind_of("x"), Some("subdomain"));
    assert_eq!(names.first_object("x"), Some(0));
    assert_eq!(names.kind_of("a b"), Some("subdomain"));
    assert_eq!(names.first_object("a b"), Some(1));
    assert_eq!(names.kind_of("q"), Some("parameter"));
    assert_eq!(names.first_object("q"), Some(2));
    let found: Vec<(Code, u32, &str)> = (diags.items.iter())
        .map(|d| (d.code, d.span.map_or(0, |s| s.start), d.message.as_str()))
        .collect();
    let object = |i: usize| doc.objects[i].name.span.start;
    let repeated = |name: &str, kind: &str, line: u32| {
        format!("the name '{name}' is already used by the {kind} on line {line}")
    };
    let expected = [
        (
            Code::NameNotIdentifier,
            doc.subdomains[1].name.span.start,
            "the name 'a b' contains characters that separate names in lists and expressions"
                .to_string(),
        ),
        (
            Code::DuplicateName,
            object(0),
            repeated("x", "subdomain", 2),
        ),
        (
            Code::DuplicateName,
            object(1),
            repeated("a b", "subdomain", 3),
        ),
        (
            Code::DuplicateName,
            doc.parameters[0].name.span.start,
            repeated("x", "subdomain", 2),
        ),
        (
            Code::DuplicateName,
            object(2),
            repeated("q", "parameter", 6),
        ),
        (
            Code::DuplicateName,
            object(3),
            repeated("x", "subdomain", 2),
        ),
    ];
    let expected: Vec<(Code, u32, &str)> = (expected.iter())
        .map(|(code, at, message)| (*code, *at, message.as_str()))
        .collect();
    assert_eq!(found, expected);
}
