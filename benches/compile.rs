//! Compile benchmark (issue 3), ratios against peers measured in the same run:
//! - meshing a unit sphere and paper 001's seven balls (as primitives, each
//!   ball meshed on its own) at about gmsh's triangle count, against gmsh's
//!   `mesh.generate(2)` of the same solids (`benches/peers/gmsh_surface.py`,
//!   one thread, CPU seconds on both sides, so a loaded machine skews neither);
//! - writer throughput for GLB, binary STL and binary MSH (MB/s into memory
//!   and into a file), against a plain `memcpy` of the same byte count;
//! - peak memory of `geomc compile` to each binary format against the size
//!   of the file it writes (`/usr/bin/time -f %M`).
//!
//! Targets: meshing ≥ 50× faster than gmsh, writers ≥ 500 MB/s, peak memory
//! ≤ 2× the output.
//!
//! Run: `cargo bench --bench compile` (`-- writers` for the writers and
//! memory only). Under `cargo test --all-targets` it is
//! a smoke run: a coarse sphere, every binary writer, no peers.

// The allocator of the `geomc` command, so meshing is timed as users run it.
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

use geomc::driver::{Options, check_source};
use geomc::formats::{Encoding, WRITERS, WriteOptions, write_mesh_file};
use geomc::ir::Model;
use geomc::mesh::Mesh;
use geomc::meshing::{MeshOptions, Tolerance, mesh_model, quality};
use geomc::span::SourceFile;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

const SEVEN: &str = r#"<geometry version="1">
  <sphere name="b0"><center x="0" y="0" z="0"/><radius value="0.7"/></sphere>
  <sphere name="b1"><center x="0.7" y="0" z="0"/><radius value="0.3"/></sphere>
  <sphere name="b2"><center x="-0.7" y="0" z="0"/><radius value="0.3"/></sphere>
  <sphere name="b3"><center x="0" y="0.7" z="0"/><radius value="0.3"/></sphere>
  <sphere name="b4"><center x="0" y="-0.7" z="0"/><radius value="0.3"/></sphere>
  <sphere name="b5"><center x="0" y="0" z="0.7"/><radius value="0.3"/></sphere>
  <sphere name="b6"><center x="0" y="0" z="-0.7"/><radius value="0.3"/></sphere>
</geometry>"#;

const SPHERE: &str = r#"<geometry version="1">
  <sphere name="ball"><center x="0" y="0" z="0"/><radius value="1"/></sphere>
  <subdomain name="inside"><solid ref="ball"/></subdomain>
</geometry>"#;

fn model(xml: &str) -> Model {
    let checked = check_source(SourceFile::new("bench.xml", xml), &Options::default());
    assert!(
        !checked.diagnostics.has_errors(),
        "the bench model is valid"
    );
    checked.lowered.expect("a model").model
}

/// CPU seconds of this process so far (utime + stime from /proc/self/stat);
/// wall time where that is unavailable.
fn cpu_seconds(origin: Instant) -> f64 {
    let ticks = std::fs::read_to_string("/proc/self/stat")
        .ok()
        .and_then(|s| {
            // Fields after the parenthesised command name; utime, stime are 14, 15.
            let rest = s.rsplit_once(')')?.1;
            let fields: Vec<&str> = rest.split_whitespace().collect();
            Some(fields.get(11)?.parse::<f64>().ok()? + fields.get(12)?.parse::<f64>().ok()?)
        });
    match ticks {
        Some(t) => t / 100.0,
        None => origin.elapsed().as_secs_f64(),
    }
}

fn mesh_with(model: &Model, tolerance: f64) -> Mesh {
    let options = MeshOptions {
        tolerance: Tolerance::Absolute(tolerance),
        ..MeshOptions::default()
    };
    mesh_model(model, &options).expect("meshable")
}

fn triangles(mesh: &Mesh) -> usize {
    mesh.faces.iter().map(|f| f.triangles.len()).sum()
}

