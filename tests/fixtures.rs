//! Runs `geomc validate --format json` on every fixture under `fixtures/` and
//! checks the outcome against the expectation in the fixture's header comments
//! (see `fixtures/README.md`): a valid fixture must pass with exactly the warning
//! codes it lists, an invalid one must fail with the error code it names. All
//! failures are collected and reported together, so one run shows every
//! fixture that disagrees with the CLI.

use geomc::diag::{Code, Severity};
use serde::Deserialize;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::Command;

/// Codes whose diagnostics legitimately have no position in the file: they are
/// about the file as a whole or about the command line.
const UNPOSITIONED: &[&str] = &["E103", "E106", "E204", "E207"];

/// Error codes that no fixture can express in a small file; they are tested elsewhere.
const NOT_COVERED_BY_FIXTURES: &[&str] = &[
    "E103", "E106",
    // .rfs language (issue 5): reached only from .rfs files; tests/implicit.rs
    // checks each code with its line:column.
    "E600", // syntax error
    "E601", // unknown name
    "E602", // wrong number of arguments
    "E603", // bad Geom setting
    "E604", // no result function
    "E605", // recursion
    "E606", // invalid library argument
    "E607", // duplicate definition
    "E608", // result function signature
    "E609", // too large / too deep
    "E610", // string used as a number
    "E611", // no return
    "W130", // unknown Geom field
    "W131", // optiterations not applied: retired, optimisation is applied now
    // XML implicit solids (issue 5): compile-time only; tests/implicit_xml.rs.
    "E624", // invalid --section
    "W133", // section plane misses a subdomain
    // Compile-time (issue 3): meshing runs in `geomc compile` and `geomc
    // inspect --mesh`, not in the `validate` run fixtures use; tested in
    // tests/mesh_report.rs and src/meshing/guard.rs.
    "E500", // internal meshing failure: a caught panic, a bug by definition
    "E501", // invalid --tolerance / --max-edge / --min-angle values
    "E502", // a face the mesher cannot triangulate
    "E503", // an edge that needs too many segments
    // `geomc locate`'s points files (CSV, not XML models): tests/locate.rs.
    "E504", // bad row in a points file
    // ---- convert (issue 4): codes of mesh files, not of XML models ----
    "E520", // mesh files (geomc convert/inspect): tests/convert_bad_input.rs, tests/convert_cli.rs
    "E521", // mesh files (geomc convert/inspect): tests/convert_bad_input.rs, tests/convert_cli.rs
    "E522", // mesh files (geomc convert/inspect): tests/convert_bad_input.rs, tests/convert_cli.rs
    "E523", // mesh files (geomc convert/inspect): tests/convert_bad_input.rs, tests/convert_cli.rs
    "E524", // mesh files (geomc convert/inspect): tests/convert_bad_input.rs, tests/convert_cli.rs
    "E525", // mesh files (geomc convert/inspect): tests/convert_bad_input.rs, tests/convert_cli.rs
    "E526", // mesh files (geomc convert/inspect): tests/convert_bad_input.rs, tests/convert_cli.rs
    "E527", // mesh files (geomc convert/inspect): tests/convert_bad_input.rs, tests/convert_cli.rs
    "E528", // mesh files (geomc convert/inspect): tests/convert_bad_input.rs, tests/convert_cli.rs
    "E529", // mesh files (geomc convert/inspect): tests/convert_bad_input.rs, tests/convert_cli.rs
    "E530", // mesh files (geomc convert/inspect): tests/convert_bad_input.rs, tests/convert_cli.rs
    "E531", // mesh files (geomc convert/inspect): tests/convert_bad_input.rs, tests/convert_cli.rs
    "E532", // mesh files (geomc convert/inspect): tests/convert_bad_input.rs, tests/convert_cli.rs
    "E533", // mesh files (geomc convert/inspect): tests/convert_bad_input.rs, tests/convert_cli.rs
    "W110", // mesh files (geomc convert/inspect): tests/convert_bad_input.rs, tests/convert_cli.rs
    "W111", // mesh files (geomc convert/inspect): tests/convert_bad_input.rs, tests/convert_cli.rs
    "W112", // mesh files (geomc convert/inspect): tests/convert_bad_input.rs, tests/convert_cli.rs
    "W113", // mesh files (geomc convert/inspect): tests/convert_bad_input.rs, tests/convert_cli.rs
    "W114", // mesh files (geomc convert/inspect): tests/convert_bad_input.rs, tests/convert_cli.rs
    "W115", // mesh files (geomc convert/inspect): tests/convert_bad_input.rs, tests/convert_cli.rs
    "W116", // mesh files (geomc convert/inspect): tests/convert_bad_input.rs, tests/convert_cli.rs
    // ---- render (issue 8): options and inputs of geomc render, not XML content ----
    "E720", // an input that is not a domain file
    "E721", // --size
    "E722", // --view
    "E723", // --section
    "E724", // the picture's extension
    "E725", // --background
    "E726", // --antialias
    "E727", // a mesh without triangles (tests/render.rs)
    "E728", // --size × --antialias too large
    "E729", // meshing failed while rendering
    "W170", // the legend does not fit the picture's height
    "W171", // --section below the whole model (tests/render.rs)
    // ---- resource limits (issue 10): compile/convert, tests/hostile_corpus.rs and tests/limits.rs ----
    "E800", // implicit grid over --max-grid-cells
    "E801", // mesh over --max-triangles
    "E802", // a mesh file holding nothing
    "E803", // an implicit solid without surface on its grid
    // 2D R-function regions (issue 6, branch twod): tests/region_2d.rs checks
    // E541, E542 (it needs a samples file beside the model) and W151 with
    // real models. E540 (the tracer found a branching contour) is a guard:
    // no model tried reaches it, the tracer resolves saddles and touching
    // pieces.
    "E540", // contour branches or crosses itself
    "E541", // empty region
    "E542", // density volume in a 2D model
    "W151", // region reaches its box
    // ---- read limits (issue 10, branch render-harden): tests/limits.rs ----
    "E804", // glTF buffers over --max-file-size
    "E805", // glTF accessor elements over --max-mesh-elements
];

