//! Implicit-solid benchmark (issue 5): PERF-ANCHORS.md's models M1 (seven balls,
//! Rvachev unions), M2 (gyroid shell in a ball, min) and M3 (max of 1,000 small
//! balls), whole path (build the function, sample with interval pruning,
//! polygonize) at 256 cells per axis, against two peers measured in the same
//! run: the `fidget` crate's JIT + octree dual-contouring mesher at depth 8
//! (2 threads, the same function converted node by node), and VTK flying
//! edges (benches/peers/vtk_flying_edges.py, when Python can import `vtk`) on
//! the same field already sampled on the same grid, against geomc's contouring
//! of the same given samples. Also dense f32 evaluation throughput of M1.
//!
//! Run: `cargo bench --bench implicit` (add `-- --quick` for 128 cells,
//! `-- --no-fidget` to skip the slow peer, `-- --no-dense` to skip the dense
//! evaluation of M2 and M3, `-- --model M1` to mesh only M1, `-- --dense-only` for the dense
//! evaluation alone, `-- --whole-only` for the whole paths alone, `-- --reps N`
//! for N runs of each instead of 3: profiles of the product path). Without `--bench` (as under
//! `cargo test --all-targets`) a 32-cell smoke run without peers.

// The allocator of the `geomc` command, so the whole path is timed as users
// run it (`geomc compile` of an implicit model), as in the other benches.
// Until session 11 this bench ran on glibc's malloc: its figures in
// docs/performance.md before then are not comparable on the allocation part.
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

use geomc::implicit::ir::{Binary, Ctx, Node, NodeId, Unary};
use geomc::implicit::library;
use geomc::implicit::polygonize::{self, Grid, Options};
use geomc::implicit::rfs::RSystem;
use geomc::implicit::tape::Ssa;
use std::time::{Duration, Instant};

fn ball(ctx: &mut Ctx, r: f64, c: [f64; 3]) -> NodeId {
    let (x, y, z) = (ctx.var(0), ctx.var(1), ctx.var(2));
    let args = [
        x,
        y,
        z,
        ctx.constant(r),
        ctx.constant(c[0]),
        ctx.constant(c[1]),
        ctx.constant(c[2]),
    ];
    let lib = library::lookup("Ball").expect("Ball is in the library");
    (lib.build)(ctx, RSystem::Rvachev, &args).expect("Ball builds")
}

fn m1() -> Ssa {
    let mut ctx = Ctx::new();
    let mut f = ball(&mut ctx, 0.7, [0.0; 3]);
    for c in [
        [0.7, 0.0, 0.0],
        [-0.7, 0.0, 0.0],
        [0.0, 0.7, 0.0],
        [0.0, -0.7, 0.0],
        [0.0, 0.0, 0.7],
        [0.0, 0.0, -0.7],
    ] {
        let b = ball(&mut ctx, 0.3, c);
        f = ctx.r_or(f, b, 0.0);
    }
    Ssa::from_ctx(&ctx, f)
}

fn m2() -> Ssa {
    let mut ctx = Ctx::new();
    let v = [ctx.var(0), ctx.var(1), ctx.var(2)];
    let six = ctx.constant(6.0);
    let s: Vec<NodeId> = v.iter().map(|&a| ctx.mul(six, a)).collect();
    let mut g = ctx.constant(0.0);
    for k in 0..3 {
        let sn = ctx.unary(Unary::Sin, s[k]);
        let cs = ctx.unary(Unary::Cos, s[(k + 1) % 3]);
        let t = ctx.mul(sn, cs);
        g = ctx.add(g, t);
    }
    let gg = ctx.square(g);
    let c = ctx.constant(0.04);
    let shell = ctx.sub(c, gg);
    let sphere = ball(&mut ctx, 0.9, [0.0; 3]);
    let f = ctx.binary(Binary::Min, shell, sphere);
    Ssa::from_ctx(&ctx, f)
}

