//! Ruppert's boundary step, done here rather than by spade (which keeps the
//! constraint edges as they are): an encroached constraint edge is split at
//! its middle placed on the true boundary — on W = 0 for a trim edge, on the
//! side for a patch side — so no node is moved after it is triangulated; and
//! a periodic seam edge is split together with its twin on the other side,
//! so both sides of the seam stay node for node the same.

use super::TrimmedSurface;
use super::boundary::{self, Boundary, U_MAX, U_MIN, V_MAX, V_MIN};
use super::chart::ArcChart;
use crate::geom::Point3;
use spade::handles::FixedVertexHandle;
use spade::{ConstrainedDelaunayTriangulation, Point2, Triangulation};
use std::collections::HashMap;

pub(super) type Cdt = ConstrainedDelaunayTriangulation<Point2<f64>>;

/// The CDT's vertices in parameter space and on the surface, and what each
/// boundary vertex lies on.
pub(super) struct Nodes {
    pub uv: Vec<[f64; 2]>,
    pub xyz: Vec<Point3>,
    /// Side bits (U_MIN … V_MAX) per vertex; 0 for trim and interior points.
    pub sides: Vec<u8>,
    /// Seam twins of a periodic surface: `twin[0]` a U_MIN vertex ↔ its
    /// U_MAX vertex (same v), `twin[1]` a V_MIN vertex ↔ its V_MAX vertex.
    pub twin: [HashMap<usize, usize>; 2],
    /// Sides whose edges are never split (a pole cap's ring).
    pub fixed: u8,
}

/// The side bits of the two sides of each parameter's seam.
pub(super) const SEAM: [u8; 2] = [U_MIN | U_MAX, V_MIN | V_MAX];

impl Nodes {
    /// Side bits and seam twins of the boundary points (`handles[p]` is the
    /// vertex of boundary point p); `periodic[a]` when parameter a (u, v) closes.
    pub fn mark_boundary(
        &mut self,
        b: &Boundary,
        handles: &[usize],
        periodic: [bool; 2],
        rect: [f64; 4],
    ) {
        self.sides = vec![0; self.uv.len()];
        self.fixed = b.fixed;
        for (p, &h) in handles.iter().enumerate() {
            if let (Some(slot), Some(&bits)) = (self.sides.get_mut(h), b.sides.get(p)) {
                *slot |= bits;
            }
        }
        for axis in 0..2 {
            if !periodic[axis] {
                continue;
            }
            // Twins share the other parameter.
            let along = 1 - axis;
            let (low_bit, high_bit) = (SEAM[axis] & (U_MIN | V_MIN), SEAM[axis] & (U_MAX | V_MAX));
            let eps = 1e-9 * (rect[2 * along + 1] - rect[2 * along]);
            let mut low: Vec<(f64, usize)> = (0..self.uv.len())
                .filter(|&h| self.sides[h] & low_bit != 0)
                .map(|h| (self.uv[h][along], h))
                .collect();
            low.sort_by(|x, y| x.0.total_cmp(&y.0));
            for h in 0..self.uv.len() {
                if self.sides[h] & high_bit == 0 {
                    continue;
                }
                let t = self.uv[h][along];
                let at = low.partition_point(|x| x.0 < t - eps);
                if let Some(&(lt, lh)) = low.get(at)
                    && (lt - t).abs() <= eps
                {
                    self.twin[axis].insert(h, lh);
                    self.twin[axis].insert(lh, h);
                }
            }
        }
    }

    fn push(&mut self, s: &TrimmedSurface, uv: [f64; 2], sides: u8) {
        self.uv.push(uv);
        self.xyz.push(s.point(uv[0], uv[1]));
        self.sides.push(sides);
    }

    fn pop(&mut self) {
        self.uv.pop();
        self.xyz.pop();
        self.sides.pop();
    }

    /// Records the vertices spade added (interior points).
    pub fn sync(&mut self, cdt: &Cdt, arc: &ArcChart, s: &TrimmedSurface) {
        for v in self.uv.len()..cdt.num_vertices() {
            let q = cdt.vertex(FixedVertexHandle::from_index(v)).position();
            self.push(s, arc.to_param([q.x, q.y]), 0);
        }
    }
}