/// Command-line options an `args:` header may name, and whether each takes a value.
/// XML comments cannot contain `--`, so the header writes `set r=2` for `--set r=2`.
const OPTIONS: &[(&str, bool)] = &[
    ("set", true),
    ("deny-warnings", false),
    ("max-depth", true),
    ("max-nodes", true),
    ("max-file-size", true),
];

#[derive(Debug, Clone, PartialEq, Eq)]
enum Expectation {
    /// A valid file and the exact set of warning codes it must produce.
    Valid { warnings: BTreeSet<String> },
    /// An invalid file and the code that must be among its errors.
    Invalid { code: String },
}

#[derive(Debug, Clone)]
struct Fixture {
    path: PathBuf,
    expectation: Expectation,
    /// Extra command-line arguments, already turned into `--option value` form.
    args: Vec<String>,
}

#[derive(Debug, Deserialize)]
struct JsonDiagnostic {
    line: Option<u32>,
    column: Option<u32>,
    severity: String,
    code: String,
    message: String,
}

fn fixtures_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures")
}

/// The `.xml` files of `fixtures/<kind>`, sorted.
fn xml_files(kind: &str) -> Vec<PathBuf> {
    let dir = fixtures_dir().join(kind);
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", dir.display()))
        .map(|entry| entry.expect("directory entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "xml"))
        .collect();
    files.sort();
    files
}

/// The text of the header comment `<!-- KEY: … -->` among the first lines.
fn header(text: &str, key: &str) -> Option<String> {
    let prefix = format!("<!-- {key}:");
    text.lines().take(6).find_map(|line| {
        let rest = line.trim().strip_prefix(&prefix)?;
        let rest = rest.strip_suffix("-->")?;
        Some(rest.trim().to_string())
    })
}

/// Turns an `args:` header (`set r=2 deny-warnings`) into CLI arguments.
fn parse_args(spec: &str) -> Result<Vec<String>, String> {
    let mut out = Vec::new();
    let mut words = spec.split_whitespace();
    while let Some(word) = words.next() {
        let Some(&(name, takes_value)) = OPTIONS.iter().find(|(n, _)| *n == word) else {
            return Err(format!("unknown option '{word}' in the args: header"));
        };
        out.push(format!("--{name}"));
        if takes_value {
            let value = words
                .next()
                .ok_or_else(|| format!("option '{name}' in the args: header needs a value"))?;
            out.push(value.to_string());
        }
    }
    Ok(out)
}

/// Reads one fixture's header; the text is decoded lossily because one fixture
/// is deliberately not UTF-8.
fn load(path: &Path, valid: bool) -> Result<Fixture, String> {
    let bytes = std::fs::read(path).map_err(|e| format!("cannot read: {e}"))?;
    let text = String::from_utf8_lossy(&bytes);
    let expectation = if valid {
        let list = header(&text, "warnings")
            .ok_or("no `<!-- warnings: … -->` header in the first lines")?;
        let warnings = if list == "none" {
            BTreeSet::new()
        } else {
            list.split_whitespace().map(str::to_string).collect()
        };
        Expectation::Valid { warnings }
    } else {
        let code = header(&text, "expect")
            .ok_or("no `<!-- expect: CODE -->` header in the first lines")?;
        if code.split_whitespace().count() != 1 {
            return Err(format!(
                "the expect: header must name one code, not '{code}'"
            ));
        }
        Expectation::Invalid { code }
    };
    let args = match header(&text, "args") {
        Some(spec) => parse_args(&spec)?,
        None => Vec::new(),
    };
    Ok(Fixture {
        path: path.to_path_buf(),
        expectation,
        args,
    })
}

fn load_all() -> (Vec<Fixture>, Vec<String>) {
    let mut fixtures = Vec::new();
    let mut problems = Vec::new();
    for (kind, valid) in [("valid", true), ("invalid", false)] {
        for path in xml_files(kind) {
            match load(&path, valid) {
                Ok(f) => fixtures.push(f),
                Err(e) => problems.push(format!("{}: {e}", display(&path))),
            }
        }
    }
    (fixtures, problems)
}

fn display(path: &Path) -> String {
    path.strip_prefix(env!("CARGO_MANIFEST_DIR"))
        .unwrap_or(path)
        .display()
        .to_string()
}

fn summarize(diagnostics: &[JsonDiagnostic]) -> String {
    if diagnostics.is_empty() {
        return "no diagnostics".to_string();
    }
    diagnostics
        .iter()
        .map(|d| {
            let at = match (d.line, d.column) {
                (Some(l), Some(c)) => format!("{l}:{c}"),
                _ => "-".to_string(),
            };
            format!("{} {} at {at}: {}", d.severity, d.code, d.message)
        })
        .collect::<Vec<_>>()
        .join("; ")
}

/// Runs the CLI on one fixture; returns a description of every way the outcome
/// disagrees with the expectation (empty when it agrees).
fn check(fixture: &Fixture) -> Vec<String> {
    let output = Command::new(env!("CARGO_BIN_EXE_geomc"))
        .args(["validate", "--format", "json"])
        .args(&fixture.args)
        .arg(&fixture.path)
        .output();
    let output = match output {
        Ok(o) => o,
        Err(e) => return vec![format!("cannot run geomc: {e}")],
    };
    let stdout = String::from_utf8_lossy(&output.stdout);
    let stderr = String::from_utf8_lossy(&output.stderr);
    let status = output.status.code();
    let diagnostics: Vec<JsonDiagnostic> = match serde_json::from_str(stdout.trim()) {
        Ok(d) => d,
        Err(e) => {
            return vec![format!(
                "stdout is not one JSON array of diagnostics ({e}); exit {status:?}; stdout: {:.300}; stderr: {:.300}",
                stdout.trim(),
                stderr.trim()
            )];
        }
    };
    let mut problems = Vec::new();
    let errors: BTreeSet<&str> = diagnostics
        .iter()
        .filter(|d| d.severity == "error")
        .map(|d| d.code.as_str())
        .collect();
    let warnings: BTreeSet<String> = diagnostics
        .iter()
        .filter(|d| d.severity == "warning")
        .map(|d| d.code.clone())
        .collect();
    for d in &diagnostics {
        if d.severity != "error" && d.severity != "warning" {
            problems.push(format!(
                "diagnostic {} has severity '{}'",
                d.code, d.severity
            ));
        }
    }
    match &fixture.expectation {
        Expectation::Valid { warnings: expected } => {
            if status != Some(0) {
                problems.push(format!("expected exit 0, got {status:?}"));
            }
            if !errors.is_empty() {
                problems.push(format!("expected no errors, got {errors:?}"));
            }
            if &warnings != expected {
                problems.push(format!("expected warnings {expected:?}, got {warnings:?}"));
            }
        }
        Expectation::Invalid { code } => {
            if status != Some(1) {
                problems.push(format!("expected exit 1, got {status:?}"));
            }
            if !errors.contains(code.as_str()) {
                problems.push(format!("expected error {code}, got errors {errors:?}"));
            }
            for d in &diagnostics {
                if (d.line.is_none() || d.column.is_none())
                    && !UNPOSITIONED.contains(&d.code.as_str())
                {
                    problems.push(format!("{} '{}' has no line/column", d.code, d.message));
                }
            }
        }
    }
    if !problems.is_empty() {
        problems.push(format!("reported: {}", summarize(&diagnostics)));
    }
    problems
}

#[test]
fn every_fixture_gives_its_expected_result() {
    let (fixtures, mut failures) = load_all();
    assert!(
        !fixtures.is_empty(),
        "no fixtures found under {}",
        fixtures_dir().display()
    );
    let threads = std::thread::available_parallelism()
        .map_or(2, |n| n.get())
        .min(8);
    let chunk = fixtures.len().div_ceil(threads);
    let results: Vec<(PathBuf, Vec<String>)> = std::thread::scope(|scope| {
        let handles: Vec<_> = fixtures
            .chunks(chunk)
            .map(|part| {
                scope.spawn(move || {
                    part.iter()
                        .map(|f| (f.path.clone(), check(f)))
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().expect("checker thread"))
            .collect()
    });
    for (path, problems) in results {
        if !problems.is_empty() {
            failures.push(format!(
                "{}:\n    {}",
                display(&path),
                problems.join("\n    ")
            ));
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {} fixtures disagree with geomc:\n{}",
        failures.len(),
        fixtures.len(),
        failures.join("\n")
    );
}

#[test]
fn headers_name_known_codes_of_the_right_severity() {
    let (fixtures, mut failures) = load_all();
    for fixture in &fixtures {
        let (codes, severity): (Vec<&String>, Option<Severity>) = match &fixture.expectation {
            Expectation::Valid { warnings } => (warnings.iter().collect(), Some(Severity::Warning)),
            Expectation::Invalid { code } => (vec![code], None),
        };
        for code in codes {
            match Code::parse(code) {
                None => failures.push(format!("{}: unknown code {code}", display(&fixture.path))),
                Some(c) if c.as_str() != code => failures.push(format!(
                    "{}: write {code} as {}",
                    display(&fixture.path),
                    c.as_str()
                )),
                Some(c) if severity.is_some_and(|s| c.severity() != s) => failures.push(format!(
                    "{}: {code} is not a warning",
                    display(&fixture.path)
                )),
                Some(_) => {}
            }
        }
    }
    assert!(
        failures.is_empty(),
        "bad fixture headers:\n{}",
        failures.join("\n")
    );
}

#[test]
fn every_code_has_a_fixture() {
    let (fixtures, problems) = load_all();
    assert!(
        problems.is_empty(),
        "bad fixture headers:\n{}",
        problems.join("\n")
    );
    let mut expected_errors = BTreeSet::new();
    let mut listed_warnings = BTreeSet::new();
    for fixture in &fixtures {
        match &fixture.expectation {
            Expectation::Valid { warnings } => listed_warnings.extend(warnings.iter().cloned()),
            Expectation::Invalid { code } => {
                expected_errors.insert(code.clone());
                listed_warnings.insert(code.clone());
            }
        }
    }
    let mut missing = Vec::new();
    for code in Code::ALL {
        let text = code.as_str();
        let covered = match code.severity() {
            Severity::Error => {
                NOT_COVERED_BY_FIXTURES.contains(&text) || expected_errors.contains(text)
            }
            Severity::Warning => {
                NOT_COVERED_BY_FIXTURES.contains(&text) || listed_warnings.contains(text)
            }
        };
        if !covered {
            missing.push(format!("{text} ({})", code.title()));
        }
    }
    assert!(
        missing.is_empty(),
        "codes without a fixture: {}",
        missing.join(", ")
    );
}

#[test]
fn fixture_counts() {
    let valid = xml_files("valid").len();
    let invalid = xml_files("invalid").len();
    assert!(valid >= 45, "only {valid} valid fixtures");
    assert!(invalid >= 90, "only {invalid} invalid fixtures");
}
