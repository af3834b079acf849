//! Crash-safe output (issue 10): geomc killed with SIGKILL in the middle of
//! writing leaves at each target either the previous file, byte for byte, or
//! (for an output it had finished) a complete new one — never a partial file.
//! Writers go through `formats::write_atomic`: a hidden temporary
//! `.NAME.PID.N.tmp` beside the target, fsync, rename. A kill can leave that
//! temporary behind; it is the only leftover allowed, and it is named as one.
#![cfg(unix)]

use std::os::unix::process::ExitStatusExt;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const TARGETS: [&str; 4] = ["big.stl", "big.obj", "big.vtu", "big.msh"];

fn previous(name: &str) -> Vec<u8> {
    format!("the previous {name}, which must survive a crash\n").into_bytes()
}

/// The temporary file of a target being written, if any.
fn temporary_of(dir: &Path) -> Option<(String, u64)> {
    std::fs::read_dir(dir)
        .ok()?
        .filter_map(|e| e.ok())
        .find_map(|e| {
            let name = e.file_name().to_string_lossy().into_owned();
            let size = e.metadata().map(|m| m.len()).unwrap_or(0);
            (name.starts_with('.') && name.ends_with(".tmp") && size > 0).then_some((name, size))
        })
}

/// Whether `path` is a complete mesh file: geomc reads it back without error.
fn reads_back(path: &Path) -> bool {
    Command::new(env!("CARGO_BIN_EXE_geomc"))
        .arg("inspect")
        .arg(path)
        .output()
        .is_ok_and(|o| o.status.success())
}

#[test]
fn sigkill_mid_write_leaves_the_previous_file_or_a_complete_one() {
    let dir = tempfile::tempdir().expect("temporary folder");
    for name in TARGETS {
        std::fs::write(dir.path().join(name), previous(name)).expect("previous file");
    }
    let rfs = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/rfs/seven_balls.rfs");
    // About 300,000 triangles written four times as text (about 100 MB in all):
    // the writes take long enough in a debug build to be caught in the middle.
    let mut child = Command::new(env!("CARGO_BIN_EXE_geomc"))
        .arg("compile")
        .arg(&rfs)
        .args(["--cells", "200", "--ascii", "--quiet"])
        .args(TARGETS.iter().flat_map(|t| {
            [
                "-o".to_string(),
                dir.path().join(t).to_string_lossy().into_owned(),
            ]
        }))
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("geomc starts");
    let start = Instant::now();
    let caught = loop {
        if let Some(found) = temporary_of(dir.path()) {
            break Some(found);
        }
        if child.try_wait().expect("poll").is_some() || start.elapsed() > Duration::from_secs(300) {
            break None;
        }
        std::thread::sleep(Duration::from_micros(200));
    };
    let _ = child.kill(); // SIGKILL
    let status = child.wait().expect("reaped");
    let (temporary, size) = caught.expect("geomc finished before any write could be caught");
    assert_eq!(status.signal(), Some(9), "geomc was not killed: {status:?}");
    assert!(size > 0);
    // The target being written when the kill came still holds the previous file.
    let being_written = TARGETS
        .iter()
        .find(|t| temporary.starts_with(&format!(".{t}.")))
        .expect("the temporary names its target");
    assert_eq!(
        std::fs::read(dir.path().join(being_written)).expect("target"),
        previous(being_written),
        "{being_written} is not the previous file"
    );
    // Every other target is the previous file or a complete new one.
    for name in TARGETS {
        let path = dir.path().join(name);
        let bytes = std::fs::read(&path).expect("target");
        assert!(
            bytes == previous(name) || reads_back(&path),
            "{name} is neither the previous file nor a complete mesh ({} bytes)",
            bytes.len()
        );
    }
    // Leftovers are only hidden temporaries, named as such.
    for entry in std::fs::read_dir(dir.path()).expect("folder") {
        let name = entry
            .expect("entry")
            .file_name()
            .to_string_lossy()
            .into_owned();
        assert!(
            TARGETS.contains(&name.as_str()) || (name.starts_with('.') && name.ends_with(".tmp")),
            "unexpected file {name}"
        );
    }
}