/// Best CPU time of `runs` runs of meshing, and the last mesh.
fn time_meshing(model: &Model, tolerance: f64, runs: usize) -> (f64, Mesh) {
    let origin = Instant::now();
    let mut best = f64::INFINITY;
    let mut mesh = Mesh::default();
    for _ in 0..runs {
        let start = cpu_seconds(origin);
        mesh = mesh_with(model, tolerance);
        best = best.min(cpu_seconds(origin) - start);
    }
    (best, mesh)
}

struct Peer {
    cpu_seconds: f64,
    triangles: usize,
    min_angle: f64,
}

fn gmsh(model: &str, size: f64) -> Option<Peer> {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("benches/peers/gmsh_surface.py");
    let output = Command::new("python3")
        .arg(script)
        .arg(model)
        .arg(size.to_string())
        .output()
        .ok()?;
    if !output.status.success() {
        eprintln!(
            "gmsh peer failed (pip install gmsh numpy): {}",
            String::from_utf8_lossy(&output.stderr)
        );
        return None;
    }
    let json: serde_json::Value = serde_json::from_slice(&output.stdout).ok()?;
    Some(Peer {
        cpu_seconds: json["cpu_seconds"].as_f64()?,
        triangles: json["triangles"].as_u64()? as usize,
        min_angle: json["min_angle"].as_f64()?,
    })
}

/// Meshes `xml` at the tolerance whose triangle count is closest to
/// `target` (triangle counts scale about as 1 / tolerance), then times it.
fn versus_gmsh(name: &str, xml: &str, peer_model: &str, size: f64) -> Option<f64> {
    let peer = gmsh(peer_model, size)?;
    let model = model(xml);
    let mut tolerance = 1e-3;
    for _ in 0..4 {
        let n = triangles(&mesh_with(&model, tolerance));
        let ratio = n as f64 / peer.triangles as f64;
        if (ratio - 1.0).abs() < 0.03 {
            break;
        }
        tolerance *= ratio;
    }
    let (seconds, mesh) = time_meshing(&model, tolerance, 3);
    let q = quality(&mesh);
    let speedup = peer.cpu_seconds / seconds;
    println!(
        "  {name}: geomc {:7.3} s CPU, {:7} triangles, min angle {:4.1}° (tolerance {tolerance:.2e})",
        seconds,
        triangles(&mesh),
        q.min_angle
    );
    println!(
        "  {name}: gmsh  {:7.3} s CPU, {:7} triangles, min angle {:4.1}° (size {size})",
        peer.cpu_seconds, peer.triangles, peer.min_angle
    );
    println!(
        "  {name}: geomc is {speedup:.1}x faster than gmsh (target >= 50x) {}",
        verdict(speedup >= 50.0)
    );
    Some(speedup)
}

fn binary() -> WriteOptions {
    WriteOptions {
        encoding: Some(Encoding::Binary),
        ..WriteOptions::default()
    }
}

/// MB/s of each binary writer into memory and into a file.
fn writers(mesh: &Mesh, dir: &Path, runs: usize) {
    let copy_speed = {
        let source = vec![7u8; 64 << 20];
        let start = Instant::now();
        let mut target = Vec::with_capacity(source.len());
        target.extend_from_slice(&source);
        std::hint::black_box(&target);
        source.len() as f64 / 1e6 / start.elapsed().as_secs_f64()
    };
    println!("  memcpy of 64 MB: {copy_speed:.0} MB/s");
    for ext in ["glb", "stl", "msh"] {
        let writer = WRITERS
            .iter()
            .find(|w| w.extensions().contains(&ext))
            .expect("a writer");
        let mut size = 0;
        let mut best = f64::INFINITY;
        for _ in 0..runs {
            let mut out = Vec::new();
            let start = Instant::now();
            writer.write(mesh, &binary(), &mut out).expect("writes");
            best = best.min(start.elapsed().as_secs_f64());
            size = out.len();
            std::hint::black_box(&out);
        }
        let path = dir.join(format!("bench.{ext}"));
        let mut file_best = f64::INFINITY;
        for _ in 0..runs {
            let start = Instant::now();
            write_mesh_file(&path, mesh, &binary()).expect("writes a file");
            file_best = file_best.min(start.elapsed().as_secs_f64());
        }
        let mb = size as f64 / 1e6;
        println!(
            "  {ext:>3} binary: {mb:7.1} MB, {:6.0} MB/s into memory, {:6.0} MB/s into a file (target >= 500) {}",
            mb / best,
            mb / file_best,
            verdict(mb / best >= 500.0)
        );
    }
}

