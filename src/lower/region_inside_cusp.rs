//! The kernel arc next to a carved region's inside touch (issue 6): where a
//! region inside a kernel circle or ellipse touches it, the arc bends
//! towards the region on both sides of the touch point, and the chords the
//! mesher lays on the arc (to its chordal tolerance, up to 1e-3 of the
//! model's diagonal deep by default) would cross the contour's first
//! pieces, which stay closer to the arc than that. The arc is cut next to
//! the touch point at the projections of contour vertices, as few as keep
//! every contour vertex and piece middle strictly on the centre's side of
//! each chord between cuts, out to the first contour vertex farther from
//! the arc than `GAP_FRACTION` of the model's diagonal: beyond it a chord
//! of the arc cannot reach the contour.

use super::region_arcs::KernelCurve;
use super::region_touch::vertex_at;
use crate::geom::Point3;
use crate::ir::{EdgeId, Model, OrientedEdge};

/// How far from the arc the contour must be where the cuts stop, as a
/// fraction of the model's diagonal: twice the default chordal tolerance.
const GAP_FRACTION: f64 = 2e-3;

/// Contour vertices looked at on each side of a touch point, at most.
const MAX_WALK: usize = 4096;

/// The parameters where kernel edge `edge` is cut next to the touch point
/// `touch` (on it, or at its end) of the region loop `lp`, whose vertex `at`
/// goes there: walking the loop from it both ways, as far as it runs along
/// the edge. None for a straight edge or a region on the arc's convex side.
pub(super) fn arc_cuts(
    model: &Model,
    edge: EdgeId,
    lp: &[OrientedEdge],
    at: usize,
    touch: Point3,
) -> Vec<f64> {
    let gap = GAP_FRACTION * model.bbox().diagonal();
    let Some(kc) = KernelCurve::of(&model.edge_curve(edge)) else {
        return Vec::new();
    };
    let Some(center) = kc.center() else {
        return Vec::new();
    };
    let span = kc.span();
    let n = lp.len();
    let inside = |u: f64| u > 0.0 && u < span;
    let mut cuts = Vec::new();
    for step in [1, n - 1] {
        let first = model.vertex(vertex_at(model, lp, at + step)).position;
        // The region must lie on the arc's concave side (inside a circle);
        // against a hole's rim the chords bend away from it.
        if !inside(kc.parameter(&first)) || (first - touch).dot(&(center - touch)) <= 0.0 {
            continue;
        }
        // (parameter, projection, the points to keep inside before it).
        let mut walk: Vec<(f64, Point3, Vec<Point3>)> = Vec::new();
        for k in 1..=MAX_WALK.min(n - 1) {
            let i = (at + k * step) % n;
            let q = model.vertex(vertex_at(model, lp, i)).position;
            let u = kc.parameter(&q);
            if !inside(u) {
                break;
            }
            let piece = if step == 1 {
                lp[(i + n - 1) % n]
            } else {
                lp[i]
            };
            let middle = model.edge_curve(piece.edge).point(0.5);
            let k_point = kc.point(u);
            walk.push((u, k_point, vec![middle, q]));
            if (k_point - q).norm() > gap {
                break;
            }
        }
        cuts.extend(greedy_cuts(touch, center, &walk));
    }
    cuts.sort_by(f64::total_cmp);
    cuts.dedup();
    cuts
}

/// The fewest cuts among the walk's projections such that every point
/// between two cuts lies strictly on the centre's side of their chord; the
/// walk's last projection is always cut.
fn greedy_cuts(touch: Point3, center: Point3, walk: &[(f64, Point3, Vec<Point3>)]) -> Vec<f64> {
    let side = |a: Point3, b: Point3, p: Point3| {
        let (d, e) = (b - a, p - a);
        d.x * e.y - d.y * e.x
    };
    let clear = |a: Point3, from: usize, to: usize| {
        let b = walk[to].1;
        let c = side(a, b, center);
        walk[from..=to]
            .iter()
            .flat_map(|w| w.2.iter())
            .filter(|&&p| p != b)
            .all(|&p| side(a, b, p) * c > 0.0)
    };
    let mut cuts = Vec::new();
    let (mut a, mut from) = (touch, 0);
    let mut j = 0;
    while j < walk.len() {
        if j > from && !clear(a, from, j) {
            // The chord from the last cut to j would pass a point: cut
            // before j.
            cuts.push(walk[j - 1].0);
            a = walk[j - 1].1;
            from = j;
            continue;
        }
        j += 1;
    }
    if let Some(last) = walk.last() {
        cuts.push(last.0);
    }
    cuts
}
