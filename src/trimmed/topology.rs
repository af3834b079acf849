//! The boundary pieces of a trimmed surface for the topology IR (issue 9):
//! the trim loops traced as for meshing (marching squares on the grid the
//! chart's lengths give, short edges merged) and cut where a loop passes
//! from a trim curve to a patch side or from one side to another. Pieces
//! on a periodic seam (no boundary on the surface) and degenerate pieces (a
//! pole side, no length in 3D) are left out. Meshing traces again at its own
//! tolerance; these pieces only name the chains and their ends.

use super::TrimmedSurface;
use super::boundary;
use super::chart::ArcChart;
use super::triangulate::{TrimSettings, element_size, is_periodic};
use crate::geom::Point3;

/// One piece of a boundary loop, in the loop's direction.
#[derive(Debug, Clone, PartialEq)]
pub struct Piece {
    /// Global points; a closed piece repeats its first point last.
    pub points: Vec<Point3>,
    /// 0 for a trim curve, else the rectangle side's bit (`boundary::U_MIN`…).
    pub side: u8,
}

/// The pieces of every boundary loop of `s`, loop by loop, traced at
/// `tolerance` (the model's).
pub fn pieces(s: &TrimmedSurface, tolerance: f64) -> Result<Vec<Vec<Piece>>, String> {
    let [u0, u1, v0, v1] = s.rect;
    if !(u1 > u0 && v1 > v0) {
        return Err(format!(
            "the parameter rectangle [{u0}, {u1}] × [{v0}, {v1}] is empty"
        ));
    }
    let arc = ArcChart::new(s)?;
    let (lu, lv) = arc.lengths();
    let extent = lu.hypot(lv);
    let settings = TrimSettings {
        tolerance,
        min_angle: 0.0,
        max_edge: f64::INFINITY,
    };
    let h = element_size(lu, lv, &settings);
    let nu = ((lu / h).ceil() as usize).clamp(4, 2048);
    let nv = ((lv / h).ceil() as usize).clamp(4, 2048);
    let mut b = boundary::trace(s, [nu, nv])?;
    b.merge_short(s, 0.4 * (lu / nu as f64).hypot(lv / nv as f64));
    let periodic = [is_periodic(s, 0, extent), is_periodic(s, 1, extent)];
    let seam = |side: u8| {
        (periodic[0] && side & (boundary::U_MIN | boundary::U_MAX) != 0)
            || (periodic[1] && side & (boundary::V_MIN | boundary::V_MAX) != 0)
    };
    let degenerate = 1e-9 * extent.max(f64::MIN_POSITIVE);
    let mut out = Vec::with_capacity(b.loops.len());
    for lp in &b.loops {
        let n = lp.len();
        if n < 2 {
            continue;
        }
        // Material on the left in (u, v), so the loops run counter-clockwise
        // about R_u × R_v as the face's loops must (the trace leaves the
        // direction to the order it met the crossings).
        let reversed: Vec<usize>;
        let lp = if material_on_left(s, &b.points, lp) {
            lp
        } else {
            reversed = lp.iter().rev().copied().collect();
            &reversed
        };
        // The class of segment i (lp[i] → lp[i + 1]): the side both ends lie
        // on, 0 on a trim curve.
        let class: Vec<u8> = (0..n)
            .map(|i| b.sides[lp[i]] & b.sides[lp[(i + 1) % n]])
            .map(|c| c & c.wrapping_neg())
            .collect();
        let start = (0..n).find(|&i| class[i] != class[(i + n - 1) % n]);
        let mut pieces: Vec<Piece> = Vec::new();
        let mut current: Option<Piece> = None;
        let first = start.unwrap_or(0);
        for k in 0..n {
            let i = (first + k) % n;
            let a = b.points[lp[i]];
            let c = b.points[lp[(i + 1) % n]];
            let piece = match current.take() {
                Some(p) if p.side == class[i] => p,
                other => {
                    pieces.extend(other);
                    Piece {
                        points: vec![s.point(a[0], a[1])],
                        side: class[i],
                    }
                }
            };
            let mut piece = piece;
            piece.points.push(s.point(c[0], c[1]));
            current = Some(piece);
        }
        pieces.extend(current);
        pieces.retain(|p| {
            let length: f64 = p.points.windows(2).map(|w| (w[1] - w[0]).norm()).sum();
            !seam(p.side) && length > degenerate && length.is_finite()
        });
        out.push(pieces);
    }
    join_across_seams(&mut out, 2.0 * tolerance);
    Ok(out)
}

/// Whether the material lies left of the loop: tested beside its longest
/// segment, a point off the rectangle counting as no material.
fn material_on_left(s: &TrimmedSurface, points: &[[f64; 2]], lp: &[usize]) -> bool {
    let n = lp.len();
    let Some(i) = (0..n).max_by(|&i, &j| {
        let len = |k: usize| {
            let (a, b) = (points[lp[k]], points[lp[(k + 1) % n]]);
            (b[0] - a[0]).hypot(b[1] - a[1])
        };
        len(i).total_cmp(&len(j))
    }) else {
        return true;
    };
    let (a, b) = (points[lp[i]], points[lp[(i + 1) % n]]);
    let d = [b[0] - a[0], b[1] - a[1]];
    let m = [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])];
    let [u0, u1, v0, v1] = s.rect;
    let w = |sign: f64| {
        let p = [m[0] - sign * 1e-3 * d[1], m[1] + sign * 1e-3 * d[0]];
        let inside = p[0] >= u0 && p[0] <= u1 && p[1] >= v0 && p[1] <= v1;
        if inside {
            s.material(p[0], p[1])
        } else {
            f64::NEG_INFINITY
        }
    };
    w(1.0) >= w(-1.0)
}

/// Joins trim pieces that a periodic seam cut (one ends where another
/// begins, at a point no side piece touches), so a hole across the seam is
/// one closed trim piece, as the mesh joins its chain again.
fn join_across_seams(loops: &mut [Vec<Piece>], distance: f64) {
    let ends = |p: &Piece| (p.points[0], p.points[p.points.len() - 1]);
    loop {
        let all: Vec<(usize, usize)> = (0..loops.len())
            .flat_map(|l| (0..loops[l].len()).map(move |i| (l, i)))
            .collect();
        let touches_side = |q: &Point3, loops: &[Vec<Piece>]| {
            loops.iter().flatten().filter(|p| p.side != 0).any(|p| {
                let (a, b) = ends(p);
                (a - q).norm() <= distance || (b - q).norm() <= distance
            })
        };
        let pair = all.iter().find_map(|&(l, i)| {
            let p = &loops[l][i];
            let (a, b) = ends(p);
            if p.side != 0 || (a - b).norm() <= distance || touches_side(&b, loops) {
                return None;
            }
            all.iter()
                .find(|&&(l2, j)| {
                    let q = &loops[l2][j];
                    (l2, j) != (l, i) && q.side == 0 && (ends(q).0 - b).norm() <= distance
                })
                .map(|&(l2, j)| ((l, i), (l2, j)))
        });
        let Some(((l, i), (l2, j))) = pair else {
            return;
        };
        let tail = loops[l2][j].points[1..].to_vec();
        loops[l][i].points.extend(tail);
        loops[l2].remove(j);
        // Removing an earlier piece of the same loop shifts this one back.
        let i = if l2 == l && j < i { i - 1 } else { i };
        let p = &mut loops[l][i];
        let (a, b) = ends(p);
        if (a - b).norm() <= distance {
            let n = p.points.len();
            p.points[n - 1] = a;
        }
    }
}
