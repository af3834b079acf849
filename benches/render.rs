//! Render benchmark (issue 8): a 1-million-triangle torus rendered to a
//! 1024×1024 PNG with the default options, against reading the same mesh from
//! GLB (written by geomc, read with the `gltf` crate: file, JSON, buffer,
//! positions and indices) in the same run. Target: render time below read
//! time. Also the SVG hidden-line drawing of a 50,000-triangle torus.
//!
//! The machine these runs shared was loaded when this was written (load
//! average 15–20 on 2 cores), so one wall-clock timing of either side swung
//! several-fold. Two measures,
//! each the median of repetitions made alternately (read, render, read,
//! render, …) so both sides see the same load:
//! - CPU time, summed over every thread of the process (`/proc/self/task/*/
//!   schedstat`): the render's CPU time over all its threads bounds its wall
//!   time on an idle machine, and the single-threaded read's CPU time is its
//!   wall time there, so a CPU ratio below 1 means the render is faster than
//!   the read on any idle machine with one core or more;
//! - wall time, printed beside it with every pair's own ratio and the load.
//!
//! Then each step again in a fresh process (cold memory, as one CLI run); the
//! read with geomc's own reader followed by the render in one fresh process,
//! as one `geomc render torus.glb` run meets them; and each side warm in a
//! process of its own (repeated there, so it meets only its own freed memory).
//!
//! The verdict is issue 8's target in its own words, on the last measure:
//! the render's time (wall) under the read's, each warm in a process of its
//! own (the read's fastest form; in the alternated rounds one side's
//! allocations change the other's page faults, session 24). The machine is
//! quiet now, so wall times are stable; the CPU ratio beside it is the
//! stricter bound for a machine of one core (which the issue does not ask),
//! printed and recorded but not the verdict (session 25).
//!
//! Run: `cargo bench --bench render`. Under `cargo test --all-targets` it runs
//! as a smoke test on small meshes.

// The allocator of the `geomc` command, so the render is timed as users run it
// (the read gets it too).
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

use geomc::formats::read::{ReadLimits, load_mesh_limited};
use geomc::formats::{WriteOptions, write_mesh_file};
use geomc::mesh::{Mesh, MeshFace, MeshFragment, MeshSubdomain};
use geomc::render::{Edges, RenderOptions, render_png, render_svg};
use std::time::{Duration, Instant};

