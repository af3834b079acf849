//! Checks that the XSD `schema/geomc.xsd`, as applied by an independent validator
//! (libxml2's `xmllint`), agrees with the fixtures: every valid fixture is
//! accepted; an invalid fixture is rejected exactly when its problem is one of
//! structure (the codes the XSD can express), and accepted otherwise, since
//! names, values and geometry are beyond XSD. All disagreements are reported
//! together.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The codes of problems the XSD also rejects.
const STRUCTURAL: &[&str] = &[
    "E100", "E104", "E105", "E110", "E111", "E112", "E113", "E114", "E115", "E116", "E117", "E118",
];

/// Fixtures xmllint cannot judge like geomc does:
/// - E101: xmllint reads the DTD and would expand its entities (the point of the
///   fixture is that geomc refuses to), so its verdict says nothing about the XSD;
/// - E107: the problem is the file's encoding, which xmllint reports its own way.
const SKIPPED: &[&str] = &["E101", "E107"];

const INSTALL_HINT: &str = "xmllint is not installed, so the schema cannot be checked against the fixtures; \
     run the test command from fixtures/README.md, which installs it: \
     apt-get update && apt-get install -y libxml2-utils && cargo test --test xmllint_agreement";

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn xml_files(kind: &str) -> Vec<PathBuf> {
    let dir = root().join("fixtures").join(kind);
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", dir.display()))
        .map(|entry| entry.expect("directory entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "xml"))
        .collect();
    files.sort();
    files
}

/// The code in an invalid fixture's `<!-- expect: CODE -->` header.
fn expected_code(path: &Path) -> Option<String> {
    let bytes = std::fs::read(path).ok()?;
    let text = String::from_utf8_lossy(&bytes);
    text.lines().take(6).find_map(|line| {
        let rest = line
            .trim()
            .strip_prefix("<!-- expect:")?
            .strip_suffix("-->")?;
        Some(rest.trim().to_string())
    })
}

fn display(path: &Path) -> String {
    path.strip_prefix(root())
        .unwrap_or(path)
        .display()
        .to_string()
}

/// Whether xmllint accepts the file, with its messages.
fn xmllint(schema: &Path, file: &Path) -> (bool, String) {
    let output = Command::new("xmllint")
        .args(["--noout", "--nonet", "--schema"])
        .arg(schema)
        .arg(file)
        .output()
        .unwrap_or_else(|e| panic!("cannot run xmllint: {e}"));
    let stderr = String::from_utf8_lossy(&output.stderr).to_string();
    // Exit 5: the schema itself did not compile; every verdict would be meaningless.
    if output.status.code() == Some(5) || stderr.contains("failed to compile") {
        panic!("xmllint cannot compile {}:\n{stderr}", display(schema));
    }
    (output.status.success(), stderr)
}

fn first_lines(text: &str, n: usize) -> String {
    text.lines().take(n).collect::<Vec<_>>().join(" | ")
}

#[test]
fn xmllint_agrees_with_the_fixtures() {
    if Command::new("xmllint").arg("--version").output().is_err() {
        panic!("{INSTALL_HINT}");
    }
    let schema = root().join("schema").join("geomc.xsd");
    assert!(
        schema.is_file(),
        "{} does not exist: the schema must be in the tree for this test",
        display(&schema)
    );
    let mut disagreements = Vec::new();
    let mut checked = 0;
    for file in xml_files("valid") {
        checked += 1;
        let (accepted, messages) = xmllint(&schema, &file);
        if !accepted {
            disagreements.push(format!(
                "{}: valid, but xmllint rejects it: {}",
                display(&file),
                first_lines(&messages, 3)
            ));
        }
    }
    for file in xml_files("invalid") {
        let Some(code) = expected_code(&file) else {
            disagreements.push(format!(
                "{}: no `<!-- expect: CODE -->` header",
                display(&file)
            ));
            continue;
        };
        if SKIPPED.contains(&code.as_str()) {
            continue;
        }
        checked += 1;
        let structural = STRUCTURAL.contains(&code.as_str());
        let (accepted, messages) = xmllint(&schema, &file);
        if structural && accepted {
            disagreements.push(format!(
                "{}: expects structural error {code}, but xmllint accepts it",
                display(&file)
            ));
        } else if !structural && !accepted {
            disagreements.push(format!(
                "{}: expects {code}, which is beyond the XSD, but xmllint rejects it: {}",
                display(&file),
                first_lines(&messages, 3)
            ));
        }
    }
    assert!(
        disagreements.is_empty(),
        "{} of {checked} fixtures: xmllint and the fixtures disagree:\n{}",
        disagreements.len(),
        disagreements.join("\n")
    );
}
