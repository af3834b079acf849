//! Golden outputs: the rendered diagnostics of every invalid fixture and the
//! `inspect` report of every valid fixture, as insta snapshots in
//! `tests/snapshots/`. A change in wording or in computed facts shows up as a
//! reviewed diff (`cargo insta review`), never silently.

use geomc::diag::render_human;
use geomc::driver::{Options, check_file};
use std::path::{Path, PathBuf};

fn fixtures(folder: &str) -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files: Vec<PathBuf> = std::fs::read_dir(root.join("fixtures").join(folder))
        .expect("fixture folder")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "xml"))
        .map(|p| p.strip_prefix(root).map(Path::to_path_buf).unwrap_or(p))
        .collect();
    files.sort();
    files
}

fn settings() -> insta::Settings {
    let mut settings = insta::Settings::clone_current();
    settings.set_prepend_module_to_snapshot(false);
    settings.set_omit_expression(true);
    settings
}

#[test]
fn diagnostics_of_invalid_fixtures() {
    std::env::set_current_dir(env!("CARGO_MANIFEST_DIR")).expect("cd");
    let settings = settings();
    for path in fixtures("invalid") {
        let checked = check_file(&path, &Options::default()).expect("readable fixture");
        let text: String = checked
            .diagnostics
            .items
            .iter()
            .map(|d| render_human(&checked.source, d))
            .collect();
        let name = format!(
            "invalid__{}",
            path.file_stem()
                .and_then(|s| s.to_str())
                .unwrap_or("fixture")
        );
        settings.bind(|| insta::assert_snapshot!(name, text));
    }
}

#[test]
fn inspect_reports_of_valid_fixtures() {
    std::env::set_current_dir(env!("CARGO_MANIFEST_DIR")).expect("cd");
    let settings = settings();
    for path in fixtures("valid") {
        let checked = check_file(&path, &Options::default()).expect("readable fixture");
        let lowered = checked.lowered.expect("valid fixtures resolve");
        let report = geomc::inspect::Report::of(&lowered.model);
        let text = report.render_text(&lowered.model, false);
        let name = format!(
            "valid__{}",
            path.file_stem()
                .and_then(|s| s.to_str())
                .unwrap_or("fixture")
        );
        settings.bind(|| insta::assert_snapshot!(name, text));
    }
}
