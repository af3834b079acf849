//! The subdomains' lookups, classification and checks run on the workers:
//! pinned here against one thread (every task in order) on files of more
//! definitions than a task holds, with every kind of subdomain and finding.

use crate::diag::Code;
use crate::driver::{Checked, Options, check_source};
use crate::ir::SubdomainCells;
use crate::span::SourceFile;
use crate::test_threads::on_threads;
use std::fmt::Write as _;

/// `groups` copies of six kinds of subdomain definitions, on a grid 10 apart
/// in x and z (a small model: the overlap check's probes step 1000 welding
/// tolerances, a millionth of the model's diagonal, into a subdomain); with
/// `crossing`, every third group adds a union of two crossing balls.
fn definitions(groups: usize, crossing: bool) -> String {
    let mut xml = String::from("<geometry version=\"1\">\n");
    for i in 0..groups {
        let (x, z) = (10 * (i % 20), 10 * (i / 20));
        let (z1, z2, z4) = (z + 1, z + 2, z + 4);
        let w = |xml: &mut String, s: String| xml.push_str(&s);
        // A ball in a box: the box minus the ball, and the ball.
        w(
            &mut xml,
            format!(
                "<parallelepiped name=\"b{i}\"><first_point x=\"{x}\" y=\"0\" z=\"{z}\"/><second_point x=\"{}\" y=\"4\" z=\"{z4}\"/></parallelepiped>\n",
                x + 4
            ),
        );
        w(
            &mut xml,
            format!(
                "<sphere name=\"s{i}\"><center x=\"{}\" y=\"2\" z=\"{z2}\"/><radius value=\"1\"/></sphere>\n",
                x + 2
            ),
        );
        w(
            &mut xml,
            format!(
                "<subdomain name=\"m{i}\"><difference><solid ref=\"b{i}\"/><solid ref=\"s{i}\"/></difference></subdomain>\n"
            ),
        );
        w(
            &mut xml,
            format!("<subdomain name=\"c{i}\"><solid ref=\"s{i}\"/></subdomain>\n"),
        );
        // An undefined solid, with a near name to suggest.
        w(
            &mut xml,
            format!("<subdomain name=\"u{i}\"><solid ref=\"s{i}x\"/></subdomain>\n"),
        );
        // Nested balls, each its own subdomain: they overlap.
        w(
            &mut xml,
            format!(
                "<sphere name=\"o{i}\"><center x=\"{}\" y=\"10\" z=\"{z}\"/><radius value=\"2\"/></sphere>\n",
                x + 2
            ),
        );
        w(
            &mut xml,
            format!(
                "<sphere name=\"p{i}\"><center x=\"{}\" y=\"10\" z=\"{z}\"/><radius value=\"0.5\"/></sphere>\n",
                x + 2
            ),
        );
        w(
            &mut xml,
            format!("<subdomain name=\"O{i}\"><solid ref=\"o{i}\"/></subdomain>\n"),
        );
        w(
            &mut xml,
            format!("<subdomain name=\"P{i}\"><solid ref=\"p{i}\"/></subdomain>\n"),
        );
        // A box given by its faces, and a definition of neither form.
        w(
            &mut xml,
            format!(
                "<parallelepiped name=\"f{i}\"><first_point x=\"{x}\" y=\"20\" z=\"{z}\"/><second_point x=\"{}\" y=\"21\" z=\"{z1}\"/></parallelepiped>\n",
                x + 1
            ),
        );
        w(
            &mut xml,
            format!(
                "<subdomain name=\"F{i}\" faces=\"f{i}.xmin f{i}.xmax f{i}.ymin f{i}.ymax f{i}.zmin f{i}.zmax\"/>\n"
            ),
        );
        w(&mut xml, format!("<subdomain name=\"N{i}\"/>\n"));
        if crossing && i % 3 == 0 {
            w(
                &mut xml,
                format!(
                    "<sphere name=\"x{i}\"><center x=\"{x}\" y=\"30\" z=\"{z}\"/><radius value=\"1\"/></sphere>\n"
                ),
            );
            w(
                &mut xml,
                format!(
                    "<sphere name=\"y{i}\"><center x=\"{}\" y=\"30\" z=\"{z}\"/><radius value=\"1\"/></sphere>\n",
                    x + 1
                ),
            );
            w(
                &mut xml,
                format!(
                    "<subdomain name=\"X{i}\"><union><solid ref=\"x{i}\"/><solid ref=\"y{i}\"/></union></subdomain>\n"
                ),
            );
        }
    }
    xml.push_str("<boundary name=\"inlet\" faces=\"b0.xmin\"/>\n</geometry>\n");
    xml
}