/// Splits the constraint edge x–y (and its seam twin); false when it is no
/// longer a constraint edge or cannot be split without crossing another.
pub(super) fn split_constraint(
    cdt: &mut Cdt,
    arc: &ArcChart,
    s: &TrimmedSurface,
    nodes: &mut Nodes,
    x: usize,
    y: usize,
) -> bool {
    let common = nodes.sides[x] & nodes.sides[y];
    let (cx, cy) = (arc.to_chart(nodes.uv[x]), arc.to_chart(nodes.uv[y]));
    let middle = arc.to_param([0.5 * (cx[0] + cy[0]), 0.5 * (cx[1] + cy[1])]);
    let uv = if common != 0 {
        snap_to_side(middle, common, s.rect)
    } else {
        let on_trim = boundary::project(s, middle, nodes.uv[x], nodes.uv[y]);
        // A root far from the chord (another branch of W = 0) is not this edge's.
        let c = arc.to_chart(on_trim);
        let half = 0.5 * (cx[0] - cy[0]).hypot(cx[1] - cy[1]);
        let m = [0.5 * (cx[0] + cy[0]), 0.5 * (cx[1] + cy[1])];
        if (c[0] - m[0]).hypot(c[1] - m[1]) <= 0.5 * half {
            on_trim
        } else {
            middle
        }
    };
    // An edge along a seam side is split with its twin on the other side.
    let seam = (0..2).find_map(|axis| {
        let bits = common & SEAM[axis];
        if bits == 0 {
            return None;
        }
        let (tx, ty) = (nodes.twin[axis].get(&x)?, nodes.twin[axis].get(&y)?);
        Some((axis, bits, *tx, *ty))
    });
    let Some(n) = split_at(cdt, arc, s, nodes, x, y, uv, common) else {
        return false;
    };
    if let Some((axis, bits, tx, ty)) = seam {
        let mut other = uv;
        let low = bits & (U_MIN | V_MIN) != 0;
        other[axis] = if low {
            s.rect[2 * axis + 1]
        } else {
            s.rect[2 * axis]
        };
        let sides = (common & !SEAM[axis]) | (bits ^ SEAM[axis]);
        let Some(m) = split_at(cdt, arc, s, nodes, tx, ty, other, sides) else {
            undo(cdt, nodes, x, y);
            return false;
        };
        nodes.twin[axis].insert(n, m);
        nodes.twin[axis].insert(m, n);
    }
    true
}

/// Replaces the constraint x–y by x–n–y with a new vertex n at `uv`.
#[allow(clippy::too_many_arguments)]
fn split_at(
    cdt: &mut Cdt,
    arc: &ArcChart,
    s: &TrimmedSurface,
    nodes: &mut Nodes,
    x: usize,
    y: usize,
    uv: [f64; 2],
    sides: u8,
) -> Option<usize> {
    let (hx, hy) = (
        FixedVertexHandle::from_index(x),
        FixedVertexHandle::from_index(y),
    );
    let edge = cdt.get_edge_from_neighbors(hx, hy)?.as_undirected().fix();
    if !cdt.remove_constraint_edge(edge) {
        return None;
    }
    let c = arc.to_chart(uv);
    let restore = |cdt: &mut Cdt| {
        cdt.try_add_constraint(hx, hy);
    };
    let Ok(hn) = cdt.insert_with_hint(Point2::new(c[0], c[1]), hx) else {
        restore(cdt);
        return None;
    };
    if hn.index() != nodes.uv.len() {
        // The point is an existing vertex.
        restore(cdt);
        return None;
    }
    nodes.push(s, uv, sides);
    let first = cdt.try_add_constraint(hx, hn);
    let second = if first.len() == 1 {
        cdt.try_add_constraint(hn, hy)
    } else {
        Vec::new()
    };
    if first.len() != 1 || second.len() != 1 {
        undo(cdt, nodes, x, y);
        return None;
    }
    Some(hn.index())
}

/// Removes the last vertex (with its constraints) and restores x–y.
fn undo(cdt: &mut Cdt, nodes: &mut Nodes, x: usize, y: usize) {
    let last = FixedVertexHandle::from_index(cdt.num_vertices() - 1);
    cdt.remove(last);
    nodes.pop();
    cdt.try_add_constraint(
        FixedVertexHandle::from_index(x),
        FixedVertexHandle::from_index(y),
    );
}

pub(super) fn snap_to_side(uv: [f64; 2], side: u8, rect: [f64; 4]) -> [f64; 2] {
    let mut uv = uv;
    if side & U_MIN != 0 {
        uv[0] = rect[0];
    }
    if side & U_MAX != 0 {
        uv[0] = rect[1];
    }
    if side & V_MIN != 0 {
        uv[1] = rect[2];
    }
    if side & V_MAX != 0 {
        uv[1] = rect[3];
    }
    uv
}
