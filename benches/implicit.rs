//! Implicit-solid benchmark (issue 5): PERF-ANCHORS.md's models M1 (seven balls,
//! Rvachev unions), M2 (gyroid shell in a ball, min) and M3 (max of 1,000 small
//! balls), whole path (build the function, sample with interval pruning,
//! polygonize) at 256 cells per axis; and dense evaluation throughput of M1 on
//! 257³ points. No peer runs in this harness (fidget was not added as a
//! dependency): compare with the anchors of PERF-ANCHORS.md measured on this
//! kind of machine, which drift by up to ±40%.
//!
//! Run: `cargo bench --bench implicit` (add `-- --quick` for 128 cells).

use geomc::implicit::ir::{Binary, Ctx, NodeId, Unary};
use geomc::implicit::library;
use geomc::implicit::polygonize::{self, Grid, Options};
use geomc::implicit::rfs::RSystem;
use geomc::implicit::tape::{Ssa, Tape};
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

/// A model's name, its builder and the plain-Rust anchor in seconds.
type Model = (&'static str, fn() -> Ssa, f64);

fn median(mut runs: Vec<Duration>) -> Duration {
    runs.sort();
    runs[runs.len() / 2]
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let smoke = !args.iter().any(|a| a == "--bench");
    let quick = args.iter().any(|a| a == "--quick");
    let (n, reps) = match (smoke, quick) {
        (true, _) => (32, 1),
        (false, true) => (128, 3),
        (false, false) => (256, 3),
    };
    let threads = rayon::current_num_threads();
    println!("implicit benchmark: {n} cells per axis, {threads} threads, median of {reps}");
    let grid = Grid {
        min: [-1.0; 3],
        max: [1.0; 3],
        cells: [n; 3],
    };
    let models: [Model; 3] = [
        ("M1 seven balls", m1, 0.45),
        ("M2 gyroid in ball", m2, 0.55),
        ("M3 1,000 balls", m3, 31.0),
    ];
    for (name, build, plain_rust_2t) in models {
        let mut tris = 0;
        let mut pruned = (0, 0);
        let time = median(
            (0..reps)
                .map(|_| {
                    let start = Instant::now();
                    let ssa = build();
                    let s = polygonize::polygonize(&ssa, &grid, &Options::default());
                    let t = start.elapsed();
                    tris = s.triangles.len();
                    pruned = (s.pruned_blocks, s.blocks);
                    t
                })
                .collect(),
        );
        println!(
            "{name}: {:.3} s, {tris} triangles, {} of {} blocks pruned; anchor (2 threads): plain Rust dense + MC {plain_rust_2t} s",
            time.as_secs_f64(),
            pruned.0,
            pruned.1
        );
    }
    let tape = Tape::new(&m1());
    let time = median(
        (0..reps)
            .map(|_| {
                let start = Instant::now();
                let v = polygonize::sample_grid(&tape, &grid);
                let t = start.elapsed();
                assert_eq!(v.len(), (n + 1).pow(3));
                t
            })
            .collect(),
    );
    let points = ((n + 1) as f64).powi(3);
    let rate = points / time.as_secs_f64();
    // Peak of the machine in PERF-ANCHORS.md: 160 GFLOP/s (f32 AVX2 FMA, 2 cores);
    // f64 halves the lanes. M1 is about 99 flops per point.
    let flops = rate * 99.0;
    println!(
        "dense M1 evaluation, {} tape instructions: {:.1} M points/s ({:.3} s for {:.1} M points); {:.1} GFLOP/s = {:.1}% of the f64 AVX2 peak (80 GFLOP/s); anchor: fidget JIT 142–149 M/s on 2 threads",
        tape.len(),
        rate / 1e6,
        time.as_secs_f64(),
        points / 1e6,
        flops / 1e9,
        flops / 80e9 * 100.0
    );
}
