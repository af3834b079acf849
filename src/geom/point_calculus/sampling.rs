//! Adaptive sampling of a curve to a chordal tolerance: an interval is split
//! in half while the curve strays from its chord by more than the tolerance
//! (judged at the quarter, half and three-quarter parameters, so an S-bend
//! inside one interval is seen) or the chord exceeds `max_chord`.
//! Sequential and depth-first, so the samples are deterministic.

use super::PcCurve;
use crate::geom::Point3;

/// Deepest bisection: 2⁻²⁴ of the parameter range.
const MAX_DEPTH: u32 = 24;

/// Parameters and points from u = 0 to u = 1, ends exact, with every chord
/// within `tolerance` of the curve and no longer than `max_chord`; at least
/// `min_segments` segments. `None` when the tolerance is not positive or the
/// curve is not finite.
pub fn adaptive_samples(
    curve: &PcCurve,
    tolerance: f64,
    max_chord: f64,
    min_segments: usize,
) -> Option<(Vec<f64>, Vec<Point3>)> {
    if tolerance.is_nan() || tolerance <= 0.0 || max_chord.is_nan() || max_chord <= 0.0 {
        return None;
    }
    let n0 = min_segments.max(1);
    let mut params = vec![0.0];
    let mut points = vec![curve.begin()];
    for i in 0..n0 {
        let (u0, u1) = (i as f64 / n0 as f64, (i + 1) as f64 / n0 as f64);
        let p1 = if i + 1 == n0 {
            curve.end()
        } else {
            curve.point(u1)
        };
        let p0 = points[points.len() - 1];
        split(
            curve,
            (u0, p0),
            (u1, p1),
            tolerance,
            max_chord,
            0,
            &mut params,
            &mut points,
        )?;
    }
    Some((params, points))
}

#[allow(clippy::too_many_arguments)]
fn split(
    curve: &PcCurve,
    (u0, p0): (f64, Point3),
    (u1, p1): (f64, Point3),
    tolerance: f64,
    max_chord: f64,
    depth: u32,
    params: &mut Vec<f64>,
    points: &mut Vec<Point3>,
) -> Option<()> {
    if !p1.coords.iter().all(|x| x.is_finite()) {
        return None;
    }
    let um = 0.5 * (u0 + u1);
    let pm = curve.point(um);
    let good = depth >= MAX_DEPTH
        || ((p1 - p0).norm() <= max_chord
            && [0.25, 0.5, 0.75].iter().all(|f| {
                let q = if *f == 0.5 {
                    pm
                } else {
                    curve.point(u0 + (u1 - u0) * f)
                };
                distance_to_segment(&q, &p0, &p1) <= tolerance
            }));
    if good {
        params.push(u1);
        points.push(p1);
        return Some(());
    }
    split(
        curve,
        (u0, p0),
        (um, pm),
        tolerance,
        max_chord,
        depth + 1,
        params,
        points,
    )?;
    split(
        curve,
        (um, pm),
        (u1, p1),
        tolerance,
        max_chord,
        depth + 1,
        params,
        points,
    )
}

fn distance_to_segment(p: &Point3, a: &Point3, b: &Point3) -> f64 {
    let d = b - a;
    let len2 = d.norm_squared();
    if len2 <= 0.0 {
        return (p - a).norm();
    }
    let t = ((p - a).dot(&d) / len2).clamp(0.0, 1.0);
    (p - (a + d * t)).norm()
}
