//! The hostile-input corpus (issue 10): every file under fixtures/hostile/
//! (written by fixtures/hostile/generate.py) is run through the real binary
//! with the command EXPECTED.tsv names, and must be refused with exactly its
//! expected error codes, exit status 1, within generous time and memory
//! ceilings (they catch a hang or a blow-up, they do not measure speed), and
//! without leaving any file — output or temporary — in the output folder.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

const TIME_CEILING: Duration = Duration::from_secs(30);
const MEMORY_CEILING: u64 = 512 * 1024 * 1024;

struct Entry {
    file: String,
    command: String,
    codes: BTreeSet<String>,
    extra: Vec<String>,
}

fn corpus() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/hostile")
}

fn manifest() -> Vec<Entry> {
    let text = std::fs::read_to_string(corpus().join("EXPECTED.tsv")).expect("EXPECTED.tsv");
    text.lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .map(|line| {
            let cols: Vec<&str> = line.split('\t').collect();
            assert!(cols.len() >= 3, "malformed manifest line: {line}");
            Entry {
                file: cols[0].to_string(),
                command: cols[1].to_string(),
                codes: cols[2].split_whitespace().map(String::from).collect(),
                extra: cols
                    .get(3)
                    .map(|a| a.split_whitespace().map(String::from).collect())
                    .unwrap_or_default(),
            }
        })
        .collect()
}

/// Error codes in the output, as `error[E123]` (human form) or `"code":"E123"`.
fn error_codes(text: &str) -> BTreeSet<String> {
    let mut codes = BTreeSet::new();
    for (i, _) in text.match_indices("error[") {
        let code = &text[i + 6..];
        if let Some(end) = code.find(']') {
            codes.insert(code[..end].to_string());
        }
    }
    codes
}

/// Runs one entry; returns a description of what went wrong, if anything.
fn check(entry: &Entry) -> Option<String> {
    let input = corpus().join(&entry.file);
    let out_dir = tempfile::tempdir().expect("temporary folder");
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_geomc"));
    cmd.env("GEOMC_STATS", "1");
    match entry.command.as_str() {
        "compile" => cmd
            .arg("compile")
            .args(&entry.extra)
            .arg(&input)
            .arg("-o")
            .arg(out_dir.path().join("out.msh")),
        "convert" => cmd
            .arg("convert")
            .args(&entry.extra)
            .arg(&input)
            .arg(out_dir.path().join("out.obj")),
        "inspect" | "validate" => cmd.arg(&entry.command).args(&entry.extra).arg(&input),
        other => return Some(format!("unknown command {other}")),
    };
    let start = Instant::now();
    let output = cmd.output().expect("geomc runs");
    let elapsed = start.elapsed();
    let stderr = String::from_utf8_lossy(&output.stderr);
    let stdout = String::from_utf8_lossy(&output.stdout);
    let mut problems = Vec::new();
    if output.status.code() != Some(1) {
        problems.push(format!(
            "exit status {:?}, expected 1",
            output.status.code()
        ));
    }
    let codes = error_codes(&format!("{stdout}{stderr}"));
    if codes != entry.codes {
        problems.push(format!("codes {codes:?}, expected {:?}", entry.codes));
    }
    if elapsed > TIME_CEILING {
        problems.push(format!("took {elapsed:?}"));
    }
    let peak: Option<u64> = stderr
        .lines()
        .find_map(|l| l.strip_prefix("peak memory: "))
        .and_then(|l| l.trim_end_matches(" bytes").parse().ok());
    match peak {
        Some(bytes) if bytes > MEMORY_CEILING => {
            problems.push(format!("peak memory {bytes} bytes"))
        }
        Some(_) => {}
        None if Path::new("/proc/self/status").exists() => {
            problems.push("no peak memory reported".into())
        }
        None => {}
    }
    let left: Vec<String> = std::fs::read_dir(out_dir.path())
        .expect("read output folder")
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    if !left.is_empty() {
        problems.push(format!("left files behind: {left:?}"));
    }
    (!problems.is_empty()).then(|| {
        format!(
            "{} ({}): {}\n{}",
            entry.file,
            entry.command,
            problems.join("; "),
            stderr.lines().take(3).collect::<Vec<_>>().join("\n")
        )
    })
}

#[test]
fn manifest_lists_every_file_of_the_corpus() {
    let listed: BTreeSet<String> = manifest().into_iter().map(|e| e.file).collect();
    let mut present = BTreeSet::new();
    for kind in std::fs::read_dir(corpus()).expect("corpus folder") {
        let kind = kind.expect("entry").path();
        if !kind.is_dir() {
            continue;
        }
        for file in std::fs::read_dir(&kind).expect("kind folder") {
            let file = file.expect("entry").path();
            let rel = file.strip_prefix(corpus()).expect("inside corpus");
            present.insert(rel.to_string_lossy().replace('\\', "/"));
        }
    }
    assert_eq!(listed, present, "EXPECTED.tsv and the files disagree");
    assert!(present.len() >= 150, "only {} hostile files", present.len());
    let kinds: BTreeSet<&str> = present.iter().filter_map(|f| f.split('/').next()).collect();
    let expected: BTreeSet<&str> = ["xml", "rfs", "stl", "obj", "gltf", "glb", "msh", "vtu"].into();
    assert_eq!(kinds, expected);
}

#[test]
fn every_hostile_file_is_refused_with_its_code_and_leaves_nothing() {
    let entries = manifest();
    let threads = std::thread::available_parallelism()
        .map_or(2, |n| n.get())
        .min(4);
    let chunk = entries.len().div_ceil(threads);
    let failures: Vec<String> = std::thread::scope(|scope| {
        let handles: Vec<_> = entries
            .chunks(chunk)
            .map(|part| scope.spawn(move || part.iter().filter_map(check).collect::<Vec<_>>()))
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().expect("worker"))
            .collect()
    });
    assert!(
        failures.is_empty(),
        "{} of {} hostile runs failed:\n{}",
        failures.len(),
        entries.len(),
        failures.join("\n\n")
    );
}
