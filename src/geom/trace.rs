//! Marching along the intersection curve of two surfaces: a predictor step
//! along the tangent ∇f₁ × ∇f₂, a minimum-norm Newton correction back onto
//! both surfaces, and step control by the turning of the tangent. Bounded in
//! steps and never panics; when marching fails the straight chord a → b,
//! projected point by point, stands in.

use super::newton::project_onto_pair;
use super::{Point3, Surface, Vec3};

/// Most accepted or rejected steps of one march.
const MAX_STEPS: usize = 4000;
/// Largest turn of the tangent accepted per step (radians, as a cosine bound).
const MAX_TURN: f64 = 0.1;
/// Below this turn the step grows.
const SMALL_TURN: f64 = 0.03;

/// Points along the intersection of `surfaces` from `a` to `b` (closed when
/// a = b), starting with `a` and ending with `b`.
pub(super) fn trace(surfaces: &[Surface; 2], a: &Point3, b: &Point3) -> Vec<Point3> {
    let pair = [&surfaces[0], &surfaces[1]];
    let scale = 1.0 + a.coords.amax().max(b.coords.amax());
    if !scale.is_finite() {
        return vec![*a, *b];
    }
    let chord = (b - a).norm();
    let closed = chord <= 1e-12 * scale;
    let Some(t0) = tangent(pair, a) else {
        return straight(pair, a, b);
    };
    let march = |sign: f64| {
        let (h0, h_max, max_len) = if closed {
            (1e-3 * scale, scale, f64::INFINITY)
        } else {
            (chord / 64.0, chord / 16.0, 64.0 * chord)
        };
        Marcher {
            pair,
            a: *a,
            b: *b,
            closed,
            h_min: 1e-9 * scale,
            h_max,
            max_len,
        }
        .run(t0 * sign, h0)
    };
    // Towards b first; the other way round if b is not reached.
    let preferred = if t0.dot(&(b - a)) >= 0.0 { 1.0 } else { -1.0 };
    march(preferred)
        .or_else(|| if closed { None } else { march(-preferred) })
        .unwrap_or_else(|| straight(pair, a, b))
}

/// The point at arclength fraction `s` of a polyline and the direction of
/// the piece it lies on.
pub(super) fn polyline_at(line: &[Point3], s: f64) -> (Point3, Vec3) {
    let lengths: Vec<f64> = line.windows(2).map(|w| (w[1] - w[0]).norm()).collect();
    let total: f64 = lengths.iter().sum();
    let (Some(first), Some(last)) = (line.first(), line.last()) else {
        return (Point3::origin(), Vec3::zeros());
    };
    if lengths.is_empty() || total <= 0.0 || !total.is_finite() {
        return (*first, last - first);
    }
    let mut target = s.clamp(0.0, 1.0) * total;
    for (i, &len) in lengths.iter().enumerate() {
        if target <= len || i + 1 == lengths.len() {
            let f = if len > 0.0 {
                (target / len).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let d = line[i + 1] - line[i];
            return (line[i] + d * f, d);
        }
        target -= len;
    }
    (*last, last - first)
}

/// The unit tangent ∇f₁ × ∇f₂, `None` where the surfaces touch tangentially.
fn tangent(pair: [&Surface; 2], p: &Point3) -> Option<Vec3> {
    let t = pair[0].gradient(p).cross(&pair[1].gradient(p));
    let len = t.norm();
    (len > 0.0 && len.is_finite()).then(|| t / len)
}

/// The chord from a to b in 64 pieces, each point projected onto both
/// surfaces where that succeeds.
fn straight(pair: [&Surface; 2], a: &Point3, b: &Point3) -> Vec<Point3> {
    let n = 64;
    (0..=n)
        .map(|i| match i {
            0 => *a,
            i if i == n => *b,
            i => {
                let p = a + (b - a) * (i as f64 / n as f64);
                project_onto_pair(pair, &p).unwrap_or(p)
            }
        })
        .collect()
}

struct Marcher<'a> {
    pair: [&'a Surface; 2],
    a: Point3,
    b: Point3,
    closed: bool,
    h_min: f64,
    h_max: f64,
    max_len: f64,
}

impl Marcher<'_> {
    /// Marches from `a` with initial direction `t` until `b` is within reach;
    /// `None` when steps collapse, the budget runs out, or an open march
    /// comes back to its start without meeting `b`.
    fn run(&self, mut t: Vec3, mut h: f64) -> Option<Vec<Point3>> {
        let mut points = vec![self.a];
        let mut x = self.a;
        let mut travelled = 0.0;
        let mut left_start = false;
        for _ in 0..MAX_STEPS {
            if (!self.closed || left_start) && (self.b - x).norm() <= 1.5 * h {
                points.push(self.b);
                return Some(points);
            }
            if !self.closed && left_start && (self.a - x).norm() <= 1.5 * h {
                return None;
            }
            let accepted = project_onto_pair(self.pair, &(x + t * h)).and_then(|y| {
                let step = (y - x).norm();
                let t2 = tangent(self.pair, &y)?;
                let t2 = if t2.dot(&t) < 0.0 { -t2 } else { t2 };
                let turn = t.dot(&t2).clamp(-1.0, 1.0).acos();
                (turn <= MAX_TURN && step <= 2.0 * h && step > 0.0).then_some((y, t2, step, turn))
            });
            match accepted {
                Some((y, t2, step, turn)) => {
                    travelled += step;
                    (x, t) = (y, t2);
                    points.push(x);
                    if turn < SMALL_TURN {
                        h = (2.0 * h).min(self.h_max);
                    }
                    if (x - self.a).norm() > 3.0 * h {
                        left_start = true;
                    }
                    if travelled > self.max_len {
                        return None;
                    }
                }
                None => {
                    h /= 2.0;
                    if h < self.h_min {
                        return None;
                    }
                }
            }
        }
        None
    }
}
