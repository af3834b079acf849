//! Splitting poly_line pieces when the boundary is kept whole.
//!
//! In a face's last meshing round (`keep_boundary`) spade is told to keep
//! every constraint edge whole, and spade cannot tell the loops (which
//! other faces share, so they must not move) from the poly_lines (inside
//! one face, free to split). Left whole, a poly_line encroached by fine
//! triangles kept only its own points and collected slivers along it (a
//! crack at `--max-area` 0.0006 was then not opened). Here, between
//! refinement calls, each poly_line piece with an adjacent vertex inside
//! its diametral circle, or with an adjacent triangle below the angle
//! limit or above the area limit, is split at its middle; refinement then
//! runs again around the new vertex.

use super::face::{Cdt, on_segment};
use spade::handles::FixedVertexHandle;
use spade::{Point2, Triangulation};

/// Splits the encroached or badly surrounded poly_line pieces; returns how
/// many were split (0: the poly_lines are done). A piece shorter than twice
/// `min_length` (the tolerance: below the model's resolution) is left
/// whole: where a poly_line meets a side at a tiny angle, its pieces are
/// encroached and skinny however short they get (a crack ending on a corner
/// at 0.003° split without end).
pub(super) fn split_pieces(
    cdt: &mut Cdt,
    polyline_segments: &[(usize, usize)],
    min_angle_degrees: f64,
    max_area: f64,
    min_length: f64,
) -> Result<usize, String> {
    let cos_limit = min_angle_degrees.to_radians().cos();
    let mut pieces: Vec<(FixedVertexHandle, FixedVertexHandle, Point2<f64>)> = Vec::new();
    for edge in cdt.undirected_edges() {
        if !edge.is_constraint_edge() {
            continue;
        }
        let [a, b] = edge.vertices();
        let (pa, pb) = (a.position(), b.position());
        if (pb.x - pa.x).hypot(pb.y - pa.y) < 2.0 * min_length {
            continue;
        }
        let mid = Point2::new(0.5 * (pa.x + pb.x), 0.5 * (pa.y + pb.y));
        let (ia, ib) = (a.fix().index(), b.fix().index());
        let on_polyline = polyline_segments.iter().any(|&(p, q)| {
            (p == ia && q == ib) || (p == ib && q == ia) || on_segment(cdt, p, q, mid).is_some()
        });
        if !on_polyline {
            continue;
        }
        let directed = edge.as_directed();
        let bad = [directed, directed.rev()].iter().any(|side| {
            let Some(o) = side.opposite_position() else {
                return false;
            };
            let (u, v) = ([pa.x - o.x, pa.y - o.y], [pb.x - o.x, pb.y - o.y]);
            // The opposite vertex sees the piece at more than 90°.
            let encroached = u[0] * v[0] + u[1] * v[1] < 0.0;
            let area = 0.5 * (u[0] * v[1] - u[1] * v[0]).abs();
            encroached || area > max_area || skinny([pa, pb, o], cos_limit)
        });
        if bad {
            pieces.push((a.fix(), b.fix(), mid));
        }
    }
    for &(a, b, mid) in &pieces {
        let edge = cdt
            .get_edge_from_neighbors(a, b)
            .ok_or("a poly_line piece vanished while splitting")?
            .fix()
            .as_undirected();
        cdt.remove_constraint_edge(edge);
        let m = cdt
            .insert(mid)
            .map_err(|e| format!("a poly_line split point cannot be inserted: {e:?}"))?;
        if m == a || m == b || !cdt.can_add_constraint(a, m) || !cdt.can_add_constraint(m, b) {
            return Err("a poly_line piece cannot be split (it is too short)".into());
        }
        cdt.add_constraint(a, m);
        cdt.add_constraint(m, b);
    }
    Ok(pieces.len())
}

/// Whether the triangle has an angle whose cosine exceeds `cos_limit`.
fn skinny(p: [Point2<f64>; 3], cos_limit: f64) -> bool {
    (0..3).any(|k| {
        let (a, b, c) = (p[k], p[(k + 1) % 3], p[(k + 2) % 3]);
        let (u, v) = ([b.x - a.x, b.y - a.y], [c.x - a.x, c.y - a.y]);
        let norms = u[0].hypot(u[1]) * v[0].hypot(v[1]);
        norms > 0.0 && (u[0] * v[0] + u[1] * v[1]) / norms > cos_limit
    })
}
