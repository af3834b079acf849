//! Random edits of the valid fixtures read by the split path (the scan, the
//! plain reader, roxmltree's runs) against a whole-file parse.

use super::*;
use crate::test_rng::TestRng;
use std::path::PathBuf;

/// The valid fixtures' texts from their root elements on.
fn valid_fixtures() -> Vec<(PathBuf, String)> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("fixtures/valid");
    let mut paths: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("the fixtures are there")
        .map(|entry| entry.expect("a readable entry").path())
        .filter(|path| path.extension().is_some_and(|e| e == "xml"))
        .collect();
    paths.sort();
    paths
        .into_iter()
        .map(|path| {
            let text = std::fs::read_to_string(&path).expect("a fixture is UTF-8");
            // From the root on: the fixtures' leading comments (their expected
            // findings) would make every file be parsed whole.
            let root = text.find("<geometry").expect("a fixture has a root");
            (path, text[root..].to_string())
        })
        .collect()
}

/// The root's children as a whole parse reads them, or `None` when it
/// refuses the file or cannot place a name.
fn whole_read<'s>(text: &'s str, limits: &Limits) -> Option<Vec<Element<'s>>> {
    let document = roxmltree::Document::parse_with_options(text, options(limits)).ok()?;
    check_depth(document.root_element(), limits).ok()?;
    let children = document
        .root_element()
        .children()
        .filter(|c| c.is_element());
    children
        .map(|c| tree::build(c, Origin::whole(text)).ok())
        .collect()
}

/// Where the root's children may start: after its start tag.
fn contents_start(text: &str) -> Option<usize> {
    let root = prolog_end(text.as_bytes())?;
    start_tag_end(text.as_bytes(), root).map(|(end, _)| end)
}

/// Every valid fixture, edited at random: whenever the scan splits the file
/// and every run reads, the children and heads are the whole parse's (and it
/// accepts the file); a scan in halves from a guessed middle finds what one
/// scan finds; and a run the plain reader accepts is what roxmltree reads.
#[test]
fn edited_fixtures_split_only_as_a_whole_parse_reads_them() {
    let fixtures = valid_fixtures();
    assert!(fixtures.len() >= 40, "{}", fixtures.len());
    let alphabet: &[u8] = b"<>/=\"' \t\n&!?-:_.aZ09";
    let mut rng = TestRng::new(0x51af_d7ed_558c_cd01);
    let limits = Limits::default();
    let (mut split_and_read, mut refused, mut plain_runs, mut halves) = (0, 0, 0, 0);
    for (path, original) in &fixtures {
        for edit in 0..60 {
            // The fixture itself first, then edits of it.
            let text = match edit {
                0 => original.clone(),
                _ => match rng.edit(original, alphabet, 2) {
                    Some(text) => text,
                    None => continue,
                },
            };
            let whole = whole_read(&text, &limits);
            if let Some(from) = contents_start(&text) {
                let one = scan_children(&text, from, usize::MAX);
                let at = from + rng.below(text.len() - from + 1);
                if let Some(middle) = guess_child_start(text.as_bytes(), at) {
                    halves += 1;
                    assert_eq!(scan_halves(&text, from, middle), one, "{path:?} {text:?}");
                }
            }
            let Some(split) = Split::scan(&text, &limits) else {
                continue;
            };
            for first in split.run_starts() {
                let last = split.run_end(first) - 1;
                let (start, end) = (split.children[first].start, split.children[last].end);
                let read = plain::read_run(&text, start, end, limits.max_depth, 0);
                if let Some(read) = read {
                    plain_runs += 1;
                    let parsed = split.run(first).expect("a plain run matches its heads");
                    assert_eq!(read, parsed, "{path:?} {text:?}");
                }
            }
            match split.top_level().collect::<Result<Vec<_>, _>>() {
                Ok(children) => {
                    split_and_read += 1;
                    let elements = whole.expect("the whole parse accepts it");
                    assert_eq!(children, elements, "{path:?} {text:?}");
                    let heads: Vec<Head> = elements.iter().map(Element::head).collect();
                    assert_eq!(heads, split.heads(), "{path:?} {text:?}");
                }
                Err(Reparse) => refused += 1,
            }
        }
    }
    // Every outcome is exercised.
    assert!(split_and_read > 1_000, "{split_and_read} {refused}");
    assert!(refused > 1_000, "{split_and_read} {refused}");
    assert!(plain_runs > 1_000, "{plain_runs}");
    assert!(halves > 3_000, "{halves}");
}