fn m3() -> Ssa {
    let mut state = 1u32;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        -0.9 + 1.8 * (state as f64 / 4294967296.0)
    };
    let mut ctx = Ctx::new();
    let mut f = None;
    for _ in 0..1000 {
        let c = [next(), next(), next()];
        let b = ball(&mut ctx, 0.05, c);
        f = Some(match f {
            None => b,
            Some(acc) => ctx.binary(Binary::Max, acc, b),
        });
    }
    Ssa::from_ctx(&ctx, f.expect("1000 balls"))
}

/// FNV-1a over the mesh's position bits and indices: equal digests before
/// and after a speed change show the change kept the meshes byte-identical.
fn digest(s: &polygonize::Surface) -> u64 {
    let words = s.positions.iter().flat_map(|p| p.map(f64::to_bits));
    let ids = s.triangles.iter().flat_map(|t| t.map(u64::from));
    words.chain(ids).fold(0xcbf2_9ce4_8422_2325, |h, w| {
        (h ^ w).wrapping_mul(0x0100_0000_01b3)
    })
}

/// A model's name and its builder.
type Model = (&'static str, fn() -> Ssa);

/// CPU time used so far by all threads of this process (Linux
/// `/proc/self/task/*/schedstat`; 0 elsewhere). On a machine shared with
/// other builds the wall time swings with the load; the CPU time much less.
fn cpu_time() -> Duration {
    let tasks = std::fs::read_dir("/proc/self/task").into_iter().flatten();
    let ns: u64 = tasks
        .flatten()
        .filter_map(|t| std::fs::read_to_string(t.path().join("schedstat")).ok())
        .filter_map(|s| s.split_whitespace().next()?.parse::<u64>().ok())
        .sum();
    Duration::from_nanos(ns)
}

/// CPU time of the median-wall-time run, printed by `time`'s callers.
static LAST_CPU: std::sync::Mutex<Duration> = std::sync::Mutex::new(Duration::ZERO);

fn time<T>(reps: usize, mut f: impl FnMut() -> T) -> (Duration, T) {
    let mut last = None;
    let mut runs: Vec<(Duration, Duration)> = (0..reps)
        .map(|_| {
            let (start, cpu) = (Instant::now(), cpu_time());
            let r = f();
            let t = start.elapsed();
            let c = cpu_time().saturating_sub(cpu);
            last = Some(r);
            (t, c)
        })
        .collect();
    runs.sort();
    let (wall, cpu) = runs[runs.len() / 2];
    if let Ok(mut l) = LAST_CPU.lock() {
        *l = cpu;
    }
    (wall, last.expect("at least one run"))
}

/// The CPU seconds of the last `time` call.
fn last_cpu() -> f64 {
    LAST_CPU
        .lock()
        .map(|l| *l)
        .unwrap_or_default()
        .as_secs_f64()
}

/// " (cpu 1.234 s)": the CPU time of the last `time` call.
fn cpu() -> String {
    format!(" (cpu {:.3} s)", last_cpu())
}

/// The same function as a fidget tree, negated (fidget's inside is f < 0).
fn to_fidget(ssa: &Ssa) -> fidget::context::Tree {
    use fidget::context::Tree;
    let mut t: Vec<Tree> = Vec::with_capacity(ssa.ops.len());
    for op in &ssa.ops {
        let g = |k: u32| t[k as usize].clone();
        let v = match *op {
            Node::Const(bits) => Tree::constant(f64::from_bits(bits) as f32),
            Node::Var(0) => Tree::x(),
            Node::Var(1) => Tree::y(),
            Node::Var(_) => Tree::z(),
            Node::Unary(u, a) => {
                let a = g(a);
                match u {
                    Unary::Neg => a.neg(),
                    Unary::Sqrt => a.sqrt(),
                    Unary::Square => a.square(),
                    Unary::Abs => a.abs(),
                    Unary::Sin => a.sin(),
                    Unary::Cos => a.cos(),
                    other => panic!("{other:?} is not used by the benchmark models"),
                }
            }
            Node::Binary(b, x, y) => {
                let (x, y) = (g(x), g(y));
                match b {
                    Binary::Add => x + y,
                    Binary::Sub => x - y,
                    Binary::Mul => x * y,
                    Binary::Div => x / y,
                    Binary::Min => x.min(y),
                    Binary::Max => x.max(y),
                    other => panic!("{other:?} is not used by the benchmark models"),
                }
            }
            Node::ROr(x, y, _) => {
                let (x, y) = (g(x), g(y));
                x.clone() + y.clone() + (x.square() + y.square()).sqrt()
            }
            Node::RAnd(x, y, _) => {
                let (x, y) = (g(x), g(y));
                x.clone() + y.clone() - (x.square() + y.square()).sqrt()
            }
        };
        t.push(v);
    }
    t[ssa.root()].neg()
}

/// fidget's octree mesher at `depth` on the global rayon pool; triangles.
fn fidget_mesh(ssa: &Ssa, depth: u8) -> usize {
    use fidget::jit::JitShape;
    use fidget::mesh::{Octree, Settings};
    let shape = JitShape::from(to_fidget(ssa));
    let bound = shape.try_into().expect("x, y, z only");
    let settings = Settings {
        depth,
        ..Default::default()
    };
    let octree = Octree::build(&bound, &settings).expect("not cancelled");
    octree.walk_dual().triangles.len()
}

/// fidget's JIT float-slice evaluator on every point of the grid, a z plane
/// per call, planes spread over rayon's pool as for geomc, into `values`
/// (with geomc's sign convention, inside > 0): the wall time (median of
/// `reps`; the CPU time goes to `LAST_CPU`).
fn fidget_dense(ssa: &Ssa, grid: &Grid, values: &mut [f32], reps: usize) -> Duration {
    use fidget::jit::JitShape;
    use rayon::prelude::*;
    let shape = JitShape::from(to_fidget(ssa));
    let [xs, ys, zs] = [0, 1, 2].map(|a| grid.coords(a));
    let plane = xs.len() * ys.len();
    let px: Vec<f32> = (0..plane).map(|p| xs[p % xs.len()] as f32).collect();
    let py: Vec<f32> = (0..plane).map(|p| ys[p / xs.len()] as f32).collect();
    time(reps, || {
        values.par_chunks_mut(plane).enumerate().for_each_init(
            || {
                let tape = shape.float_slice_tape(Default::default());
                (JitShape::new_float_slice_eval(), tape, vec![0.0f32; plane])
            },
            |(eval, tape, pz), (k, out)| {
                pz.fill(zs[k] as f32);
                let v = eval.eval(tape, &px, &py, pz).expect("x, y, z only");
                for (o, &v) in out.iter_mut().zip(v) {
                    *o = -v;
                }
            },
        );
    })
    .0
}

/// VTK flying edges on `values` through the Python peer: (seconds, triangles),
/// or None when Python or `vtk` is missing.
fn vtk_flying_edges(values: &[f32], n: usize, threads: usize, reps: usize) -> Option<(f64, u64)> {
    let script = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/benches/peers/vtk_flying_edges.py"
    );
    let dir = tempfile::tempdir().ok()?;
    let path = dir.path().join("field.f32");
    let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
    std::fs::write(&path, bytes).ok()?;
    let n1 = (n + 1).to_string();
    let out = std::process::Command::new("python3")
        .arg(script)
        .arg(&path)
        .args([&n1, &n1, &n1, "-1", "1"])
        .args([threads.to_string(), reps.to_string()])
        .output()
        .ok()?;
    if !out.status.success() {
        eprintln!(
            "VTK peer skipped: {}",
            String::from_utf8_lossy(&out.stderr)
                .lines()
                .last()
                .unwrap_or("")
        );
        return None;
    }
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).ok()?;
    Some((json["seconds"].as_f64()?, json["triangles"].as_u64()?))
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let smoke = !args.iter().any(|a| a == "--bench");
    let quick = args.iter().any(|a| a == "--quick");
    let with_fidget = !smoke && !args.iter().any(|a| a == "--no-fidget");
    let no_dense = smoke || args.iter().any(|a| a == "--no-dense");
    let (n, mut reps) = match (smoke, quick) {
        (true, _) => (32, 1),
        (false, true) => (128, 3),
        (false, false) => (256, 3),
    };
    if let Some(r) = args
        .iter()
        .position(|a| a == "--reps")
        .and_then(|p| args.get(p + 1)?.parse::<usize>().ok())
    {
        reps = r.max(1);
    }
    let whole_only = args.iter().any(|a| a == "--whole-only");
    let depth = (n as f64).log2().round() as u8;
    let threads = rayon::current_num_threads();
    println!("implicit benchmark: {n} cells per axis, {threads} threads, median of {reps}");
    if let Ok(load) = std::fs::read_to_string("/proc/loadavg") {
        println!("load average at start: {}", load.trim());
    }
    let grid = Grid {
        min: [-1.0; 3],
        max: [1.0; 3],
        cells: [n; 3],
    };
    let models: [Model; 3] = [
        ("M1 seven balls", m1),
        ("M2 gyroid in ball", m2),
        ("M3 1,000 balls", m3),
    ];
    // `--model M2`: only that model's meshing (for profiling).
    let only = args
        .iter()
        .position(|a| a == "--model")
        .and_then(|p| args.get(p + 1));
    let dense_only = args.iter().any(|a| a == "--dense-only");
    for (name, build) in models {
        if dense_only || only.is_some_and(|m| !name.starts_with(m.as_str())) {
            continue;
        }
        let (t, s) = time(reps, || {
            let ssa = build();
            polygonize::polygonize(&ssa, &grid, &Options::default())
        });
        println!(
            "{name}: geomc whole path {:.3} s{}, {} triangles (digest {:016x}), {} of {} blocks pruned",
            t.as_secs_f64(),
            cpu(),
            s.triangles.len(),
            digest(&s),
            s.pruned_blocks,
            s.blocks
        );
        if whole_only {
            continue;
        }
        let t_cpu = last_cpu();
        let ssa = build();
        // Contouring only, on the same densely sampled field as VTK.
        let values = polygonize::sample_grid(&ssa, &grid);
        let mut copies = vec![values.clone(); reps];
        let (tc, sc) = time(reps, || {
            let v = copies.pop().expect("one copy per run");
            // The buffer comes back and is freed outside the timing, as
            // VTK's input is.
            polygonize::polygonize_samples_f32_returning(v, &grid, &Options::default())
        });
        let sc = sc.0;
        print!(
            "  contouring the sampled field: geomc {:.3} s{} ({} triangles, digest {:016x})",
            tc.as_secs_f64(),
            cpu(),
            sc.triangles.len(),
            digest(&sc)
        );
        if !smoke {
            match vtk_flying_edges(&values, n, threads, reps) {
                Some((tv, tris)) => print!(
                    "; VTK flying edges {tv:.3} s ({tris} triangles): geomc contouring {:.1}x, whole path {:.1}x faster",
                    tv / tc.as_secs_f64(),
                    tv / t.as_secs_f64()
                ),
                None => print!("; VTK not available"),
            }
        }
        println!();
        if with_fidget {
            let (tf, tris) = time(1, || fidget_mesh(&ssa, depth));
            println!(
                "  fidget depth {depth}: {:.3} s{} ({tris} triangles), geomc {:.1}x faster ({:.1}x in CPU time)",
                tf.as_secs_f64(),
                cpu(),
                tf.as_secs_f64() / t.as_secs_f64(),
                last_cpu() / t_cpu
            );
        }
    }
    if whole_only {
        return;
    }
    let ssa = m1();
    let tape = geomc::implicit::rows::RowTape::new(&ssa);
    let points = ((n + 1) as f64).powi(3);
    // Fresh allocation each run (the first touch of 68 MB of new pages is
    // in the time), as the meshing path does it.
    let (t_fresh, v) = time(reps.max(3), || polygonize::sample_grid(&ssa, &grid));
    let fresh_cpu = last_cpu();
    assert_eq!(v.len(), (n + 1).pow(3));
    println!(
        "dense M1 evaluation into fresh memory: {:.1} M points/s ({:.3} s, cpu {fresh_cpu:.3} s)",
        points / t_fresh.as_secs_f64() / 1e6,
        t_fresh.as_secs_f64()
    );
    // Evaluation alone: into a buffer already mapped (both evaluators below).
    let mut buf = vec![1.0f32; v.len()];
    let (t, ()) = time(reps.max(5), || {
        polygonize::sample_grid_into(&ssa, &grid, &mut buf)
    });
    let m1_cpu = last_cpu();
    assert!(buf.iter().zip(&v).all(|(a, b)| a.to_bits() == b.to_bits()));
    let rate = points / t.as_secs_f64();
    // 6 Rvachev unions × 6 flops + 7 balls × 2 row terms per point (the x
    // terms are computed once per set of x); the 256-bit f32 peak of 2
    // cores at 2.6 GHz with 2 FMA pipes: 2 × 2 × 8 × 2 × 2.6 GHz = 166 GFLOP/s.
    let flops = rate * 50.0;
    println!(
        "dense M1 evaluation (f32 lanes, {} lane passes per row): {:.1} M points/s ({:.3} s, cpu {m1_cpu:.3} s = {:.1} M points per CPU-second, for {:.1} M points); {:.1} GFLOP/s = {:.1}% of the 166 GFLOP/s f32 AVX2 FMA peak",
        tape.lane_len(),
        rate / 1e6,
        t.as_secs_f64(),
        points / m1_cpu / 1e6,
        points / 1e6,
        flops / 1e9,
        flops / 166e9 * 100.0
    );
    // Dense evaluation of every model by both evaluators in this run, each
    // into a mapped buffer (median of 5 for M1, one run for M2 and M3, whose
    // dense loops are not the product path).
    let mut fbuf = vec![1.0f32; v.len()];
    for (name, build) in models {
        if no_dense && !name.starts_with("M1") {
            continue;
        }
        let ssa = build();
        let (tg, g_cpu) = if name.starts_with("M1") {
            (t, m1_cpu)
        } else {
            let (tg, ()) = time(1, || polygonize::sample_grid_into(&ssa, &grid, &mut buf));
            (tg, last_cpu())
        };
        print!(
            "dense {name}: geomc {:.1} M points/s ({:.3} s, cpu {g_cpu:.3} s)",
            points / tg.as_secs_f64() / 1e6,
            tg.as_secs_f64()
        );
        if with_fidget {
            let f_reps = if name.starts_with("M1") { 5 } else { 1 };
            let tf = fidget_dense(&ssa, &grid, &mut fbuf, f_reps);
            // The same points in f32: how many samples the two disagree on in sign.
            let differ = fbuf
                .iter()
                .zip(&buf)
                .filter(|(a, b)| (**a > 0.0) != (**b > 0.0))
                .count();
            print!(
                "; fidget JIT {:.1} M points/s ({:.3} s{}): geomc {:.1}x faster ({:.1}x in CPU time); {differ} samples differ in sign",
                points / tf.as_secs_f64() / 1e6,
                tf.as_secs_f64(),
                cpu(),
                tf.as_secs_f64() / tg.as_secs_f64(),
                last_cpu() / g_cpu
            );
        }
        println!();
    }
    if let Ok(load) = std::fs::read_to_string("/proc/loadavg") {
        println!("load average at end: {}", load.trim());
    }
}