fn checked(threads: usize, text: &str) -> Checked {
    let source = SourceFile::new("subdomains.xml".to_string(), text.to_string());
    on_threads(threads, || check_source(source, &Options::default()))
}

/// The model, source map and diagnostics, compared whole.
fn outcome(checked: &Checked) -> String {
    let mut out = String::new();
    let lowered = checked.lowered.as_ref().expect("the file lowers");
    write!(out, "{:?}\n{:?}\n", lowered.model, lowered.source_map).expect("a string");
    write!(out, "{:?}", checked.diagnostics.items).expect("a string");
    out
}

fn count(checked: &Checked, code: Code) -> usize {
    let items = &checked.diagnostics.items;
    items.iter().filter(|d| d.code == code).count()
}

#[test]
fn subdomains_lower_and_check_alike_on_any_thread_count() {
    let groups = 300;
    let text = definitions(groups, false);
    let one = checked(1, &text);
    // Six definitions a group, more than a task of lookups.
    assert!(6 * groups > 2 * super::booleans::DEFINITIONS_PER_TASK);
    assert_eq!(count(&one, Code::UndefinedName), groups);
    assert_eq!(count(&one, Code::MissingElement), groups);
    assert_eq!(count(&one, Code::SubdomainsOverlap), groups);
    assert_eq!(count(&one, Code::BoundariesIntersect), 0);
    let undefined = (one.diagnostics.items.iter())
        .find(|d| d.code == Code::UndefinedName)
        .and_then(|d| d.help.clone());
    assert_eq!(undefined.as_deref(), Some("did you mean 's0'?"));
    let model = &one.lowered.as_ref().expect("the file lowers").model;
    // m, c, O, P and F of every group; u and N are not made.
    assert_eq!(model.subdomains.len(), 5 * groups);
    let boundary = |name: &str| {
        let s = (model.subdomains.iter()).find(|s| s.name == name);
        match s.map(|s| &s.cells) {
            Some(SubdomainCells::Volume { boundary }) => boundary.len(),
            _ => usize::MAX,
        }
    };
    // The box minus the ball: its 6 faces and the ball's; the faces= box: 6.
    let ball_faces = boundary("c7");
    assert!(ball_faces > 0);
    assert_eq!(boundary("m7"), 6 + ball_faces);
    assert_eq!(boundary("F7"), 6);
    assert_eq!(boundary("O7"), ball_faces);
    let solids = |name: &str| {
        let s = (model.subdomains.iter()).find(|s| s.name == name);
        s.map_or(0, |s| s.solids.len())
    };
    assert_eq!((solids("m9"), solids("c9"), solids("F9")), (2, 1, 0));
    alike_on_more_threads(&text, &one);
}

#[test]
fn crossing_solids_are_reported_alike_on_any_thread_count() {
    let groups = 300;
    let text = definitions(groups, true);
    let one = checked(1, &text);
    assert_eq!(count(&one, Code::BoundariesIntersect), groups / 3);
    // Crossing boundaries stop the classification and the overlap check.
    assert_eq!(count(&one, Code::SubdomainsOverlap), 0);
    let first = (one.diagnostics.items.iter())
        .find(|d| d.code == Code::BoundariesIntersect)
        .map(|d| d.message.clone());
    assert_eq!(
        first.as_deref(),
        Some("the boundaries of 'x0' and 'y0' cross near (0.5, 29.652928812, -0.79343657)")
    );
    alike_on_more_threads(&text, &one);
}

/// Checks `text` on 2 and 3 threads against its one-thread check `one`.
fn alike_on_more_threads(text: &str, one: &Checked) {
    let expected = outcome(one);
    for threads in [2, 3] {
        assert_eq!(
            outcome(&checked(threads, text)),
            expected,
            "{threads} threads"
        );
    }
}