/// Peak resident memory of `geomc compile` writing one binary output,
/// against that output's size.
fn memory(input: &Path, tolerance: f64, dir: &Path) {
    for ext in ["glb", "stl", "msh"] {
        let output: PathBuf = dir.join(format!("peak.{ext}"));
        let run = Command::new("/usr/bin/time")
            .args(["-f", "%M"])
            .arg(env!("CARGO_BIN_EXE_geomc"))
            .arg("compile")
            .arg(input)
            .args([
                "--binary",
                "-q",
                "--tolerance",
                &tolerance.to_string(),
                "-o",
            ])
            .arg(&output)
            .output();
        let Ok(run) = run else {
            println!("  peak memory: /usr/bin/time is not available");
            return;
        };
        let stderr = String::from_utf8_lossy(&run.stderr);
        let peak_kb: Option<f64> = stderr.lines().last().and_then(|l| l.trim().parse().ok());
        let size = std::fs::metadata(&output).map(|m| m.len()).unwrap_or(0) as f64;
        match peak_kb {
            Some(kb) if size > 0.0 => {
                let ratio = kb * 1024.0 / size;
                println!(
                    "  compile to {ext}: peak {:6.1} MB for a {:6.1} MB file = {ratio:.1}x (target <= 2x) {}",
                    kb * 1024.0 / 1e6,
                    size / 1e6,
                    verdict(ratio <= 2.0)
                );
            }
            _ => println!("  compile to {ext}: not measured ({stderr})"),
        }
    }
}

fn main() {
    // As the `geomc` binary does: the meshing times include returning memory.
    let args: Vec<String> = std::env::args().collect();
    let smoke = !args.iter().any(|a| a == "--bench");
    let dir = std::env::temp_dir().join(format!("geomc-compile-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temporary folder");
    if smoke {
        let mesh = mesh_with(&model(SPHERE), 0.02);
        assert!(triangles(&mesh) > 100);
        writers(&mesh, &dir, 1);
        let _ = std::fs::remove_dir_all(&dir);
        return;
    }
    // `-- --bench writers` runs only the writers and the memory part.
    let writers_only = args.iter().any(|a| a == "writers");
    if !writers_only {
        println!("compile: meshing against gmsh (CPU seconds, one thread each)");
        versus_gmsh("sphere", SPHERE, "sphere", 0.02);
        versus_gmsh("seven balls", SEVEN, "seven", 0.0137);
    }

    println!("compile: binary writers, seven balls at 2e-5 tolerance");
    let model = model(SEVEN);
    let tolerance = 2e-5;
    let mesh = mesh_with(&model, tolerance);
    println!(
        "  mesh: {} nodes, {} triangles",
        mesh.nodes.len(),
        triangles(&mesh)
    );
    writers(&mesh, &dir, 3);
    let input = dir.join("seven.xml");
    std::fs::write(&input, SEVEN).expect("write the input");
    memory(&input, tolerance, &dir);
    let _ = std::fs::remove_dir_all(&dir);
}

fn verdict(ok: bool) -> &'static str {
    if ok { "PASS" } else { "FAIL" }
}
