//! 2D meshing benchmark (issue 6): geomc's 2D mesher against Shewchuk's
//! Triangle (PyPI `triangle`, benches/mesh2d_triangle.py) in the same run, on
//! the three domains at the same minimum angle: a disk with 50
//! holes, a polygon with 10,000 boundary vertices, and about a million
//! triangles from an area limit. Triangle gets geomc's own boundary nodes as
//! its PSLG, so both mesh the same boundary. Reports the best wall time of
//! 3 × `reps` single runs on each side (one slow start of a 10 ms run decided
//! the small cases' ratios before), their ratio, and the triangle-count ratio.
//!
//! The CPU columns are CPU time (user + system, every thread of the
//! process) per run, the best of 3 samples of `reps` back-to-back runs on
//! both sides: one run of the small cases lasts about 10 ms, too short for
//! one sample to read. The peer runs with one OpenBLAS thread: numpy's
//! OpenBLAS worker spins for about 0.1 s after `import numpy` and, on an
//! idle machine, its spinning was counted in Triangle's `process_time`
//! (0.017 s of CPU against 0.009 s of wall time on the disk).
//!
//! Run: `cargo bench --bench mesh2d` (`-- --quick`: smaller sizes). Needs
//! `pip install triangle` (./scripts/test.sh installs it).

// The allocator of the `geomc` command (as in the other benches), so
// meshing is timed as users run it: on the system allocator the polygon's
// meshing spent about a tenth of its time in `malloc` and `free`.
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

use geomc::driver::{Options, check_source};
use geomc::ir::Model;
use geomc::mesh::Mesh;
use geomc::meshing::{MeshOptions, mesh_model};
use geomc::span::SourceFile;
use std::fmt::Write as _;
use std::time::Instant;

const MIN_ANGLE: f64 = 28.0;

struct Case {
    name: &'static str,
    xml: String,
    max_area: Option<f64>,
    /// A point inside each hole, for Triangle.
    holes: Vec<[f64; 2]>,
    /// Runs per CPU sample (each sample's CPU time is divided by it).
    reps: usize,
}

fn disk_with_holes() -> Case {
    let mut xml = String::from(
        "<geometry version=\"1\" dimension=\"2\">\n<circle name=\"disk\"><center x=\"0\" y=\"0\"/><radius value=\"10\"/></circle>\n",
    );
    let mut holes = Vec::new();
    let mut k = 0;
    for i in -4..=4 {
        for j in -4..=4 {
            let (x, y) = (2.0 * i as f64, 2.0 * j as f64);
            if k < 50 && x.hypot(y) < 8.5 {
                writeln!(xml, "<circle name=\"h{k}\"><center x=\"{x}\" y=\"{y}\"/><radius value=\"0.4\"/></circle>").unwrap();
                holes.push([x, y]);
                k += 1;
            }
        }
    }
    xml.push_str("<subdomain name=\"plate\"><difference><solid ref=\"disk\"/>");
    for h in 0..k {
        write!(xml, "<solid ref=\"h{h}\"/>").unwrap();
    }
    xml.push_str("</difference></subdomain>\n</geometry>\n");
    Case {
        name: "disk with holes",
        xml,
        max_area: Some(0.02),
        holes,
        reps: 16,
    }
}

fn wiggly_polygon(n: usize) -> Case {
    let mut xml = String::from("<geometry version=\"1\" dimension=\"2\">\n<polygon name=\"star\">");
    for k in 0..n {
        let t = std::f64::consts::TAU * k as f64 / n as f64;
        let r = 1.0 + 0.1 * (20.0 * t).sin();
        write!(
            xml,
            "<vertex x=\"{:.12}\" y=\"{:.12}\"/>",
            r * t.cos(),
            r * t.sin()
        )
        .unwrap();
    }
    xml.push_str(
        "</polygon>\n<subdomain name=\"inside\"><solid ref=\"star\"/></subdomain>\n</geometry>\n",
    );
    Case {
        name: "polygon",
        xml,
        max_area: None,
        holes: Vec::new(),
        reps: (80_000 / n).clamp(1, 16),
    }
}

fn square(area: f64) -> Case {
    Case {
        name: "area-limited square",
        xml: "<geometry version=\"1\" dimension=\"2\"><rectangle name=\"sq\"><first_point x=\"0\" y=\"0\"/><second_point x=\"1\" y=\"1\"/></rectangle><subdomain name=\"inside\"><solid ref=\"sq\"/></subdomain></geometry>".into(),
        max_area: Some(area),
        holes: Vec::new(),
        reps: 1,
    }
}

/// The process's CPU time (user + system, all threads) in seconds, from
/// `clock_gettime(CLOCK_PROCESS_CPUTIME_ID)`: on a loaded machine wall time
/// also counts the waits for a core, CPU time does not.
fn cpu_seconds() -> f64 {
    #[repr(C)]
    struct Timespec {
        tv_sec: i64,
        tv_nsec: i64,
    }
    unsafe extern "C" {
        fn clock_gettime(clock: i32, tp: *mut Timespec) -> i32;
    }
    const CLOCK_PROCESS_CPUTIME_ID: i32 = 2;
    let mut t = Timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `t` is a valid, writable timespec (64-bit Linux layout).
    let ok = unsafe { clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &mut t) } == 0;
    if ok {
        t.tv_sec as f64 + t.tv_nsec as f64 * 1e-9
    } else {
        f64::NAN
    }
}

