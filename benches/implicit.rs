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
//! `-- --no-fidget` to skip the slow peer). Without `--bench` (as under
//! `cargo test --all-targets`) a 32-cell smoke run without peers.

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

/// A model's name and its builder.
type Model = (&'static str, fn() -> Ssa);

fn median(mut runs: Vec<Duration>) -> Duration {
    runs.sort();
    runs[runs.len() / 2]
}

fn time<T>(reps: usize, mut f: impl FnMut() -> T) -> (Duration, T) {
    let mut last = None;
    let runs = (0..reps)
        .map(|_| {
            let start = Instant::now();
            let r = f();
            let t = start.elapsed();
            last = Some(r);
            t
        })
        .collect();
    (median(runs), last.expect("at least one run"))
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
    let (n, reps) = match (smoke, quick) {
        (true, _) => (32, 1),
        (false, true) => (128, 3),
        (false, false) => (256, 3),
    };
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
    for (name, build) in models {
        let (t, s) = time(reps, || {
            let ssa = build();
            polygonize::polygonize(&ssa, &grid, &Options::default())
        });
        println!(
            "{name}: geomc {:.3} s, {} triangles, {} of {} blocks pruned",
            t.as_secs_f64(),
            s.triangles.len(),
            s.pruned_blocks,
            s.blocks
        );
        let ssa = build();
        // Contouring only, on the same densely sampled field as VTK.
        let values = polygonize::sample_grid(&ssa, &grid);
        let (tc, sc) = time(reps, || {
            let v: Vec<f64> = values.iter().map(|&v| v as f64).collect();
            polygonize::polygonize_samples(v, &grid, &Options::default())
        });
        print!(
            "  contouring the sampled field: geomc {:.3} s ({} triangles)",
            tc.as_secs_f64(),
            sc.triangles.len()
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
                "  fidget depth {depth}: {:.3} s ({tris} triangles), geomc {:.1}x faster",
                tf.as_secs_f64(),
                tf.as_secs_f64() / t.as_secs_f64()
            );
        }
    }
    let ssa = m1();
    let tape = geomc::implicit::rows::RowTape::new(&ssa);
    let (t, v) = time(reps.max(3), || polygonize::sample_grid(&ssa, &grid));
    assert_eq!(v.len(), (n + 1).pow(3));
    let points = ((n + 1) as f64).powi(3);
    let rate = points / t.as_secs_f64();
    // 6 unions × 6 flops + 7 balls × 2 per point (the x, y and z terms are
    // computed once per row); the 256-bit f32 peak of 2 cores at 2.6 GHz with
    // 2 FMA pipes: 2 × 2 × 8 lanes × 2 flops × 2.6 GHz = 166 GFLOP/s.
    let flops = rate * 50.0;
    println!(
        "dense M1 evaluation (f32 lanes, {} lane instructions per point): {:.1} M points/s ({:.3} s for {:.1} M points); {:.1} GFLOP/s = {:.1}% of the 166 GFLOP/s f32 AVX2 FMA peak",
        tape.lane_len(),
        rate / 1e6,
        t.as_secs_f64(),
        points / 1e6,
        flops / 1e9,
        flops / 166e9 * 100.0
    );
    if let Ok(load) = std::fs::read_to_string("/proc/loadavg") {
        println!("load average at end: {}", load.trim());
    }
}