/// A torus of `nu × nv × 2` triangles, outward-oriented, as one face bounding one subdomain.
fn torus(nu: usize, nv: usize) -> Mesh {
    let (big, small) = (1.0, 0.35);
    let mut nodes = Vec::with_capacity(nu * nv);
    for i in 0..nu {
        let u = i as f64 / nu as f64 * std::f64::consts::TAU;
        for j in 0..nv {
            let v = j as f64 / nv as f64 * std::f64::consts::TAU;
            let ring = big + small * v.cos();
            nodes.push([ring * u.cos(), ring * u.sin(), small * v.sin()]);
        }
    }
    let id = |i: usize, j: usize| ((i % nu) * nv + (j % nv)) as u32;
    let mut triangles = Vec::with_capacity(2 * nu * nv);
    for i in 0..nu {
        for j in 0..nv {
            // Counter-clockwise seen from outside: u then v turns outward.
            triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    Mesh {
        dimension: 3,
        nodes,
        faces: vec![MeshFace {
            name: "torus".into(),
            triangles,
            boundary: Vec::new(),
        }],
        subdomains: vec![MeshSubdomain {
            name: "ring".into(),
            material: None,
            faces: vec![(0, true)],
        }],
        fragments: vec![MeshFragment {
            name: "surface".into(),
            subdomain: 0,
            other: None,
            faces: vec![0],
            edges: Vec::new(),
        }],
        ..Mesh::default()
    }
}

fn best_of<T>(runs: usize, mut f: impl FnMut() -> T) -> (Duration, T) {
    let mut best = Duration::MAX;
    let mut last = None;
    for _ in 0..runs {
        let start = Instant::now();
        let value = f();
        best = best.min(start.elapsed());
        last = Some(value);
    }
    (best, last.expect("at least one run"))
}

/// Reads a GLB's first primitive with the gltf crate: positions and indices.
fn read_glb(path: &std::path::Path) -> (Vec<[f32; 3]>, Vec<u32>) {
    let bytes = std::fs::read(path).expect("read GLB");
    let gltf = gltf::Gltf::from_slice(&bytes).expect("parse GLB");
    let blob = gltf.blob.as_deref().expect("GLB binary chunk");
    let mut positions = Vec::new();
    let mut indices = Vec::new();
    for mesh in gltf.meshes() {
        for primitive in mesh.primitives() {
            let reader = primitive.reader(|_| Some(blob));
            let base = positions.len() as u32;
            if let Some(p) = reader.read_positions() {
                positions.extend(p);
            }
            if let Some(i) = reader.read_indices() {
                indices.extend(i.into_u32().map(|i| i + base));
            }
        }
    }
    (positions, indices)
}

/// `--child read GLB [REPEATS]` or `--child render NU NV ANTIALIAS [REPEATS]`: one
/// step timed in a fresh process, as `geomc render` meets it (no memory left warm by
/// the other side), repeated REPEATS times (default 1); prints the medians of its wall
/// and CPU seconds. Repeated, the step runs warm in a process of its own: its
/// allocations meet only its own freed memory, not the other side's.
fn child(args: &[String]) {
    let parse = |v: &String| v.parse::<u32>().expect("a count");
    let repeats = |r: &[String]| r.first().map_or(1, parse).max(1);
    let mut walls = Vec::new();
    let mut cpus = Vec::new();
    match args {
        [what, path, r @ ..] if what == "read" && r.len() <= 1 => {
            for _ in 0..repeats(r) {
                let (wall, cpu, _) = timed(|| read_glb(std::path::Path::new(path)));
                walls.push(wall);
                cpus.push(cpu);
            }
        }
        [what, nu, nv, aa, r @ ..] if what == "render" && r.len() <= 1 => {
            let mesh = torus(parse(nu) as usize, parse(nv) as usize);
            let options = RenderOptions {
                width: 1024,
                height: 1024,
                antialias: parse(aa),
                ..RenderOptions::default()
            };
            for _ in 0..repeats(r) {
                let (wall, cpu, _) = timed(|| render_png(&mesh, &options).expect("renders"));
                walls.push(wall);
                cpus.push(cpu);
            }
        }
        [what, path] if what == "run" => return one_run(std::path::Path::new(path)),
        _ => panic!(
            "--child read GLB [REPEATS] | --child render NU NV ANTIALIAS [REPEATS] | --child run GLB"
        ),
    };
    println!("{} {}", median(&walls), median(&cpus));
}

/// `--child run GLB`: what one `geomc render GLB -o out.png --size 1024x1024`
/// does, in this fresh process: the mesh read with geomc's own reader (with
/// its surface checks), then rendered. Prints the read's wall and CPU seconds,
/// then the render's.
fn one_run(path: &std::path::Path) {
    let (read_wall, read_cpu, loaded) =
        timed(|| load_mesh_limited(path, None, &ReadLimits::default()).expect("reads the GLB"));
    let options = RenderOptions {
        width: 1024,
        height: 1024,
        ..RenderOptions::default()
    };
    let (wall, cpu, _) = timed(|| render_png(&loaded.mesh, &options).expect("renders"));
    println!("{read_wall} {read_cpu} {wall} {cpu}");
}

/// Runs one `--child` step of this benchmark in a fresh process: (wall, CPU) seconds.
fn in_fresh_process(args: &[&str]) -> (f64, f64) {
    let v = child_output(args);
    (v[0], v[1])
}

/// The seconds a `--child` step printed, run in a fresh process.
fn child_output(args: &[&str]) -> Vec<f64> {
    let exe = std::env::current_exe().expect("the benchmark's own path");
    let out = std::process::Command::new(exe)
        .arg("--child")
        .args(args)
        .output()
        .expect("runs itself");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    let v: Vec<f64> = text
        .split_whitespace()
        .map(|v| v.parse::<f64>().expect("seconds"))
        .collect();
    assert!(v.len() >= 2, "a wall and a CPU time: {text}");
    v
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if let Some(at) = args.iter().position(|a| a == "--child") {
        return child(&args[at + 1..]);
    }
    let smoke = !args.iter().any(|a| a == "--bench");
    let (nu, nv, svg_nu, svg_nv, runs, reps) = if smoke {
        (100, 50, 50, 25, 1, 1)
    } else {
        (1000, 500, 250, 100, 3, 9)
    };
    let mesh = torus(nu, nv);
    let n_tris = mesh.faces[0].triangles.len();
    let dir = std::env::temp_dir().join(format!("geomc-render-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temporary folder");
    let glb = dir.join("torus.glb");
    write_mesh_file(&glb, &mesh, &WriteOptions::default()).expect("write GLB");
    let mb = std::fs::metadata(&glb).map(|m| m.len()).unwrap_or(0) as f64 / 1e6;
    println!(
        "render: torus of {n_tris} triangles, GLB {mb:.1} MB, {} threads",
        rayon::current_num_threads()
    );

    let options = RenderOptions {
        width: 1024,
        height: 1024,
        ..RenderOptions::default()
    };
    let aa1 = RenderOptions {
        antialias: 1,
        ..options.clone()
    };
    let load_before = load_average();
    // Alternate: read, render, render --antialias 1, and again.
    let (mut reads, mut renders, mut renders_aa1) = (Vec::new(), Vec::new(), Vec::new());
    let mut png_len = 0;
    let (mut read_cpu, mut render_cpu, mut aa1_cpu) = (Vec::new(), Vec::new(), Vec::new());
    for _ in 0..reps {
        let (t, c, (positions, indices)) = timed(|| read_glb(&glb));
        assert!(indices.len() >= 3 * n_tris);
        assert!(positions.len() >= mesh.nodes.len());
        reads.push(t);
        read_cpu.push(c);
        let (t, c, (png, _)) = timed(|| render_png(&mesh, &options).expect("renders"));
        png_len = png.len();
        renders.push(t);
        render_cpu.push(c);
        let (t, c, _) = timed(|| render_png(&mesh, &aa1).expect("renders"));
        renders_aa1.push(t);
        aa1_cpu.push(c);
    }
    // The same, each step in a fresh process (cold memory, as one CLI run).
    let (mut cold_read, mut cold_render) = (Vec::new(), Vec::new());
    let glb_arg = glb.to_string_lossy().to_string();
    let (nu_arg, nv_arg) = (nu.to_string(), nv.to_string());
    for _ in 0..reps {
        cold_read.push(in_fresh_process(&["read", &glb_arg]));
        cold_render.push(in_fresh_process(&["render", &nu_arg, &nv_arg, "2"]));
    }
    // And each side warm, but in a process of its own (`own` repetitions
    // each, their medians): in the alternated rounds above the two sides
    // share one allocator, so one side's freed memory changes the other's
    // page faults (a render that frees less leaves the read faster).
    let own = if smoke { "1" } else { "7" };
    let (mut own_read, mut own_render) = (Vec::new(), Vec::new());
    for _ in 0..reps.min(5) {
        own_read.push(in_fresh_process(&["read", &glb_arg, own]));
        own_render.push(in_fresh_process(&["render", &nu_arg, &nv_arg, "2", own]));
    }
    // And as one `geomc render GLB` run meets it: geomc's own reader, then
    // the render, in one fresh process.
    let runs_of_cli: Vec<Vec<f64>> = (0..reps)
        .map(|_| child_output(&["run", &glb_arg]))
        .collect();
    let load_after = load_average();
    let pairs = |a: &[f64], b: &[f64]| {
        (a.iter().zip(b))
            .map(|(r, p)| format!("{:.2}", p / r))
            .collect::<Vec<_>>()
            .join(" ")
    };
    println!(
        "  load average before / after: {load_before} / {load_after}; {reps} alternated repetitions, medians (min)"
    );
    println!("  {:<46} {:>16} {:>16}", "", "CPU, all threads", "wall");
    let row = |what: &str, cpu: &[f64], wall: &[f64]| {
        println!(
            "  {what:<46} {:>7.3} ({:.3}) s {:>7.3} ({:.3}) s",
            median(cpu),
            min(cpu),
            median(wall),
            min(wall)
        )
    };
    row(
        "gltf crate: read GLB (positions + indices)",
        &read_cpu,
        &reads,
    );
    row(
        "geomc render 1024x1024 PNG (default, 2x2 AA)",
        &render_cpu,
        &renders,
    );
    row(
        "geomc render 1024x1024 PNG, --antialias 1",
        &aa1_cpu,
        &renders_aa1,
    );
    println!("  PNG {:.1} kB", png_len as f64 / 1e3);
    println!(
        "  render / read of each pair: CPU {}; wall {}",
        pairs(&read_cpu, &render_cpu),
        pairs(&reads, &renders)
    );
    let wall_of = |v: &[(f64, f64)]| v.iter().map(|p| p.0).collect::<Vec<_>>();
    let cpu_of = |v: &[(f64, f64)]| v.iter().map(|p| p.1).collect::<Vec<_>>();
    println!("  each step in a fresh process:");
    row(
        "gltf crate: read GLB (positions + indices)",
        &cpu_of(&cold_read),
        &wall_of(&cold_read),
    );
    row(
        "geomc render 1024x1024 PNG (default, 2x2 AA)",
        &cpu_of(&cold_render),
        &wall_of(&cold_render),
    );
    println!(
        "  render / read, fresh processes, medians: CPU {:.2}; wall {:.2}",
        median(&cpu_of(&cold_render)) / median(&cpu_of(&cold_read)),
        median(&wall_of(&cold_render)) / median(&wall_of(&cold_read)),
    );
    println!(
        "  one `geomc render` run (geomc's reader with its checks, then the render; fresh processes):"
    );
    let column = |k: usize| runs_of_cli.iter().map(|v| v[k]).collect::<Vec<_>>();
    row("geomc: read GLB", &column(1), &column(0));
    row(
        "geomc render 1024x1024 PNG (default, 2x2 AA)",
        &column(3),
        &column(2),
    );
    println!(
        "  render / read, one geomc run, medians: CPU {:.2}; wall {:.2}",
        median(&column(3)) / median(&column(1)),
        median(&column(2)) / median(&column(0)),
    );
    println!("  each side warm in a process of its own ({own} repetitions, their medians):");
    row(
        "gltf crate: read GLB (positions + indices)",
        &cpu_of(&own_read),
        &wall_of(&own_read),
    );
    row(
        "geomc render 1024x1024 PNG (default, 2x2 AA)",
        &cpu_of(&own_render),
        &wall_of(&own_render),
    );
    let own_ratio = median(&cpu_of(&own_render)) / median(&cpu_of(&own_read));
    println!(
        "  render / read, alternated medians: CPU {:.2}; wall {:.2}; --antialias 1 CPU {:.2}",
        median(&render_cpu) / median(&read_cpu),
        median(&renders) / median(&reads),
        median(&aa1_cpu) / median(&read_cpu)
    );
    let own_wall = median(&wall_of(&own_render)) / median(&wall_of(&own_read));
    println!(
        "  render / read, warm in own processes, medians: CPU {own_ratio:.2} (one-core bound, below 1: {}); wall {own_wall:.2}",
        if own_ratio < 1.0 { "yes" } else { "no" },
    );
    println!(
        "  verdict: render time / GLB read time, warm in own processes (wall medians) {own_wall:.2} (target < 1) {}",
        verdict(own_wall < 1.0),
    );

    let small = torus(svg_nu, svg_nv);
    let svg_tris = small.faces[0].triangles.len();
    let svg_options = RenderOptions {
        width: 1024,
        height: 1024,
        ..RenderOptions::default()
    };
    let (svg_time, drawing) = best_of(runs, || render_svg(&small, &svg_options).expect("draws"));
    let (svg_all, all) = best_of(runs, || {
        render_svg(
            &small,
            &RenderOptions {
                edges: Edges::All,
                ..svg_options.clone()
            },
        )
        .expect("draws")
    });
    let (png_small, _) = best_of(runs, || render_png(&small, &svg_options).expect("renders"));
    println!(
        "  SVG hidden lines, {svg_tris} triangles, silhouettes: {:8.3} s ({} pieces); every edge: {:8.3} s ({} pieces); PNG of the same: {:8.3} s",
        svg_time.as_secs_f64(),
        drawing.segments,
        svg_all.as_secs_f64(),
        all.segments,
        png_small.as_secs_f64()
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// Wall and CPU seconds of `f`, and its value.
fn timed<T>(f: impl FnOnce() -> T) -> (f64, f64, T) {
    let cpu = process_cpu_seconds();
    let start = Instant::now();
    let value = f();
    let wall = start.elapsed().as_secs_f64();
    (wall, process_cpu_seconds() - cpu, value)
}

/// CPU time of every thread of this process so far (rayon's workers
/// included), in seconds: the first field of each task's `schedstat` is its
/// time on a CPU in nanoseconds. Zero where `/proc` is missing.
fn process_cpu_seconds() -> f64 {
    let Ok(tasks) = std::fs::read_dir("/proc/self/task") else {
        return 0.0;
    };
    let mut ns: u64 = 0;
    for task in tasks.flatten() {
        if let Ok(stat) = std::fs::read_to_string(task.path().join("schedstat")) {
            ns += stat
                .split_whitespace()
                .next()
                .and_then(|v| v.parse::<u64>().ok())
                .unwrap_or(0);
        }
    }
    ns as f64 * 1e-9
}

fn median(times: &[f64]) -> f64 {
    let mut sorted = times.to_vec();
    sorted.sort_by(f64::total_cmp);
    let n = sorted.len();
    if n % 2 == 1 {
        sorted[n / 2]
    } else {
        (sorted[n / 2 - 1] + sorted[n / 2]) / 2.0
    }
}

fn min(times: &[f64]) -> f64 {
    times.iter().copied().fold(f64::INFINITY, f64::min)
}

/// The 1-, 5- and 15-minute load averages, as `/proc/loadavg` gives them.
fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .map(|l| l.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_else(|_| "unknown".into())
}

fn verdict(ok: bool) -> &'static str {
    if ok { "PASS" } else { "FAIL" }
}
