//! Convert benchmark (issue 4): a binary STL of 5 million triangles (a UV
//! sphere) converted to GLB and to MSH 4.1 binary, and a 2-million-triangle
//! MSH converted to GLB, by the release `geomc convert` and by peers in the
//! same run (`benches/peers/convert_peers.py`: meshio 5.3.5, and trimesh
//! 5.2.0 where meshio has no glTF writer, with numpy, scipy and networkx
//! pinned in `benches/peers/requirements.txt`). Targets: at least 10× the
//! peers' speed, peak memory at most 3× the input file.
//!
//! Times are medians of repeated runs (geomc 5, peers 3; see the peer
//! script), with the first runs' ratio beside them as before.
//!
//! Run: `cargo bench --bench convert` (add `-- --quick` for 500k / 200k
//! triangles). Under `cargo test --all-targets` it is a smoke run of geomc
//! alone on a small sphere.

use std::io::Write;
use std::path::Path;
use std::process::Command;

/// A closed UV sphere with about `triangles` triangles as binary STL.
fn write_sphere_stl(path: &Path, triangles: usize) -> usize {
    let rings = ((triangles as f64 / 3.2).sqrt() as usize).max(3);
    let segments = (triangles / (2 * rings)).max(3);
    let point = |i: usize, j: usize| -> [f32; 3] {
        let theta = std::f64::consts::PI * i as f64 / rings as f64;
        let phi = 2.0 * std::f64::consts::PI * (j % segments) as f64 / segments as f64;
        [
            (theta.sin() * phi.cos()) as f32,
            (theta.sin() * phi.sin()) as f32,
            theta.cos() as f32,
        ]
    };
    let mut tris: Vec<[[f32; 3]; 3]> = Vec::with_capacity(2 * rings * segments);
    for i in 0..rings {
        for j in 0..segments {
            let (a, b, c, d) = (
                point(i, j),
                point(i + 1, j),
                point(i + 1, j + 1),
                point(i, j + 1),
            );
            if i > 0 {
                tris.push([a, b, d]);
            }
            if i + 1 < rings {
                tris.push([b, c, d]);
            }
        }
    }
    let file = std::fs::File::create(path).expect("create STL");
    let mut w = std::io::BufWriter::new(file);
    w.write_all(&[b' '; 80]).expect("write");
    w.write_all(&(tris.len() as u32).to_le_bytes())
        .expect("write");
    for t in &tris {
        w.write_all(&[0u8; 12]).expect("write");
        for p in t {
            for c in p {
                w.write_all(&c.to_le_bytes()).expect("write");
            }
        }
        w.write_all(&[0, 0]).expect("write");
    }
    w.flush().expect("flush");
    tris.len()
}

fn geomc(args: &[&str]) {
    let out = Command::new(env!("CARGO_BIN_EXE_geomc"))
        .args(args)
        .output()
        .expect("run geomc");
    assert!(
        out.status.success(),
        "geomc {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let smoke = !args.iter().any(|a| a == "--bench");
    let quick = args.iter().any(|a| a == "--quick");
    let (big, mid) = match (smoke, quick) {
        (true, _) => (20_000, 10_000),
        (false, true) => (500_000, 200_000),
        (false, false) => (5_000_000, 2_000_000),
    };
    let dir = std::env::temp_dir().join(format!("geomc-convert-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temporary folder");
    let s = |p: &Path| p.to_str().expect("utf-8 path").to_string();
    let big_stl = dir.join("big.stl");
    let n_big = write_sphere_stl(&big_stl, big);
    let mid_stl = dir.join("mid.stl");
    let n_mid = write_sphere_stl(&mid_stl, mid);
    let mid_msh = dir.join("mid.msh");
    geomc(&["convert", "--binary", &s(&mid_stl), &s(&mid_msh)]);
    let size = |p: &Path| std::fs::metadata(p).map(|m| m.len()).unwrap_or(0) as f64;
    println!(
        "convert: {n_big} triangles as binary STL ({:.0} MB), {n_mid} as binary MSH 4.1 ({:.0} MB)",
        size(&big_stl) / 1e6,
        size(&mid_msh) / 1e6
    );
    if smoke {
        geomc(&["convert", &s(&big_stl), &s(&dir.join("g.glb"))]);
        geomc(&["convert", "--binary", &s(&big_stl), &s(&dir.join("g.msh"))]);
        geomc(&["convert", &s(&mid_msh), &s(&dir.join("g2.glb"))]);
        println!("  smoke run: geomc only (cargo bench --bench convert measures the peers)");
        let _ = std::fs::remove_dir_all(&dir);
        return;
    }
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("benches/peers/convert_peers.py");
    let out = Command::new("python3")
        .arg(&script)
        .arg(env!("CARGO_BIN_EXE_geomc"))
        .arg(&dir)
        .output()
        .expect("run python3 (pip install -r benches/peers/requirements.txt)");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).expect("peer JSON");
    print_environment(&report["environment"]);
    let inputs = [
        ("stl_to_glb", &big_stl),
        ("stl_to_msh41_binary", &big_stl),
        ("msh_to_glb", &mid_msh),
    ];
    for (case, input) in inputs {
        let tools = &report[case];
        let g = &tools["geomc"];
        let gs = g["seconds"].as_f64().unwrap_or(f64::NAN);
        let g1 = g["first_seconds"].as_f64().unwrap_or(f64::NAN);
        let gm = g["peak_bytes"].as_f64().unwrap_or(f64::NAN);
        println!("  {case}:");
        println!(
            "    geomc           {gs:8.3} s  peak {:7.0} MB = {:.2}x the input (target <= 3x) {}",
            gm / 1e6,
            gm / size(input),
            verdict(gm / size(input) <= 3.0)
        );
        for (tool, v) in tools.as_object().into_iter().flatten() {
            if tool == "geomc" {
                continue;
            }
            let ps = v["seconds"].as_f64().unwrap_or(f64::NAN);
            let p1 = v["first_seconds"].as_f64().unwrap_or(f64::NAN);
            let pm = v["peak_bytes"].as_f64().unwrap_or(f64::NAN);
            println!(
                "    {tool:<15} {ps:8.3} s  peak {:7.0} MB = {:.2}x the input; geomc is {:.1}x faster (target >= 10x) {}",
                pm / 1e6,
                pm / size(input),
                ps / gs,
                verdict(ps / gs >= 10.0)
            );
            // The single-run ratio the bench gave before it took medians.
            println!(
                "    (first runs alone: geomc {g1:.3} s, {tool} {p1:.3} s, {:.1}x)",
                p1 / g1
            );
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The peers' package versions, and a warning when they are not the pinned
/// ones: the peers' times (and so the ratios) depend on them.
fn print_environment(env: &serde_json::Value) {
    let versions: Vec<String> = env["versions"]
        .as_object()
        .into_iter()
        .flatten()
        .map(|(name, v)| format!("{name} {}", v.as_str().unwrap_or("missing")))
        .collect();
    println!(
        "  peers on Python {}: {}",
        env["python"].as_str().unwrap_or("?"),
        versions.join(", ")
    );
    if env["pinned"].as_bool() != Some(true) {
        println!(
            "  WARNING: not the pinned peer set-up (benches/peers/requirements.txt): {}; the ratios are not comparable with the recorded ones",
            env["differs"]
                .as_array()
                .into_iter()
                .flatten()
                .filter_map(|d| d.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
}

fn verdict(ok: bool) -> &'static str {
    if ok { "PASS" } else { "FAIL" }
}
