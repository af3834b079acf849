//! Point-calculus benchmark (issue 7): 100 million points of conic arcs and
//! 100 million points of 9-point patches, evaluated coordinate-wise into x, y,
//! z streams in parallel, against the memory-bandwidth bound of writing
//! 3 × 8 bytes per point, measured in the same run by a plain parallel array
//! copy of the same size. Target: at least 50% of the bound.
//!
//! Run: `cargo bench --bench point_calculus` (add `-- --quick` for 10 million
//! points each). Under `cargo test --all-targets` it is a smoke run of 2
//! million points.

use geomc::geom::Point3;
use geomc::geom::point_calculus::{Patch9, PcCurve, Streams, eval_curve, eval_patch_grid};
use rayon::prelude::*;
use std::time::{Duration, Instant};

/// Points per block: 2²¹, so each block's 48 MB of output is far beyond the
/// last-level cache and every run measures memory, not cache.
const BLOCK: usize = 1 << 21;

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
    let args: Vec<String> = std::env::args().collect();
    let smoke = !args.iter().any(|a| a == "--bench");
    let quick = args.iter().any(|a| a == "--quick");
    let total: usize = match (smoke, quick) {
        (true, _) => 2_000_000,
        (false, true) => 10_000_000,
        (false, false) => 100_000_000,
    };
    let block = BLOCK.min(total);
    let blocks = total.div_ceil(block);
    let points = blocks * block;
    println!(
        "point calculus: {points} points per object kind in blocks of {block}, {} threads",
        rayon::current_num_threads()
    );

    // The peer: a plain parallel copy of three f64 streams, 24 bytes per point.
    let src = Streams {
        x: vec![1.0; block],
        y: vec![2.0; block],
        z: vec![3.0; block],
    };
    let mut dst = Streams::zeroed(block);
    let copy = best_of(3, || {
        for _ in 0..blocks {
            for (d, s) in [
                (&mut dst.x, &src.x),
                (&mut dst.y, &src.y),
                (&mut dst.z, &src.z),
            ] {
                d.par_chunks_mut(1 << 14)
                    .zip(s.par_chunks(1 << 14))
                    .for_each(|(d, s)| d.copy_from_slice(s));
            }
            std::hint::black_box(&dst);
        }
    });
    let bound = points as f64 / copy.as_secs_f64();
    println!(
        "  plain copy, 24 B/point written:   {:8.3} s  {:7.2} GB/s written = {:7.1} Mpoints/s bound",
        copy.as_secs_f64(),
        24.0 * bound / 1e9,
        bound / 1e6
    );

    // Conic arcs of the three types, cycled block by block.
    let arcs: Vec<PcCurve> = [0.3, 0.5, 0.8]
        .iter()
        .map(|&k| PcCurve::Conic {
            a: Point3::new(0.0, 0.0, 0.0),
            b: Point3::new(3.0, 0.5, 1.0),
            c: Point3::new(1.0, 2.0, 0.5),
            k,
        })
        .collect();
    let params: Vec<f64> = (0..block).map(|i| i as f64 / (block - 1) as f64).collect();
    let mut out = Streams::zeroed(block);
    let mut checksum = 0.0;
    let conic = best_of(3, || {
        for b in 0..blocks {
            eval_curve(&arcs[b % arcs.len()], &params, &mut out);
            checksum = out.x[block / 3] + out.y[block / 2] + out.z[block - 1];
        }
        std::hint::black_box(&out);
    });
    report("conic arcs", points, conic, bound);
    assert!(checksum.is_finite());
    // The last block was the arc k = …: its end is the exact end point.
    let last = &arcs[(blocks - 1) % arcs.len()];
    assert_eq!(
        Point3::new(out.x[block - 1], out.y[block - 1], out.z[block - 1]),
        last.end()
    );

    // 9-point patches: a square grid of parameters per block.
    let patch = Patch9 {
        rows: [
            [
                Point3::new(0.0, 0.0, 0.0),
                Point3::new(1.0, 0.0, 0.3),
                Point3::new(2.0, 0.0, 0.0),
            ],
            [
                Point3::new(0.0, 1.0, 0.2),
                Point3::new(1.0, 1.0, 0.8),
                Point3::new(2.0, 1.0, 0.1),
            ],
            [
                Point3::new(0.0, 2.0, 0.0),
                Point3::new(1.0, 2.0, 0.4),
                Point3::new(2.0, 2.0, -0.2),
            ],
        ],
    };
    let side = (block as f64).sqrt() as usize;
    let grid: Vec<f64> = (0..side).map(|i| i as f64 / (side - 1) as f64).collect();
    let rows_per_block = block / side;
    let vs: Vec<f64> = (0..rows_per_block)
        .map(|i| i as f64 / (rows_per_block - 1) as f64)
        .collect();
    let patch_points = blocks * side * rows_per_block;
    let patched = best_of(3, || {
        for _ in 0..blocks {
            eval_patch_grid(&patch, &grid, &vs, &mut out);
        }
        std::hint::black_box(&out);
    });
    report("9-point patches", patch_points, patched, bound);
    assert_eq!(
        Point3::new(out.x[0], out.y[0], out.z[0]),
        patch.rows[0][0],
        "the patch interpolates its corner"
    );
}

fn report(what: &str, points: usize, time: Duration, bound: f64) {
    let rate = points as f64 / time.as_secs_f64();
    let ratio = rate / bound;
    println!(
        "  {what:<32} {:8.3} s  {:7.1} Mpoints/s = {:5.1}% of the bound (target >= 50%) {}",
        time.as_secs_f64(),
        rate / 1e6,
        100.0 * ratio,
        if ratio >= 0.5 { "PASS" } else { "FAIL" }
    );
}
