//! A panic anywhere in geomc ends as `geomc: internal error: …` with a request
//! to report it, exit code 3, and no output file. The panic is provoked with
//! `GEOMC_DEBUG_PANIC`, which only debug builds read (src/cli/panic_probe.rs),
//! so this test only exists in debug builds too.
#![cfg(debug_assertions)]

use std::path::Path;
use std::process::Command;

fn compile(out: &Path, panic: bool) -> std::process::Output {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_geomc"));
    cmd.args(["compile", "examples/ball_in_box.xml", "-o"])
        .arg(out);
    if panic {
        cmd.env("GEOMC_DEBUG_PANIC", "1");
    } else {
        cmd.env_remove("GEOMC_DEBUG_PANIC");
    }
    cmd.current_dir(env!("CARGO_MANIFEST_DIR"));
    cmd.output().expect("geomc runs")
}

#[test]
fn a_panic_is_an_internal_error_with_exit_code_3() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("ball.msh");
    let run = compile(&out, true);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(3), "stderr: {stderr}");
    // The panic's location and message, then the request to report it.
    assert!(
        stderr.starts_with("geomc: internal error: panicked at src/cli/panic_probe.rs:"),
        "{stderr}"
    );
    assert!(
        stderr.contains("deliberate panic requested by GEOMC_DEBUG_PANIC"),
        "{stderr}"
    );
    assert_eq!(
        stderr.lines().last(),
        Some("this is a bug in geomc; please report it with the input that caused it")
    );
    assert!(run.stdout.is_empty());
    assert!(!out.exists(), "a panic must leave no output file");
}

#[test]
fn without_the_variable_the_same_command_succeeds() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("ball.msh");
    let run = compile(&out, false);
    assert_eq!(
        run.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert!(out.exists());
}
