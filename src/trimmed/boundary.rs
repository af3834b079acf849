//! Stage 1 of paper 002: the boundary of the kept region in (u, v). The sign
//! of W = ±F(R(u, v)) is sampled on a background grid; each cell with a sign
//! change gives boundary segments whose ends are placed on W = 0 by root
//! finding on the cell's edges; a cell with opposite corners of equal sign
//! (ambiguous) is split in four with new samples. The rectangle's sides
//! close the loops where material reaches them. Segments are chained into
//! loops, points closer (in 3D) than a fraction of the cell diagonal are
//! merged, and edges are split until their chord is within the tolerance.

use super::TrimmedSurface;
use std::collections::HashMap;

/// Side bits of a point on the parameter rectangle.
pub const U_MIN: u8 = 1;
pub const U_MAX: u8 = 2;
pub const V_MIN: u8 = 4;
pub const V_MAX: u8 = 8;

/// Closed loops of boundary points in (u, v).
#[derive(Debug, Clone, Default)]
pub struct Boundary {
    pub points: Vec<[f64; 2]>,
    /// Which rectangle sides each point lies on.
    pub sides: Vec<u8>,
    /// Loops of point indices (closed: the last joins the first).
    pub loops: Vec<Vec<usize>>,
    /// Sides whose points are fixed (a pole cap's ring): never split.
    pub fixed: u8,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
enum Key {
    /// Crossing on the grid edge from node (i, j) along u (0) or v (1).
    Edge(u32, u32, u8),
    /// A grid node on the rectangle's border.
    Node(u32, u32),
    /// Crossing on the inner half-edge `k` of a split cell.
    Inner(u32, u32, u8),
}

/// An edge of a (sub)cell: where a crossing on it is found and named.
#[derive(Clone, Copy)]
struct CellEdge {
    key: Key,
    a: [f64; 2],
    b: [f64; 2],
    wa: f64,
    wb: f64,
}

struct Builder<'a> {
    s: &'a TrimmedSurface,
    points: Vec<[f64; 2]>,
    sides: Vec<u8>,
    index: HashMap<Key, usize>,
    segments: Vec<[usize; 2]>,
}

