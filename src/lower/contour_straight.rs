//! Straight stretches of a traced region contour (issue 6): `grade` keeps
//! neighbouring contour pieces within 1.5× of each other by halving, so one
//! short piece where the contour leaves a straight line (a cut corner) makes
//! every piece of that line as short as it (the outer circle's patch had
//! about 210 pieces of 0.008 along x = 0.5). A run of pieces whose points
//! all lie on one line within [`STRAIGHT_FRACTION`] of the box diagonal is
//! laid out again on that line, graded: piece lengths grow from each end's
//! neighbour by at most [`GROWTH`] per piece, so the interface's elements
//! are sized by the area limit and the line's length, not by the corner.

use crate::trimmed::TrimmedSurface;
use crate::trimmed::boundary;

/// How far a contour point may be from the chord of its run to count as on a
/// straight line, as a fraction of the box diagonal: the traced points lie on
/// f = 0 to root finding's precision, and a curved stretch's pieces (sized to
/// the chordal tolerance, 5e-4 of the diagonal) bulge far more than this.
pub(super) const STRAIGHT_FRACTION: f64 = 1e-7;

/// The growth of piece lengths from a run's ends towards its middle, under
/// the contour's grading bound (1.5), so that a run laid out again needs no
/// split by `grade`.
const GROWTH: f64 = 1.3;

/// The most points one run is checked over (the chord check is quadratic in
/// its length); a longer straight line is laid out as several runs.
const MAX_RUN: usize = 4096;

/// Lays the straight runs of the closed loop `points` (box-side flags
/// `sides`, 0 on f = 0) out again with graded pieces. Only points on f = 0
/// are replaced; box sides and the points where a run starts or ends stay.
pub(super) fn merge_straight_runs(
    s: &TrimmedSurface,
    points: &mut Vec<[f64; 2]>,
    sides: &mut Vec<u8>,
    tol: f64,
) {
    let n = points.len();
    // A start that is no run's inside: a box-side point, or a corner.
    let Some(origin) = (0..n).find(|&k| !inside_run(points, sides, k, tol)) else {
        return;
    };
    let at = |k: usize| (origin + k) % n;
    let mut out: Vec<[f64; 2]> = Vec::with_capacity(n);
    let mut out_sides: Vec<u8> = Vec::with_capacity(n);
    let mut i = 0;
    while i < n {
        out.push(points[at(i)]);
        out_sides.push(sides[at(i)]);
        let j = run_end(points, sides, origin, i, tol);
        if j >= i + 2 {
            let (a, b) = (points[at(i)], points[at(j)]);
            let before = match out.len() {
                0 | 1 => length(points[at(n - 1)], a),
                m => length(out[m - 2], a),
            };
            let after = length(b, points[at(j + 1)]);
            for p in layout(a, b, before, after) {
                out.push(boundary::project(s, p, a, b));
                out_sides.push(0);
            }
        }
        i = if j >= i + 2 { j } else { i + 1 };
    }
    *points = out;
    *sides = out_sides;
}

fn length(a: [f64; 2], b: [f64; 2]) -> f64 {
    (b[0] - a[0]).hypot(b[1] - a[1])
}

/// The distance of p from the line through a and b.
fn off_line(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let d = [b[0] - a[0], b[1] - a[1]];
    let len = d[0].hypot(d[1]);
    if len == 0.0 {
        return length(p, a);
    }
    ((p[0] - a[0]) * d[1] - (p[1] - a[1]) * d[0]).abs() / len
}

/// Whether point k lies on f = 0 between two pieces on one line.
fn inside_run(points: &[[f64; 2]], sides: &[u8], k: usize, tol: f64) -> bool {
    let n = points.len();
    let (a, b) = (points[(k + n - 1) % n], points[(k + 1) % n]);
    sides[k] == 0 && off_line(points[k], a, b) <= tol
}

/// The last loop position j ≥ i (positions counted from `origin`) such that
/// every point between i and j lies on f = 0 and on the chord i → j within
/// `tol`; the run ends at the loop's end (the origin is no run's inside).
fn run_end(points: &[[f64; 2]], sides: &[u8], origin: usize, i: usize, tol: f64) -> usize {
    let n = points.len();
    let at = |k: usize| (origin + k) % n;
    let mut j = i + 1;
    while j < n && j - i < MAX_RUN && sides[at(j)] == 0 {
        let (a, b) = (points[at(i)], points[at(j + 1)]);
        if !(i + 1..=j).all(|k| off_line(points[at(k)], a, b) <= tol) {
            break;
        }
        j += 1;
    }
    j
}

/// The inner points of the straight piece a → b laid out with lengths
/// growing by at most [`GROWTH`] per piece from `before` (the piece ending
/// at a) and from `after` (the piece starting at b). The size grows linearly
/// with the distance from the nearer end, h(t) = h₀ + c·t with c = ln GROWTH,
/// and the k-th point is where ∫ dt/h reaches k times the integral over the
/// whole piece divided by the (rounded up) count: neighbouring pieces then
/// differ by at most e^c = GROWTH, and the first is at most (e^c − 1)/c ≈
/// 1.14 times its outer neighbour.
fn layout(a: [f64; 2], b: [f64; 2], before: f64, after: f64) -> Vec<[f64; 2]> {
    let total = length(a, b);
    if total == 0.0 || before <= 0.0 || after <= 0.0 {
        return Vec::new();
    }
    let c = GROWTH.ln();
    // Where the two sizes meet, and the size there from either side.
    let meet = ((after - before + c * total) / (2.0 * c)).clamp(0.0, total);
    let (peak_a, peak_b) = (before + c * meet, after + c * (total - meet));
    let phi_meet = (peak_a / before).ln() / c;
    let phi_total = phi_meet + (peak_b / after).ln() / c;
    let count = phi_total.ceil().max(1.0) as usize;
    (1..count)
        .map(|k| {
            let phi = phi_total * k as f64 / count as f64;
            let t = if phi <= phi_meet {
                before * ((c * phi).exp() - 1.0) / c
            } else {
                total - (peak_b * (-c * (phi - phi_meet)).exp() - after) / c
            };
            let f = (t / total).clamp(0.0, 1.0);
            [a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1])]
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::layout;

    #[test]
    fn a_long_line_between_short_pieces_is_graded_in_a_few_pieces() {
        let points = layout([0.0, 0.0], [0.0, 1.7], 0.008, 0.008);
        let mut stops = vec![0.0];
        stops.extend(points.iter().map(|p| p[1]));
        stops.push(1.7);
        let lengths: Vec<f64> = stops.windows(2).map(|w| w[1] - w[0]).collect();
        // 212 pieces of 0.008 before; grown by 1.3 from both ends about 30.
        assert!((20..=34).contains(&lengths.len()), "{}", lengths.len());
        let mut all = vec![0.008];
        all.extend(&lengths);
        all.push(0.008);
        for w in all.windows(2) {
            let ratio = w[0].max(w[1]) / w[0].min(w[1]);
            assert!(ratio <= 1.5, "{lengths:?}");
        }
        assert!(points.iter().all(|p| p[0] == 0.0));
    }

    #[test]
    fn a_line_as_short_as_its_neighbours_keeps_one_piece() {
        assert!(layout([0.0, 0.0], [1.0, 0.0], 1.0, 1.0).is_empty());
    }
}