fn model(xml: &str) -> Model {
    let checked = check_source(SourceFile::new("bench.xml", xml), &Options::default());
    assert!(checked.is_valid(), "{:?}", checked.diagnostics.items);
    checked.lowered.expect("model").model
}

/// geomc's boundary nodes and segments as Triangle's PSLG.
fn pslg(mesh: &Mesh, case: &Case) -> String {
    let mut ids = std::collections::BTreeMap::new();
    let mut vertices = Vec::new();
    let mut segments = Vec::new();
    for edge in &mesh.edges {
        for w in edge.nodes.windows(2) {
            let mut id = |n: u32| {
                *ids.entry(n).or_insert_with(|| {
                    let p = mesh.nodes[n as usize];
                    vertices.push(format!("[{:.17},{:.17}]", p[0], p[1]));
                    vertices.len() - 1
                })
            };
            let (a, b) = (id(w[0]), id(w[1]));
            segments.push(format!("[{a},{b}]"));
        }
    }
    let holes: Vec<String> = case
        .holes
        .iter()
        .map(|h| format!("[{},{}]", h[0], h[1]))
        .collect();
    format!(
        "{{\"vertices\":[{}],\"segments\":[{}],\"holes\":[{}],\"min_angle\":{MIN_ANGLE},\"max_area\":{}}}",
        vertices.join(","),
        segments.join(","),
        holes.join(","),
        case.max_area.map_or("null".to_string(), |a| a.to_string())
    )
}

fn main() {
    // `cargo bench` passes --bench; under `cargo test --all-targets` this runs as a
    // small smoke run (debug build) so the test suite stays fast.
    let args: Vec<String> = std::env::args().collect();
    let smoke = !args.iter().any(|a| a == "--bench");
    let quick = smoke || args.iter().any(|a| a == "--quick");
    let cases = if smoke {
        vec![wiggly_polygon(200), square(1e-3)]
    } else if quick {
        vec![disk_with_holes(), wiggly_polygon(2_000), square(2e-5)]
    } else {
        vec![disk_with_holes(), wiggly_polygon(10_000), square(1e-6)]
    };
    let runs = if quick { 1 } else { 3 };
    let dir = std::env::temp_dir().join(format!("geomc-mesh2d-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    println!(
        "| domain | geomc s | geomc triangles | Triangle s | Triangle triangles | time ratio | count ratio | geomc CPU s/run | Triangle CPU s/run | CPU ratio | reps |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    for case in &cases {
        let model = model(&case.xml);
        let options = MeshOptions {
            min_angle_degrees: MIN_ANGLE,
            max_area: case.max_area,
            ..MeshOptions::default()
        };
        let mut best = f64::INFINITY;
        let mut best_cpu = f64::INFINITY;
        let mut mesh = None;
        // The small cases take about 10 ms: the best of `runs × reps` single
        // runs (the same for the peer) so one slow start does not decide.
        let reps = if smoke { 1 } else { case.reps };
        for _ in 0..runs * reps {
            let (start, cpu) = (Instant::now(), cpu_seconds());
            let m = mesh_model(&model, &options).expect("meshable");
            best = best.min(start.elapsed().as_secs_f64());
            best_cpu = best_cpu.min(cpu_seconds() - cpu);
            mesh = Some(m);
        }
        // CPU per run from samples of `reps` runs (with one rep, the runs above).
        if reps > 1 {
            best_cpu = f64::INFINITY;
            for _ in 0..runs {
                let cpu = cpu_seconds();
                for _ in 0..reps {
                    std::hint::black_box(mesh_model(&model, &options).expect("meshable"));
                }
                best_cpu = best_cpu.min((cpu_seconds() - cpu) / reps as f64);
            }
        }
        let mesh = mesh.expect("one run");
        let triangles: usize = mesh.faces.iter().map(|f| f.triangles.len()).sum();
        let input = dir.join("pslg.json");
        std::fs::write(&input, pslg(&mesh, case)).expect("write PSLG");
        let script = concat!(env!("CARGO_MANIFEST_DIR"), "/benches/mesh2d_triangle.py");
        let out = std::process::Command::new("python3")
            .arg(script)
            .arg(&input)
            .arg(runs.to_string())
            .arg(reps.to_string())
            // numpy's OpenBLAS worker spins after import: its CPU time is
            // no part of Triangle's (which is single-threaded).
            .env("OPENBLAS_NUM_THREADS", "1")
            .env("OMP_NUM_THREADS", "1")
            .output()
            .expect("run python3");
        if !out.status.success() {
            panic!(
                "the Triangle peer failed (pip install triangle): {}",
                String::from_utf8_lossy(&out.stderr)
            );
        }
        let peer: serde_json::Value = serde_json::from_slice(&out.stdout).expect("peer JSON");
        let (peer_s, peer_n, peer_cpu) = (
            peer["seconds"].as_f64().unwrap_or(f64::NAN),
            peer["triangles"].as_f64().unwrap_or(f64::NAN),
            peer["cpu_seconds"].as_f64().unwrap_or(f64::NAN),
        );
        println!(
            "| {} | {best:.3} | {triangles} | {peer_s:.3} | {peer_n} | {:.2} | {:.2} | {best_cpu:.4} | {peer_cpu:.4} | {:.2} | {reps} |",
            case.name,
            best / peer_s,
            triangles as f64 / peer_n,
            best_cpu / peer_cpu
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}