impl Builder<'_> {
    fn point(&mut self, key: Key, make: impl FnOnce(&TrimmedSurface) -> ([f64; 2], u8)) -> usize {
        if let Some(&i) = self.index.get(&key) {
            return i;
        }
        let (uv, side) = make(self.s);
        self.points.push(uv);
        self.sides.push(side);
        self.index.insert(key, self.points.len() - 1);
        self.points.len() - 1
    }

    fn crossing(&mut self, e: CellEdge) -> usize {
        let rect = self.s.rect;
        self.point(e.key, |s| {
            let uv = root(s, e.a, e.b, e.wa, e.wb);
            (uv, side_bits(uv, rect))
        })
    }

    /// Marching squares on one square (corners counter-clockwise, edge k
    /// from corner k to k + 1); `depth` 0 may split an ambiguous square.
    fn square(
        &mut self,
        corners: [[f64; 2]; 4],
        w: [f64; 4],
        edges: [CellEdge; 4],
        cell: (u32, u32),
        depth: u8,
    ) {
        let inside = w.map(|x| x >= 0.0);
        let crossing: Vec<usize> = (0..4)
            .filter(|&k| inside[k] != inside[(k + 1) % 4])
            .collect();
        match crossing.len() {
            2 => {
                let a = self.crossing(edges[crossing[0]]);
                let b = self.crossing(edges[crossing[1]]);
                if a != b {
                    self.segments.push([a, b]);
                }
            }
            4 if depth == 0 => self.split(corners, w, edges, cell),
            4 => {
                // Still ambiguous after the split: the centre's sign decides
                // which corners are joined.
                let c = [
                    0.25 * corners.iter().map(|p| p[0]).sum::<f64>(),
                    0.25 * corners.iter().map(|p| p[1]).sum::<f64>(),
                ];
                let joined = (self.s.material(c[0], c[1]) >= 0.0) == inside[0];
                let pairs = if joined {
                    [(0, 3), (1, 2)]
                } else {
                    [(0, 1), (2, 3)]
                };
                for (x, y) in pairs {
                    let a = self.crossing(edges[x]);
                    let b = self.crossing(edges[y]);
                    if a != b {
                        self.segments.push([a, b]);
                    }
                }
            }
            _ => {}
        }
    }

    /// Splits an ambiguous cell in four. A half of an outer edge keeps the
    /// edge's own crossing (found on the whole edge, as the neighbour finds
    /// it); the midpoint sample is made to agree with that.
    fn split(&mut self, c: [[f64; 2]; 4], w: [f64; 4], edges: [CellEdge; 4], cell: (u32, u32)) {
        let mid = |a: [f64; 2], b: [f64; 2]| [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0];
        let m: [[f64; 2]; 4] = std::array::from_fn(|k| mid(c[k], c[(k + 1) % 4]));
        let center = mid(c[0], c[2]);
        let wc = self.s.material(center[0], center[1]);
        let wm: [f64; 4] = std::array::from_fn(|k| {
            let x = self.s.material(m[k][0], m[k][1]);
            let (a, b) = (w[k] >= 0.0, w[(k + 1) % 4] >= 0.0);
            // Same sign at both ends: the neighbour sees no crossing, so
            // neither may the halves.
            if a == b && (x >= 0.0) != a {
                if a { 0.0 } else { -f64::MIN_POSITIVE }
            } else {
                x
            }
        });
        let inner = |k: u8, a: [f64; 2], b: [f64; 2], wa: f64, wb: f64| CellEdge {
            key: Key::Inner(cell.0, cell.1, k),
            a,
            b,
            wa,
            wb,
        };
        // Inner half-edges: from midpoint k to the centre.
        let spokes: [CellEdge; 4] =
            std::array::from_fn(|k| inner(k as u8, m[k], center, wm[k], wc));
        for k in 0..4 {
            // Sub-square at corner k: corner k, mid k, centre, mid k−1.
            let prev = (k + 3) % 4;
            let corners = [c[k], m[k], center, m[prev]];
            let values = [w[k], wm[k], wc, wm[prev]];
            let reversed = |e: CellEdge| CellEdge {
                a: e.b,
                b: e.a,
                wa: e.wb,
                wb: e.wa,
                ..e
            };
            let sub_edges = [
                half(edges[k], c[k], m[k], w[k], wm[k]),
                spokes[k],
                reversed(spokes[prev]),
                half(edges[prev], m[prev], c[k], wm[prev], w[k]),
            ];
            self.square(corners, values, sub_edges, cell, 1);
        }
    }
}

/// The half of an outer edge between `a` and `b`: the whole edge's crossing
/// when the half holds it.
fn half(edge: CellEdge, a: [f64; 2], b: [f64; 2], wa: f64, wb: f64) -> CellEdge {
    if (edge.wa >= 0.0) != (edge.wb >= 0.0) {
        edge
    } else {
        CellEdge {
            a,
            b,
            wa,
            wb,
            ..edge
        }
    }
}

fn side_bits(uv: [f64; 2], rect: [f64; 4]) -> u8 {
    let eps = 1e-12 * ((rect[1] - rect[0]).abs() + (rect[3] - rect[2]).abs());
    let mut bits = 0;
    if (uv[0] - rect[0]).abs() <= eps {
        bits |= U_MIN;
    }
    if (uv[0] - rect[1]).abs() <= eps {
        bits |= U_MAX;
    }
    if (uv[1] - rect[2]).abs() <= eps {
        bits |= V_MIN;
    }
    if (uv[1] - rect[3]).abs() <= eps {
        bits |= V_MAX;
    }
    bits
}

/// W = 0 between a and b (opposite signs) by the Illinois false position.
fn root(s: &TrimmedSurface, a: [f64; 2], b: [f64; 2], wa: f64, wb: f64) -> [f64; 2] {
    let at = |t: f64| [a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t];
    let (mut t0, mut t1, mut f0, mut f1) = (0.0f64, 1.0f64, wa, wb);
    let mut side = 0;
    for _ in 0..60 {
        let t = if (f1 - f0).abs() > 0.0 && f0.is_finite() && f1.is_finite() {
            (t0 * f1 - t1 * f0) / (f1 - f0)
        } else {
            0.5 * (t0 + t1)
        };
        let t = if t > t0.min(t1) && t < t0.max(t1) {
            t
        } else {
            0.5 * (t0 + t1)
        };
        let p = at(t);
        let f = s.material(p[0], p[1]);
        if !f.is_finite() || f == 0.0 || (t1 - t0).abs() < 1e-13 {
            return p;
        }
        if (f >= 0.0) == (f1 >= 0.0) {
            t1 = t;
            f1 = f;
            if side == 1 {
                f0 *= 0.5;
            }
            side = 1;
        } else {
            t0 = t;
            f0 = f;
            if side == -1 {
                f1 *= 0.5;
            }
            side = -1;
        }
    }
    at(0.5 * (t0 + t1))
}

