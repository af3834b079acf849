//! Nearest points on point-calculus curves and patches: the best of a coarse
//! scan, refined by Gauss–Newton steps on the parameters.

use super::{Patch9, PcCurve};
use crate::geom::Point3;

const SCAN: usize = 64;
const STEPS: usize = 40;

pub(super) fn curve(c: &PcCurve, p: &Point3) -> Option<(f64, Point3)> {
    if !p.coords.iter().all(|x| x.is_finite()) {
        return None;
    }
    let dist2 = |u: f64| (c.point(u) - p).norm_squared();
    let mut best = (0.0, f64::INFINITY);
    for i in 0..=SCAN {
        let u = i as f64 / SCAN as f64;
        let d = dist2(u);
        if d < best.1 {
            best = (u, d);
        }
    }
    let mut u = best.0;
    for _ in 0..STEPS {
        let m = c.point(u);
        let d = c.derivative(u);
        let d2 = d.norm_squared();
        if !(d2 > 0.0 && d2.is_finite()) {
            break;
        }
        let step = (m - p).dot(&d) / d2;
        let next = (u - step).clamp(0.0, 1.0);
        if (next - u).abs() <= 1e-14 {
            u = next;
            break;
        }
        u = next;
    }
    let (u, _) = if dist2(u) <= best.1 { (u, 0.0) } else { best };
    let q = c.point(u);
    q.coords.iter().all(|x| x.is_finite()).then_some((u, q))
}

/// Parameters may leave [0, 1] by this much, so that points just outside a
/// side (within tolerance) still find their foot point.
const OVERSHOOT: f64 = 0.25;

pub(super) fn patch(s: &Patch9, p: &Point3) -> Option<([f64; 2], Point3)> {
    if !p.coords.iter().all(|x| x.is_finite()) {
        return None;
    }
    // A 5 × 5 scan seeds Gauss–Newton well for the mildly curved patches the
    // format describes; the scan dominates the cost of a projection.
    let n = 4;
    let mut best = ([0.0, 0.0], f64::INFINITY);
    for i in 0..=n {
        for j in 0..=n {
            let (u, v) = (j as f64 / n as f64, i as f64 / n as f64);
            let d = (s.point(u, v) - p).norm_squared();
            if d < best.1 {
                best = ([u, v], d);
            }
        }
    }
    let [mut u, mut v] = best.0;
    for _ in 0..STEPS {
        let r = s.point(u, v) - p;
        let (mu, mv) = s.derivatives(u, v);
        // Gauss–Newton: solve JᵀJ δ = −Jᵀr.
        let (a, b, c) = (mu.dot(&mu), mu.dot(&mv), mv.dot(&mv));
        let (g0, g1) = (mu.dot(&r), mv.dot(&r));
        let det = a * c - b * b;
        if !(det.abs() > 0.0 && det.is_finite()) {
            break;
        }
        let du = -(c * g0 - b * g1) / det;
        let dv = -(a * g1 - b * g0) / det;
        let nu = (u + du).clamp(-OVERSHOOT, 1.0 + OVERSHOOT);
        let nv = (v + dv).clamp(-OVERSHOOT, 1.0 + OVERSHOOT);
        let moved = (nu - u).abs().max((nv - v).abs());
        (u, v) = (nu, nv);
        if moved <= 1e-13 {
            break;
        }
    }
    let q = s.point(u, v);
    let uv = if (q - p).norm_squared() <= best.1 {
        [u, v]
    } else {
        best.0
    };
    let q = s.point(uv[0], uv[1]);
    q.coords.iter().all(|x| x.is_finite()).then_some((uv, q))
}
