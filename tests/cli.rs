//! The command line as users and CI meet it: exit codes, output formats,
//! folders, --deny-warnings, --set, explain.

use std::path::Path;
use std::process::{Command, Output};

fn geomc(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_geomc"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("geomc runs")
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn a_valid_file_exits_zero_and_an_invalid_one_exits_one() {
    let ok = geomc(&["validate", "examples/ball_in_box.xml"]);
    assert_eq!(ok.status.code(), Some(0), "{}", stderr(&ok));
    assert!(
        stderr(&ok).ends_with("checked 1 file: 0 invalid, 0 errors, 0 warnings\n"),
        "{}",
        stderr(&ok)
    );
    let bad = geomc(&["validate", "fixtures/invalid/e201_two_spheres.xml"]);
    assert_eq!(bad.status.code(), Some(1));
}

#[test]
fn human_diagnostics_show_the_location_the_line_and_a_caret() {
    let out = geomc(&["validate", "fixtures/invalid/e110_typo_root_child.xml"]);
    let text = stderr(&out);
    let first = text.lines().next().unwrap_or_default();
    assert!(
        first.starts_with("fixtures/invalid/e110_typo_root_child.xml:")
            && first.contains(": error[E110]: unknown element <"),
        "{text}"
    );
    assert!(text.contains("\n  |"), "{text}");
    assert!(
        text.lines()
            .any(|l| l.trim_start().starts_with('|') && l.contains('^')),
        "{text}"
    );
    assert!(text.contains("= help: did you mean <"), "{text}");
}

#[test]
fn json_output_is_one_array_of_located_diagnostics() {
    let out = geomc(&[
        "validate",
        "--format",
        "json",
        "fixtures/invalid/e300_negative_radius_parameter.xml",
    ]);
    assert_eq!(out.status.code(), Some(1));
    let value: serde_json::Value = serde_json::from_str(&stdout(&out)).expect("JSON");
    let items = value.as_array().expect("an array");
    let e300 = items
        .iter()
        .find(|d| d["code"] == "E300")
        .expect("E300 reported");
    for key in [
        "file",
        "line",
        "column",
        "end_line",
        "end_column",
        "severity",
        "code",
        "message",
        "help",
    ] {
        assert!(e300.get(key).is_some(), "missing {key}: {e300}");
    }
    assert_eq!(e300["severity"], "error");
    assert!(e300["line"].as_u64().unwrap_or(0) > 0);
}

#[test]
fn folders_are_searched_recursively_and_summarised() {
    let out = geomc(&["validate", "--format", "json", "fixtures/valid"]);
    assert_eq!(out.status.code(), Some(0), "{}", stdout(&out));
    let n_files = std::fs::read_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/valid"))
        .expect("folder")
        .filter(|e| {
            e.as_ref()
                .is_ok_and(|e| e.path().extension().is_some_and(|x| x == "xml"))
        })
        .count();
    let human = geomc(&["validate", "fixtures/valid"]);
    let summary = stderr(&human)
        .lines()
        .last()
        .unwrap_or_default()
        .to_string();
    assert!(
        summary.starts_with(&format!("checked {n_files} files: 0 invalid, 0 errors, ")),
        "{summary}"
    );
}

#[test]
fn deny_warnings_turns_warnings_into_failures() {
    let file = "fixtures/valid/paper000.xml";
    assert_eq!(geomc(&["validate", file]).status.code(), Some(0));
    let denied = geomc(&["validate", "--deny-warnings", "--format", "json", file]);
    assert_eq!(denied.status.code(), Some(1));
    let value: serde_json::Value = serde_json::from_str(&stdout(&denied)).expect("JSON");
    assert!(
        value
            .as_array()
            .expect("array")
            .iter()
            .all(|d| d["severity"] == "error")
    );
}

#[test]
fn missing_files_and_bad_usage_exit_two() {
    let missing = geomc(&["validate", "no/such/file.xml"]);
    assert_eq!(missing.status.code(), Some(2));
    assert!(
        stderr(&missing).starts_with("geomc: cannot read no/such/file.xml:"),
        "{}",
        stderr(&missing)
    );
    assert_eq!(geomc(&["validate"]).status.code(), Some(2));
    assert_eq!(geomc(&["frobnicate"]).status.code(), Some(2));
    assert_eq!(geomc(&["explain", "E999"]).status.code(), Some(2));
}

#[test]
fn set_overrides_a_parameter_and_reports_unknown_ones() {
    let ok = geomc(&[
        "inspect",
        "--format",
        "json",
        "--set",
        "r=1.5",
        "examples/ball_in_box.xml",
    ]);
    assert_eq!(ok.status.code(), Some(0), "{}", stderr(&ok));
    let value: serde_json::Value = serde_json::from_str(&stdout(&ok)).expect("JSON");
    let params = value["parameters"].as_array().expect("parameters");
    assert!(
        params.iter().any(|p| p[0] == "r" && p[1] == 1.5),
        "{params:?}"
    );
    let unknown = geomc(&["validate", "--set", "radius=1", "examples/ball_in_box.xml"]);
    assert_eq!(unknown.status.code(), Some(1));
    assert!(
        stderr(&unknown)
            .contains("error[E204]: --set radius: the file defines no parameter 'radius'"),
        "{}",
        stderr(&unknown)
    );
    let malformed = geomc(&["validate", "--set", "r", "examples/ball_in_box.xml"]);
    assert_eq!(malformed.status.code(), Some(1));
    assert!(
        stderr(&malformed).contains("error[E207]"),
        "{}",
        stderr(&malformed)
    );
}

#[test]
fn explain_prints_every_code() {
    let out = geomc(&["explain", "e408"]);
    assert_eq!(out.status.code(), Some(0));
    assert!(
        stdout(&out).starts_with("E408 (error): solid boundaries intersect\n\n"),
        "{}",
        stdout(&out)
    );
    let all = geomc(&["explain", "all"]);
    assert_eq!(stdout(&all).lines().count(), geomc::diag::Code::ALL.len());
}

#[test]
fn inspect_refuses_an_invalid_file() {
    let out = geomc(&[
        "inspect",
        "fixtures/invalid/e300_negative_radius_parameter.xml",
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("is invalid; fix the errors above to inspect it"));
}

#[test]
fn inspect_prints_matrices_on_request() {
    let out = geomc(&["inspect", "--matrices", "examples/ball_in_box.xml"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let text = stdout(&out);
    for title in [
        "M_VE (vertex × edge):",
        "M_EF (edge × face):",
        "M_FD (face × subdomain):",
        "V–F (vertex × face):",
        "E–D (edge × subdomain):",
    ] {
        assert!(text.contains(title), "{title} missing:\n{text}");
    }
}

#[test]
fn a_failed_edge_is_reported_once_without_follow_on_errors() {
    // The faces using the edge, the subdomain using those faces and the
    // boundaries naming them all fail with it; only the cause is reported.
    let out = geomc(&[
        "validate",
        "--format",
        "json",
        "fixtures/hostile/xml/explicit_edge_degenerate.xml",
    ]);
    assert_eq!(out.status.code(), Some(1));
    let value: serde_json::Value = serde_json::from_str(&stdout(&out)).expect("JSON");
    let codes: Vec<&str> = value
        .as_array()
        .expect("an array")
        .iter()
        .filter_map(|d| d["code"].as_str())
        .collect();
    assert_eq!(codes, ["E400"]);
    assert_eq!(value[0]["line"], 13);
    assert_eq!(value[0]["column"], 4);
}