/// The grid, in cells per direction, and the boundary it gives.
pub fn trace(s: &TrimmedSurface, cells: [usize; 2]) -> Result<Boundary, String> {
    let [nu, nv] = cells;
    let [u0, u1, v0, v1] = s.rect;
    let us: Vec<f64> = (0..=nu)
        .map(|i| u0 + (u1 - u0) * i as f64 / nu as f64)
        .collect();
    let vs: Vec<f64> = (0..=nv)
        .map(|j| v0 + (v1 - v0) * j as f64 / nv as f64)
        .collect();
    let mut w = vec![0.0; (nu + 1) * (nv + 1)];
    for j in 0..=nv {
        for i in 0..=nu {
            let x = s.material(us[i], vs[j]);
            if !x.is_finite() {
                return Err(format!(
                    "the trim has no finite value at (u, v) = ({}, {})",
                    us[i], vs[j]
                ));
            }
            w[j * (nu + 1) + i] = x;
        }
    }
    let at = |i: usize, j: usize| w[j * (nu + 1) + i];
    let mut b = Builder {
        s,
        points: Vec::new(),
        sides: Vec::new(),
        index: HashMap::new(),
        segments: Vec::new(),
    };
    let edge_u = |i: usize, j: usize| CellEdge {
        key: Key::Edge(i as u32, j as u32, 0),
        a: [us[i], vs[j]],
        b: [us[i + 1], vs[j]],
        wa: at(i, j),
        wb: at(i + 1, j),
    };
    let edge_v = |i: usize, j: usize| CellEdge {
        key: Key::Edge(i as u32, j as u32, 1),
        a: [us[i], vs[j]],
        b: [us[i], vs[j + 1]],
        wa: at(i, j),
        wb: at(i, j + 1),
    };
    let rev = |e: CellEdge| CellEdge {
        a: e.b,
        b: e.a,
        wa: e.wb,
        wb: e.wa,
        ..e
    };
    for j in 0..nv {
        for i in 0..nu {
            let corners = [
                [us[i], vs[j]],
                [us[i + 1], vs[j]],
                [us[i + 1], vs[j + 1]],
                [us[i], vs[j + 1]],
            ];
            let values = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)];
            let edges = [
                edge_u(i, j),
                edge_v(i + 1, j),
                rev(edge_u(i, j + 1)),
                rev(edge_v(i, j)),
            ];
            b.square(corners, values, edges, (i as u32, j as u32), 0);
        }
    }
    // The rectangle's sides where material reaches them.
    let rect = s.rect;
    let border = |b: &mut Builder, e: CellEdge, na: (usize, usize), nb: (usize, usize)| {
        let node = |b: &mut Builder, n: (usize, usize), uv: [f64; 2]| {
            b.point(Key::Node(n.0 as u32, n.1 as u32), |_| {
                (uv, side_bits(uv, rect))
            })
        };
        match (e.wa >= 0.0, e.wb >= 0.0) {
            (true, true) => {
                let (x, y) = (node(b, na, e.a), node(b, nb, e.b));
                b.segments.push([x, y]);
            }
            (true, false) => {
                let (x, y) = (node(b, na, e.a), b.crossing(e));
                b.segments.push([x, y]);
            }
            (false, true) => {
                let (x, y) = (b.crossing(e), node(b, nb, e.b));
                b.segments.push([x, y]);
            }
            (false, false) => {}
        }
    };
    for i in 0..nu {
        border(&mut b, edge_u(i, 0), (i, 0), (i + 1, 0));
        border(&mut b, edge_u(i, nv), (i, nv), (i + 1, nv));
    }
    for j in 0..nv {
        border(&mut b, edge_v(0, j), (0, j), (0, j + 1));
        border(&mut b, edge_v(nu, j), (nu, j), (nu, j + 1));
    }
    let loops = chain(b.points.len(), &b.segments)?;
    Ok(Boundary {
        points: b.points,
        sides: b.sides,
        loops,
        fixed: 0,
    })
}

