//! Trim loops shared with other faces (issue 9): a closed trim loop that
//! runs along a chain already discretised elsewhere (a model edge, or a
//! boundary chain of another trimmed surface — a hole's rim that is also a
//! tube's end) takes that chain's nodes instead of its own, fixed: they are
//! never split, so both faces meet node for node (the chain is discretised
//! once). The loop keeps its own direction; each node is placed on the
//! surface at the parameter point nearest it.

use super::TrimmedSurface;
use super::boundary::Boundary;
use super::triangulate::nearest_parameter;
use crate::geom::Point3;

/// The side bit of a shared loop's points (beyond the rectangle's four
/// sides): fixed, never split.
pub const SHARED: u8 = 16;

/// Replaces each closed trim loop of `b` (no point on a patch side) that
/// coincides with a closed chain of `chains` (first node repeated at the
/// end) within `distance` by that chain's nodes. Returns, per new boundary
/// point: (its index in `b.points`, the chain, the node's index in it).
pub(super) fn share_loops(
    s: &TrimmedSurface,
    b: &mut Boundary,
    chains: &[Vec<Point3>],
    distance: f64,
) -> Vec<(usize, usize, usize)> {
    let mut out = Vec::new();
    for li in 0..b.loops.len() {
        let lp = b.loops[li].clone();
        if lp.len() < 3 || lp.iter().any(|&p| b.sides[p] != 0) {
            continue;
        }
        let uv: Vec<[f64; 2]> = lp.iter().map(|&p| b.points[p]).collect();
        let pts: Vec<Point3> = uv.iter().map(|q| s.point(q[0], q[1])).collect();
        let Some(c) = chains.iter().position(|c| coincide(&pts, c, distance)) else {
            continue;
        };
        let chain = &chains[c];
        let n = chain.len() - 1;
        let nearest: Vec<usize> = pts.iter().map(|p| nearest_point(&chain[..n], p)).collect();
        // The chain's direction relative to the loop: the index steps along
        // the loop add up to ±n.
        let turn: i64 = (0..nearest.len())
            .map(|i| {
                let d = nearest[(i + 1) % nearest.len()] as i64 - nearest[i] as i64;
                let n = n as i64;
                (d + n + n / 2).rem_euclid(n) - n / 2
            })
            .sum();
        let forward = turn >= 0;
        let mut new_loop = Vec::with_capacity(n);
        for j in 0..n {
            let idx = if forward { j } else { (n - j) % n };
            let target = chain[idx];
            let start = uv[nearest_point(&pts, &target)];
            let q = nearest_parameter(s, target, start);
            let q = if q[0].is_finite() && q[1].is_finite() {
                q
            } else {
                start
            };
            b.points.push(q);
            b.sides.push(SHARED);
            new_loop.push(b.points.len() - 1);
            out.push((b.points.len() - 1, c, idx));
        }
        b.loops[li] = new_loop;
        b.fixed |= SHARED;
    }
    out
}

/// True when every loop point lies within `distance` of the closed chain
/// and every chain node within `distance` of the loop (both closed).
pub fn coincide(loop_points: &[Point3], chain: &[Point3], distance: f64) -> bool {
    if chain.len() < 4 || (chain[0] - chain[chain.len() - 1]).norm() > distance {
        return false;
    }
    let closed: Vec<Point3> = loop_points
        .iter()
        .chain(loop_points.first())
        .copied()
        .collect();
    let (a, b) = (bbox(&closed), bbox(chain));
    if (0..3).any(|k| (a.0[k] - b.0[k]).abs() > distance || (a.1[k] - b.1[k]).abs() > distance) {
        return false;
    }
    loop_points
        .iter()
        .all(|p| distance_to_polyline(chain, p) <= distance)
        && chain
            .iter()
            .all(|p| distance_to_polyline(&closed, p) <= distance)
}

/// The axis-aligned box of `points` (min corner, max corner).
pub(crate) fn bbox(points: &[Point3]) -> ([f64; 3], [f64; 3]) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in points {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    (lo, hi)
}

/// The distance from `p` to the nearest point of an open polyline.
pub(crate) fn distance_to_polyline(line: &[Point3], p: &Point3) -> f64 {
    line.windows(2)
        .map(|w| {
            let d = w[1] - w[0];
            let len2 = d.norm_squared();
            let t = if len2 > 0.0 {
                ((p - w[0]).dot(&d) / len2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            (w[0] + d * t - p).norm()
        })
        .fold(f64::INFINITY, f64::min)
}

/// The index of the point of `points` nearest to `p` (0 when empty).
pub(crate) fn nearest_point(points: &[Point3], p: &Point3) -> usize {
    let mut best = (f64::INFINITY, 0);
    for (i, q) in points.iter().enumerate() {
        let d = (q - p).norm_squared();
        if d < best.0 {
            best = (d, i);
        }
    }
    best.1
}
