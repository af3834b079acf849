//! Front-end benchmark (issue 2): a generated file of 100,000 primitives, each a
//! subdomain, parsed + resolved + validated by geomc, against a bare roxmltree
//! parse of the same file in the same run. Target: geomc's throughput at least
//! 40% of roxmltree's; peak memory at most 10× the file size (measured on the
//! release binary in a child process).
//!
//! Run: `cargo bench --bench front_end` (add `-- --quick` for 10,000 primitives).

use std::fmt::Write as _;

// The allocator of the geomc binary, so the in-process figures match the command.
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;
use std::time::{Duration, Instant};

fn generate(count: usize) -> String {
    let mut xml = String::with_capacity(count * 260);
    xml.push_str("<geometry version=\"1\">\n  <parameters><parameter name=\"r\" value=\"0.3\"/></parameters>\n");
    let side = (count as f64).cbrt().ceil() as usize;
    for i in 0..count {
        let (x, y, z) = (
            (i % side) as f64 * 2.0,
            ((i / side) % side) as f64 * 2.0,
            (i / (side * side)) as f64 * 2.0,
        );
        let name = format!("p{i}");
        match i % 5 {
            0 => writeln!(xml, "  <sphere name=\"{name}\"><center x=\"{x}\" y=\"{y}\" z=\"{z}\"/><radius value=\"r\"/></sphere>"),
            1 => writeln!(
                xml,
                "  <parallelepiped name=\"{name}\"><first_point x=\"{x}\" y=\"{y}\" z=\"{z}\"/><second_point x=\"{}\" y=\"{}\" z=\"{}\"/></parallelepiped>",
                x + 0.5,
                y + 0.5,
                z + 0.5
            ),
            2 => writeln!(
                xml,
                "  <truncated_cone name=\"{name}\"><bottom_radius value=\"0.4\"/><top_radius value=\"0.2\"/><bottom_center x=\"{x}\" y=\"{y}\" z=\"{z}\"/><top_center x=\"{x}\" y=\"{y}\" z=\"{}\"/></truncated_cone>",
                z + 1.0
            ),
            3 => writeln!(
                xml,
                "  <ellipsoid name=\"{name}\"><center x=\"{x}\" y=\"{y}\" z=\"{z}\"/><semi_axes x=\"0.5\" y=\"0.3\" z=\"0.2\"/></ellipsoid>"
            ),
            _ => writeln!(
                xml,
                "  <torus name=\"{name}\"><center x=\"{x}\" y=\"{y}\" z=\"{z}\"/><major_radius value=\"0.5\"/><minor_radius value=\"r/2\"/></torus>"
            ),
        }
        .expect("writing to a String");
        writeln!(
            xml,
            "  <subdomain name=\"d{i}\"><solid ref=\"{name}\"/></subdomain>"
        )
        .expect("writing to a String");
    }
    xml.push_str("</geometry>\n");
    xml
}

fn best_of(runs: usize, mut f: impl FnMut()) -> Duration {
    (0..runs)
        .map(|_| {
            let start = Instant::now();
            f();
            start.elapsed()
        })
        .min()
        .unwrap_or_default()
}

fn main() {
    // `cargo bench` passes --bench; under `cargo test --all-targets` this runs as a
    // smoke test of the harness on a small model, so CI time stays bounded.
    let args: Vec<String> = std::env::args().collect();
    let smoke = !args.iter().any(|a| a == "--bench");
    let quick = args.iter().any(|a| a == "--quick");
    let count = match (smoke, quick) {
        (true, _) => 1_000,
        (false, true) => 10_000,
        (false, false) => 100_000,
    };
    let xml = generate(count);
    let mb = xml.len() as f64 / 1e6;
    println!("front end: {count} primitives as subdomains, {mb:.1} MB");

    let bare = best_of(3, || {
        let doc = roxmltree::Document::parse(&xml).expect("generated XML parses");
        std::hint::black_box(doc.root_element().children().count());
    });
    let options = geomc::driver::Options::default();
    let mut errors = 0;
    let full = best_of(3, || {
        let checked = geomc::driver::check_source(
            geomc::span::SourceFile::new("bench.xml", xml.clone()),
            &options,
        );
        errors = checked.diagnostics.error_count();
        std::hint::black_box(checked.lowered.map(|l| l.model.faces.len()));
    });
    assert_eq!(errors, 0, "the generated model must be valid");
    let ratio = bare.as_secs_f64() / full.as_secs_f64();
    println!(
        "  roxmltree parse only:            {:8.3} s  {:7.1} MB/s",
        bare.as_secs_f64(),
        mb / bare.as_secs_f64()
    );
    println!(
        "  geomc parse+resolve+validate:    {:8.3} s  {:7.1} MB/s",
        full.as_secs_f64(),
        mb / full.as_secs_f64()
    );
    println!(
        "  throughput ratio geomc/roxmltree: {ratio:.2} (target >= 0.40) {}",
        verdict(ratio >= 0.40)
    );

    // Peak memory of the real command on the same file.
    let dir = std::env::temp_dir().join(format!("geomc-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temporary folder");
    let path = dir.join("bench.xml");
    std::fs::write(&path, &xml).expect("write bench file");
    let exe = env!("CARGO_BIN_EXE_geomc");
    let output = std::process::Command::new(exe)
        .args(["validate", "--stats", "--format", "json"])
        .arg(&path)
        .output()
        .expect("run geomc");
    let stderr = String::from_utf8_lossy(&output.stderr);
    let peak: Option<f64> = stderr
        .lines()
        .find_map(|l| l.strip_prefix("peak memory: "))
        .and_then(|l| l.trim_end_matches(" bytes").parse().ok());
    match peak {
        Some(bytes) => {
            let ratio = bytes / xml.len() as f64;
            println!(
                "  geomc validate peak memory:      {:8.1} MB = {ratio:.1}x the file (target <= 10x) {}",
                bytes / 1e6,
                verdict(ratio <= 10.0)
            );
        }
        None => println!("  peak memory: not available on this system"),
    }
    let _ = std::fs::remove_dir_all(&dir);
}

fn verdict(ok: bool) -> &'static str {
    if ok { "PASS" } else { "FAIL" }
}