/// Joins segments into closed loops (every point has two segments).
fn chain(n: usize, segments: &[[usize; 2]]) -> Result<Vec<Vec<usize>>, String> {
    let mut adjacent: Vec<Vec<usize>> = vec![Vec::new(); n];
    for &[a, b] in segments {
        adjacent[a].push(b);
        adjacent[b].push(a);
    }
    if let Some(p) = adjacent.iter().position(|a| a.len() != 2 && !a.is_empty()) {
        return Err(format!(
            "the trim curve branches or ends at boundary point {p} (it meets {} segments); \
             the trim's zero set must be a set of simple curves",
            adjacent[p].len()
        ));
    }
    let mut seen = vec![false; n];
    let mut loops = Vec::new();
    for start in 0..n {
        if seen[start] || adjacent[start].is_empty() {
            continue;
        }
        let mut lp = vec![start];
        seen[start] = true;
        let (mut prev, mut cur) = (start, adjacent[start][0]);
        while cur != start {
            if seen[cur] {
                return Err("the trim curve crosses itself".into());
            }
            seen[cur] = true;
            lp.push(cur);
            let next = if adjacent[cur][0] == prev {
                adjacent[cur][1]
            } else {
                adjacent[cur][0]
            };
            prev = cur;
            cur = next;
        }
        if lp.len() >= 3 {
            loops.push(lp);
        }
    }
    Ok(loops)
}

impl Boundary {
    /// Drops contour points closer than `delta` (3D) to the last point kept;
    /// points on the rectangle's sides stay (they carry its corners).
    pub fn merge_short(&mut self, s: &TrimmedSurface, delta: f64) {
        self.merge_side_points(s, delta);
        for lp in &mut self.loops {
            if lp.len() <= 3 {
                continue;
            }
            let start = lp.iter().position(|&p| self.sides[p] != 0).unwrap_or(0);
            lp.rotate_left(start);
            let mut kept: Vec<usize> = vec![lp[0]];
            let mut last = {
                let p = self.points[lp[0]];
                s.point(p[0], p[1])
            };
            for &p in &lp[1..] {
                let q = s.point(self.points[p][0], self.points[p][1]);
                if self.sides[p] != 0 || (q - last).norm() >= delta {
                    kept.push(p);
                    last = q;
                }
            }
            // A contour point just before a side point (the trim reaching
            // the side) would make a sliver there: drop it too.
            let mut k = 1;
            while k + 1 < kept.len() && kept.len() > 3 {
                let (p, q) = (kept[k], kept[k + 1]);
                let (a, b) = (self.points[p], self.points[q]);
                if self.sides[p] == 0
                    && self.sides[q] != 0
                    && (s.point(a[0], a[1]) - s.point(b[0], b[1])).norm() < delta
                {
                    kept.remove(k);
                } else {
                    k += 1;
                }
            }
            // The closing edge: drop the last contour point if it is too close to the first.
            if kept.len() > 3 {
                let (f, l) = (kept[0], kept[kept.len() - 1]);
                let pf = s.point(self.points[f][0], self.points[f][1]);
                let pl = s.point(self.points[l][0], self.points[l][1]);
                if self.sides[l] == 0 && (pf - pl).norm() < delta {
                    kept.pop();
                }
            }
            if kept.len() >= 3 {
                *lp = kept;
            }
        }
    }

    /// Drops grid points on a side closer than `delta` (3D) to a corner or to
    /// a point where the trim meets the side (they would make slivers there).
    /// The test looks at both neighbours alike, so the two sides of a
    /// periodic seam lose the same points.
    fn merge_side_points(&mut self, s: &TrimmedSurface, delta: f64) {
        let sides = &self.sides;
        let points = &self.points;
        let at = |p: usize| s.point(points[p][0], points[p][1]);
        for lp in &mut self.loops {
            let n = lp.len();
            if n <= 4 {
                continue;
            }
            let plain = |k: usize| {
                let bits = sides[lp[k]];
                bits.count_ones() == 1
                    && sides[lp[(k + n - 1) % n]] & bits != 0
                    && sides[lp[(k + 1) % n]] & bits != 0
            };
            let drop: Vec<bool> = (0..n)
                .map(|k| {
                    plain(k)
                        && [(k + n - 1) % n, (k + 1) % n]
                            .iter()
                            .any(|&j| !plain(j) && (at(lp[k]) - at(lp[j])).norm() < delta)
                })
                .collect();
            let kept: Vec<usize> = (0..n).filter(|&k| !drop[k]).map(|k| lp[k]).collect();
            if kept.len() >= 3 {
                *lp = kept;
            }
        }
    }

