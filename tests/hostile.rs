//! Hostile input: entity bombs, external entities, deep nesting, oversized
//! files, too many nodes, huge expressions. Each is refused with its own code,
//! quickly and in little memory (measured on the real binary with --stats;
//! the bounds are generous ceilings that catch a hang or a blow-up, the issue's
//! figures are under 1 s and 100 MB).

use std::io::Write;
use std::process::Command;
use std::time::{Duration, Instant};

struct Run {
    code: Option<i32>,
    json: serde_json::Value,
    elapsed: Duration,
    peak_bytes: u64,
}

fn validate(path: &std::path::Path, extra: &[&str]) -> Run {
    let start = Instant::now();
    let out = Command::new(env!("CARGO_BIN_EXE_geomc"))
        .args(["validate", "--stats", "--format", "json"])
        .args(extra)
        .arg(path)
        .output()
        .expect("geomc runs");
    let elapsed = start.elapsed();
    let stderr = String::from_utf8_lossy(&out.stderr);
    let peak_bytes = stderr
        .lines()
        .find_map(|l| l.strip_prefix("peak memory: "))
        .and_then(|l| l.trim_end_matches(" bytes").parse().ok())
        .unwrap_or(0);
    Run {
        code: out.status.code(),
        json: serde_json::from_slice(&out.stdout).unwrap_or(serde_json::Value::Null),
        elapsed,
        peak_bytes,
    }
}

fn write(name: &str, content: &[u8]) -> (tempfile::TempDir, std::path::PathBuf) {
    let dir = tempfile::tempdir().expect("temporary folder");
    let path = dir.path().join(name);
    let mut file = std::fs::File::create(&path).expect("create");
    file.write_all(content).expect("write");
    (dir, path)
}

fn assert_refused(run: &Run, code: &str) {
    assert_eq!(run.code, Some(1), "{:?}", run.json);
    let codes: Vec<&str> = run
        .json
        .as_array()
        .into_iter()
        .flatten()
        .filter(|d| d["severity"] == "error")
        .filter_map(|d| d["code"].as_str())
        .collect();
    assert_eq!(codes, vec![code], "{:?}", run.json);
    assert!(
        run.elapsed < Duration::from_secs(10),
        "took {:?}",
        run.elapsed
    );
    if run.peak_bytes > 0 {
        assert!(
            run.peak_bytes < 100_000_000,
            "peak memory {} bytes",
            run.peak_bytes
        );
    }
}

#[test]
fn billion_laughs_is_refused_before_any_expansion() {
    let mut xml =
        String::from("<?xml version=\"1.0\"?>\n<!DOCTYPE geometry [\n  <!ENTITY a \"ha\">\n");
    for level in 1..=10 {
        let previous = (b'a' + level - 1) as char;
        let name = (b'a' + level) as char;
        xml.push_str(&format!(
            "  <!ENTITY {name} \"{}\">\n",
            format!("&{previous};").repeat(10)
        ));
    }
    xml.push_str("]>\n<geometry version=\"1\"><parameters><parameter name=\"p\" value=\"&k;\"/></parameters></geometry>\n");
    let (_dir, path) = write("bomb.xml", xml.as_bytes());
    let run = validate(&path, &[]);
    assert_refused(&run, "E101");
    assert_eq!(run.json[0]["line"], 2);
}

#[test]
fn external_entities_are_never_read() {
    let xml = "<!DOCTYPE geometry [<!ENTITY secret SYSTEM \"file:///etc/hostname\">]>\n<geometry version=\"1\"><parameters><parameter name=\"p\" value=\"&secret;\"/></parameters></geometry>";
    let (_dir, path) = write("external.xml", xml.as_bytes());
    let run = validate(&path, &[]);
    assert_refused(&run, "E101");
    let hostname = std::fs::read_to_string("/etc/hostname").unwrap_or_default();
    if !hostname.trim().is_empty() {
        assert!(
            !run.json.to_string().contains(hostname.trim()),
            "the file's content leaked into the output"
        );
    }
}

#[test]
fn deep_nesting_is_refused() {
    let depth = 100_000;
    let mut xml = String::from(
        "<geometry version=\"1\"><sphere name=\"s\"><center x=\"0\" y=\"0\" z=\"0\"/><radius value=\"1\"/></sphere><subdomain name=\"d\">",
    );
    xml.push_str(&"<union>".repeat(depth));
    xml.push_str(&"</union>".repeat(depth));
    xml.push_str("</subdomain></geometry>");
    let (_dir, path) = write("deep.xml", xml.as_bytes());
    let run = validate(&path, &[]);
    assert_refused(&run, "E102");
    assert!(
        run.json[0]["message"]
            .as_str()
            .unwrap_or("")
            .contains("over the limit of 64")
    );
}

#[test]
fn oversized_files_are_refused_without_being_read() {
    let dir = tempfile::tempdir().expect("temporary folder");
    let path = dir.path().join("huge.xml");
    let file = std::fs::File::create(&path).expect("create");
    // A sparse 300 MB file: refusing it must not read (or allocate) 300 MB.
    file.set_len(300 * 1024 * 1024).expect("set length");
    let run = validate(&path, &[]);
    assert_refused(&run, "E103");
    let small = write("small.xml", b"<geometry version=\"1\"/>");
    let run = validate(&small.1, &["--max-file-size", "10"]);
    assert_refused(&run, "E103");
    assert!(
        run.json[0]["help"]
            .as_str()
            .unwrap_or("")
            .contains("--max-file-size")
    );
}

#[test]
fn too_many_nodes_are_refused_with_the_option_to_raise_the_limit() {
    let xml = format!(
        "<geometry version=\"1\">{}</geometry>",
        "<parameters/>".repeat(1000)
    );
    let (_dir, path) = write("many.xml", xml.as_bytes());
    let run = validate(&path, &["--max-nodes", "100"]);
    assert_refused(&run, "E106");
    assert!(
        run.json[0]["help"]
            .as_str()
            .unwrap_or("")
            .contains("--max-nodes")
    );
    assert_eq!(validate(&path, &[]).code, Some(0));
}

#[test]
fn huge_expressions_are_refused() {
    let expr = vec!["1"; 20_000].join("+");
    let xml = format!(
        "<geometry version=\"1\"><parameters><parameter name=\"p\" value=\"{expr}\"/></parameters></geometry>"
    );
    let (_dir, path) = write("expr.xml", xml.as_bytes());
    let run = validate(&path, &[]);
    assert_refused(&run, "E124");
}
