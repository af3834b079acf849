//! Coordinate-wise evaluation, as paper 003 proposes: the weights of a
//! parameter sample are computed once and applied to the x, y and z streams
//! of the defining points (structure of arrays), in parallel over samples.
//! Each output depends only on its own parameter, so the result is the same
//! for any number of threads.

use super::{Patch9, PcCurve, parabola_weights};
use rayon::prelude::*;

/// Samples per parallel task: large enough to amortise scheduling, small
/// enough to balance two to a few dozen threads.
const CHUNK: usize = 1 << 14;

/// Three coordinate streams of equal length.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Streams {
    pub x: Vec<f64>,
    pub y: Vec<f64>,
    pub z: Vec<f64>,
}

impl Streams {
    pub fn zeroed(n: usize) -> Streams {
        Streams {
            x: vec![0.0; n],
            y: vec![0.0; n],
            z: vec![0.0; n],
        }
    }

    pub fn len(&self) -> usize {
        self.x.len()
    }

    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }
}

/// The weights of a curve's defining points at u (values only, unused
/// slots 0). Divisions rather than a reciprocal keep the end weights exactly 1.
#[inline(always)]
pub(super) fn curve_weights(curve: &PcCurve, u: f64) -> [f64; 4] {
    match curve {
        PcCurve::Segment { .. } => [1.0 - u, u, 0.0, 0.0],
        PcCurve::Conic { k, .. } => conic(*k, u),
        PcCurve::Desargues { .. } => desargues(u),
        PcCurve::Parabola { .. } => {
            let (w, _) = parabola_weights(u);
            [w[0], w[1], w[2], 0.0]
        }
    }
}

#[inline(always)]
fn conic(k: f64, u: f64) -> [f64; 4] {
    let ub = 1.0 - u;
    let s = 1.0 - 2.0 * u;
    let den = k * s * s + 2.0 * u * ub;
    [
        k * ub * ub / den,
        k * u * u / den,
        2.0 * (1.0 - k) * u * ub / den,
        0.0,
    ]
}

#[inline(always)]
fn desargues(u: f64) -> [f64; 4] {
    let ub = 1.0 - u;
    let den = 2.0 * u * u - 2.0 * u + 1.0;
    [
        ub * ub * ub / den,
        u * u * ub / den,
        ub * ub * u / den,
        u * u * u / den,
    ]
}

/// Evaluates `curve` at every parameter of `params` into `out` (resized).
/// Parameters outside [0, 1] extrapolate the point equation.
pub fn eval_curve(curve: &PcCurve, params: &[f64], out: &mut Streams) {
    let n = params.len();
    out.x.resize(n, 0.0);
    out.y.resize(n, 0.0);
    out.z.resize(n, 0.0);
    let points = curve.points();
    let mut cx = [0.0; 4];
    let mut cy = [0.0; 4];
    let mut cz = [0.0; 4];
    for (i, p) in points.iter().enumerate() {
        (cx[i], cy[i], cz[i]) = (p.x, p.y, p.z);
    }
    // One monomorphic kernel per kind, so each inner loop is branch-free.
    match curve {
        PcCurve::Segment { .. } => run(params, out, |u| [1.0 - u, u, 0.0, 0.0], cx, cy, cz),
        PcCurve::Conic { k, .. } => {
            let k = *k;
            run(params, out, move |u| conic(k, u), cx, cy, cz)
        }
        PcCurve::Desargues { .. } => run(params, out, desargues, cx, cy, cz),
        PcCurve::Parabola { .. } => run(
            params,
            out,
            |u| {
                let (w, _) = parabola_weights(u);
                [w[0], w[1], w[2], 0.0]
            },
            cx,
            cy,
            cz,
        ),
    }
}

#[inline(always)]
fn run(
    params: &[f64],
    out: &mut Streams,
    weights: impl Fn(f64) -> [f64; 4] + Sync,
    cx: [f64; 4],
    cy: [f64; 4],
    cz: [f64; 4],
) {
    out.x
        .par_chunks_mut(CHUNK)
        .zip(out.y.par_chunks_mut(CHUNK))
        .zip(out.z.par_chunks_mut(CHUNK))
        .zip(params.par_chunks(CHUNK))
        .for_each(|(((xs, ys), zs), us)| {
            for (((x, y), z), &u) in xs.iter_mut().zip(ys.iter_mut()).zip(zs.iter_mut()).zip(us) {
                let w = weights(u);
                // Σ wᵢ·Pᵢ in index order, as `PcCurve::point` sums.
                *x = ((0.0 + cx[0] * w[0]) + cx[1] * w[1]) + cx[2] * w[2] + cx[3] * w[3];
                *y = ((0.0 + cy[0] * w[0]) + cy[1] * w[1]) + cy[2] * w[2] + cy[3] * w[3];
                *z = ((0.0 + cz[0] * w[0]) + cz[1] * w[1]) + cz[2] * w[2] + cz[3] * w[3];
            }
        });
}

/// Evaluates `patch` on the grid `us` × `vs` into `out` (resized), row-major:
/// sample (i, j) at index i·|us| + j has v = vs[i], u = us[j]. The u weights
/// are computed once per column and each row's three combined points once
/// per row, so the inner loop is three multiply-adds per coordinate.
pub fn eval_patch_grid(patch: &Patch9, us: &[f64], vs: &[f64], out: &mut Streams) {
    let cols = us.len();
    let n = cols * vs.len();
    out.x.resize(n, 0.0);
    out.y.resize(n, 0.0);
    out.z.resize(n, 0.0);
    if cols == 0 {
        return;
    }
    let wu: Vec<[f64; 3]> = us.iter().map(|&u| parabola_weights(u).0).collect();
    let rows = &patch.rows;
    out.x
        .par_chunks_mut(cols)
        .zip(out.y.par_chunks_mut(cols))
        .zip(out.z.par_chunks_mut(cols))
        .zip(vs.par_iter())
        .for_each(|(((xs, ys), zs), &v)| {
            let (wv, _) = parabola_weights(v);
            // Q_j = Σᵢ wᵢ(v)·P_ij per coordinate, as `Patch9::point` combines.
            let q = |c: usize| -> [f64; 3] {
                let mut out = [0.0; 3];
                for (j, slot) in out.iter_mut().enumerate() {
                    *slot = rows[0][j][c] * wv[0] + rows[1][j][c] * wv[1] + rows[2][j][c] * wv[2];
                }
                out
            };
            let (qx, qy, qz) = (q(0), q(1), q(2));
            for (((x, y), z), w) in xs.iter_mut().zip(ys.iter_mut()).zip(zs.iter_mut()).zip(&wu) {
                *x = ((0.0 + qx[0] * w[0]) + qx[1] * w[1]) + qx[2] * w[2];
                *y = ((0.0 + qy[0] * w[0]) + qy[1] * w[1]) + qy[2] * w[2];
                *z = ((0.0 + qz[0] * w[0]) + qz[1] * w[1]) + qz[2] * w[2];
            }
        });
}