    /// Makes the side `bit` (u = `u`, all material) a ring of `segments`
    /// equal steps in v, fixed: a pole cap's fan joins these nodes.
    pub fn fix_ring(&mut self, bit: u8, u: f64, v: [f64; 2], segments: usize) {
        self.fixed |= bit;
        let step = (v[1] - v[0]) / segments as f64;
        let loops = std::mem::take(&mut self.loops);
        for lp in loops {
            // The side's own grid points go; its ends (corners) stay.
            let kept: Vec<usize> = lp
                .iter()
                .copied()
                .filter(|&p| self.sides[p] != bit)
                .collect();
            let mut out = Vec::with_capacity(kept.len() + segments);
            for k in 0..kept.len() {
                let (a, b) = (kept[k], kept[(k + 1) % kept.len()]);
                out.push(a);
                if self.sides[a] & self.sides[b] & bit == 0 {
                    continue;
                }
                let (va, vb) = (self.points[a][1], self.points[b][1]);
                let mut inner: Vec<f64> = (1..segments)
                    .map(|j| v[0] + step * j as f64)
                    .filter(|&x| x > va.min(vb) && x < va.max(vb))
                    .collect();
                if vb < va {
                    inner.reverse();
                }
                for x in inner {
                    self.points.push([u, x]);
                    self.sides.push(bit);
                    out.push(self.points.len() - 1);
                }
            }
            self.loops.push(out);
        }
    }

    /// Splits edges until the surface point over each edge's middle (on the
    /// side, or on W = 0) is within `tolerance` of the chord and no edge is
    /// longer than `max_len` (3D).
    pub fn refine_chords(&mut self, s: &TrimmedSurface, tolerance: f64, max_len: f64) {
        let loops = std::mem::take(&mut self.loops);
        for lp in loops {
            let mut out = Vec::with_capacity(lp.len());
            for k in 0..lp.len() {
                let (a, b) = (lp[k], lp[(k + 1) % lp.len()]);
                out.push(a);
                self.split_edge(s, a, b, tolerance, max_len, 0, &mut out);
            }
            self.loops.push(out);
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn split_edge(
        &mut self,
        s: &TrimmedSurface,
        a: usize,
        b: usize,
        tol: f64,
        max_len: f64,
        depth: u32,
        out: &mut Vec<usize>,
    ) {
        if depth >= 16 {
            return;
        }
        let (pa, pb) = (self.points[a], self.points[b]);
        let common = self.sides[a] & self.sides[b];
        if common & self.fixed != 0 {
            return;
        }
        let mid = [(pa[0] + pb[0]) / 2.0, (pa[1] + pb[1]) / 2.0];
        let m = if common != 0 {
            mid
        } else {
            project(s, mid, pa, pb)
        };
        let (ra, rb, rm) = (
            s.point(pa[0], pa[1]),
            s.point(pb[0], pb[1]),
            s.point(m[0], m[1]),
        );
        let chord_mid = ra + (rb - ra) * 0.5;
        if (rm - chord_mid).norm() <= tol && (rb - ra).norm() <= max_len {
            return;
        }
        self.points.push(m);
        self.sides.push(common);
        let k = self.points.len() - 1;
        self.split_edge(s, a, k, tol, max_len, depth + 1, out);
        out.push(k);
        self.split_edge(s, k, b, tol, max_len, depth + 1, out);
    }
}

/// Moves `m` onto W = 0 across the chord a–b (root finding along the chord's
/// normal in (u, v)); `m` itself when no root is near.
pub(crate) fn project(s: &TrimmedSurface, m: [f64; 2], a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    let d = [b[0] - a[0], b[1] - a[1]];
    let len = d[0].hypot(d[1]);
    if len == 0.0 {
        return m;
    }
    let n = [-d[1] / len, d[0] / len];
    let wm = s.material(m[0], m[1]);
    if wm == 0.0 {
        return m;
    }
    // Bracket along ±n within half the chord's length.
    let mut step = len / 64.0;
    while step <= len / 2.0 {
        for sign in [1.0, -1.0] {
            let q = [m[0] + sign * step * n[0], m[1] + sign * step * n[1]];
            let wq = s.material(q[0], q[1]);
            if wq.is_finite() && (wq >= 0.0) != (wm >= 0.0) {
                return root(s, m, q, wm, wq);
            }
        }
        step *= 2.0;
    }
    m
}
