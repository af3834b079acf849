//! Paper 001's `optiterations`: improves a polygonized surface's triangles
//! without changing its topology or leaving the surface.
//!
//! Each iteration (i) flips edges whose flip raises the smaller of the two
//! triangles' minimum angles, only between nearly coplanar triangles (so a
//! crease is never flipped across), and (ii) moves each smooth vertex
//! towards the centroid of its neighbours within its tangent plane, then
//! projects it back onto f = 0 along the gradient (Newton steps on the f64
//! tape). Crease vertices — where the gradient's direction jumps, as where
//! two balls of a union meet — are first snapped onto the crease (the point
//! nearest to them on the intersection of the two tangent planes seen across
//! their edges) and then kept in place. Vertices on the box (where the solid
//! is capped) are not moved. Everything runs in a fixed order, so the result
//! is the same for any thread count.

use super::polygonize::{Grid, Surface};
use super::tape::{Ssa, Tape};
use std::collections::{HashMap, HashSet};

/// Normals of neighbouring vertices further apart than this angle mark a
/// crease edge (cos 35°).
const CREASE_COS: f64 = 0.82;
/// Triangles flip only when their normals are within ~12° (cos 12°).
const FLAT_COS: f64 = 0.978;

type P = [f64; 3];

fn sub(a: P, b: P) -> P {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn add(a: P, b: P) -> P {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
fn dot(a: P, b: P) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: P, b: P) -> P {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn norm(a: P) -> f64 {
    dot(a, a).sqrt()
}
fn unit(a: P) -> P {
    let l = norm(a);
    if l > 0.0 { a.map(|v| v / l) } else { a }
}

/// The smallest interior angle of a triangle, in degrees.
pub fn min_angle(a: P, b: P, c: P) -> f64 {
    let ang = |p: P, q: P, r: P| {
        let (u, v) = (sub(q, p), sub(r, p));
        let d = (dot(u, v) / (norm(u) * norm(v))).clamp(-1.0, 1.0);
        d.acos().to_degrees()
    };
    ang(a, b, c).min(ang(b, c, a)).min(ang(c, a, b))
}

fn tri_normal(s: &Surface, t: [u32; 3]) -> P {
    let p = t.map(|i| s.positions[i as usize]);
    cross(sub(p[1], p[0]), sub(p[2], p[0]))
}

/// f and its gradient (central differences) at many points, batched.
pub(crate) struct Field<'a> {
    pub(crate) tape: &'a Tape,
    /// Difference step and largest projection step.
    pub(crate) h: f64,
    pub(crate) reach: f64,
}

impl Field<'_> {
    pub(crate) fn eval(&self, pts: &[P]) -> (Vec<f64>, Vec<P>) {
        let n = pts.len();
        let mut ws = self.tape.workspace();
        let mut xs = Vec::with_capacity(7 * n);
        let mut ys = Vec::with_capacity(7 * n);
        let mut zs = Vec::with_capacity(7 * n);
        for d in 0..7usize {
            let (axis, sign) = (d.saturating_sub(1) / 2, if d % 2 == 1 { 1.0 } else { -1.0 });
            for p in pts {
                let mut q = *p;
                if d > 0 {
                    q[axis] += sign * self.h;
                }
                xs.push(q[0]);
                ys.push(q[1]);
                zs.push(q[2]);
            }
        }
        let mut out = vec![0.0; 7 * n];
        self.tape.eval(&mut ws, &xs, &ys, &zs, &mut out);
        let f = out[..n].to_vec();
        let g = (0..n)
            .map(|m| {
                [0, 1, 2]
                    .map(|a| (out[(1 + 2 * a) * n + m] - out[(2 + 2 * a) * n + m]) / (2.0 * self.h))
            })
            .collect();
        (f, g)
    }

    /// Newton steps along the gradient onto f = 0.
    pub(crate) fn project(&self, pts: &mut [P], steps: usize) {
        for _ in 0..steps {
            let (f, g) = self.eval(pts);
            for (m, p) in pts.iter_mut().enumerate() {
                let gg = dot(g[m], g[m]);
                if gg > 0.0 && f[m].is_finite() {
                    let s = f[m] / gg;
                    // Never jump further than a fraction of a cell.
                    let step = g[m].map(|v| v * s);
                    if norm(step) < self.reach {
                        *p = sub(*p, step);
                    }
                }
            }
        }
    }
}

/// Improves `surface` in place with `iterations` rounds (see the module doc).
/// The grid's spacing bounds every move; its box is where the solid was
/// capped (vertices there stay).
pub fn optimize(surface: &mut Surface, ssa: &Ssa, grid: &Grid, iterations: u32) {
    if iterations == 0 || surface.triangles.is_empty() {
        return;
    }
    let cell = (0..3)
        .map(|a| (grid.max[a] - grid.min[a]) / grid.cells[a].max(1) as f64)
        .fold(f64::INFINITY, f64::min);
    let bounds = (grid.min, grid.max);
    let tape = Tape::new(ssa);
    let field = Field {
        tape: &tape,
        h: cell * 1e-4,
        reach: cell,
    };
    let nv = surface.positions.len();
    let tol = cell * 1e-6;
    let on_box =
        |p: P| (0..3).any(|a| (p[a] - bounds.0[a]).abs() < tol || (p[a] - bounds.1[a]).abs() < tol);
    let fixed_box: Vec<bool> = surface.positions.iter().map(|&p| on_box(p)).collect();
    let crease = snap_creases(surface, &field, &fixed_box);
    let fixed: Vec<bool> = (0..nv).map(|v| fixed_box[v] || crease[v]).collect();
    for _ in 0..iterations {
        flip_edges(surface, &HashSet::new());
        smooth(surface, &field, &fixed, cell);
    }
}

/// Snaps vertices next to a crease onto it and returns which were snapped.
/// A mesh edge whose end normals differ by more than 35° crosses a crease;
/// its nearer end (at most one per neighbourhood, so no triangle collapses)
/// moves to the nearest point where both sides' surfaces meet, found by
/// Newton steps on the two one-sided linearisations (each side's f and
/// gradient are sampled a little towards that side's vertex).
fn snap_creases(surface: &mut Surface, field: &Field, fixed: &[bool]) -> Vec<bool> {
    let nv = surface.positions.len();
    let (_, grads) = field.eval(&surface.positions);
    let normals: Vec<P> = grads.iter().map(|&g| unit(g)).collect();
    let mut candidates: Vec<(f64, usize, usize)> = Vec::new();
    for t in &surface.triangles {
        for k in 0..3 {
            let (u, v) = (t[k] as usize, t[(k + 1) % 3] as usize);
            if u < v && dot(normals[u], normals[v]) < CREASE_COS {
                candidates.push((0.0, u, v));
                candidates.push((0.0, v, u));
            }
        }
    }
    if candidates.is_empty() {
        return vec![false; nv];
    }
    let mut q: Vec<P> = candidates
        .iter()
        .map(|&(_, a, _)| surface.positions[a])
        .collect();
    // The first step linearises at the two vertices themselves; later ones
    // ever closer to the current estimate, still on each vertex's side.
    for t in [1.0, 0.3, 0.1, 0.05, 0.02] {
        let side = |c: &[(f64, usize, usize)], which: usize, q: &[P]| -> Vec<P> {
            c.iter()
                .zip(q)
                .map(|(&(_, a, b), &q)| {
                    let p = surface.positions[if which == 0 { a } else { b }];
                    [0, 1, 2].map(|i| q[i] + t * (p[i] - q[i]))
                })
                .collect()
        };
        let (qa, qb) = (side(&candidates, 0, &q), side(&candidates, 1, &q));
        let ((fa, ga), (fb, gb)) = (field.eval(&qa), field.eval(&qb));
        for m in 0..q.len() {
            // q + λ1 ga + λ2 gb on both tangent planes.
            let r1 = -(fa[m] + dot(ga[m], sub(q[m], qa[m])));
            let r2 = -(fb[m] + dot(gb[m], sub(q[m], qb[m])));
            let (a11, a12, a22) = (dot(ga[m], ga[m]), dot(ga[m], gb[m]), dot(gb[m], gb[m]));
            let det = a11 * a22 - a12 * a12;
            if det.abs() < 1e-12 * a11 * a22 || !det.is_finite() {
                continue;
            }
            let l1 = (r1 * a22 - r2 * a12) / det;
            let l2 = (a11 * r2 - a12 * r1) / det;
            q[m] = [0, 1, 2].map(|i| q[m][i] + l1 * ga[m][i] + l2 * gb[m][i]);
        }
    }
    let reach = 0.5 * mean_edge(surface);
    for (m, c) in candidates.iter_mut().enumerate() {
        let d = norm(sub(q[m], surface.positions[c.1]));
        c.0 = if d.is_finite() && d < reach {
            d
        } else {
            f64::INFINITY
        };
    }
    let mut order: Vec<usize> = (0..candidates.len()).collect();
    order.sort_by(|&x, &y| candidates[x].0.total_cmp(&candidates[y].0).then(x.cmp(&y)));
    let mut neighbours: Vec<Vec<u32>> = vec![Vec::new(); nv];
    for t in &surface.triangles {
        for k in 0..3 {
            neighbours[t[k] as usize].push(t[(k + 1) % 3]);
            neighbours[t[k] as usize].push(t[(k + 2) % 3]);
        }
    }
    let before = surface.positions.clone();
    let normals: Vec<P> = surface
        .triangles
        .iter()
        .map(|t| tri_normal(surface, *t))
        .collect();
    let mut snapped = vec![false; nv];
    for m in order {
        let (d, a, _) = candidates[m];
        if !d.is_finite() || fixed[a] || snapped[a] {
            continue;
        }
        if neighbours[a].iter().any(|&w| snapped[w as usize]) {
            continue;
        }
        snapped[a] = true;
        surface.positions[a] = q[m];
    }
    undo_folds(surface, &before, &normals);
    for (v, s) in snapped.iter_mut().enumerate() {
        *s = *s && surface.positions[v] != before[v];
    }
    snapped
}

fn mean_edge(surface: &Surface) -> f64 {
    let mut sum = 0.0;
    for t in &surface.triangles {
        sum += norm(sub(
            surface.positions[t[0] as usize],
            surface.positions[t[1] as usize],
        ));
    }
    sum / surface.triangles.len().max(1) as f64
}

pub(crate) fn edge_key(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

/// One pass of angle-improving flips between nearly coplanar triangles; a
/// flip never makes an edge in `taken` (edges of other patches that share
/// these nodes, in the joint mesher).
pub(crate) fn flip_edges(surface: &mut Surface, taken: &HashSet<(u32, u32)>) {
    let mut edges: HashMap<(u32, u32), [u32; 2]> =
        HashMap::with_capacity(surface.triangles.len() * 2);
    for (ti, t) in surface.triangles.iter().enumerate() {
        for k in 0..3 {
            let e = edge_key(t[k], t[(k + 1) % 3]);
            let slot = edges.entry(e).or_insert([u32::MAX; 2]);
            if slot[0] == u32::MAX {
                slot[0] = ti as u32;
            } else {
                slot[1] = ti as u32;
            }
        }
    }
    let mut keys: Vec<(u32, u32)> = edges.keys().copied().collect();
    keys.sort_unstable();
    let pos = |s: &Surface, i: u32| s.positions[i as usize];
    for e in keys {
        let Some(&[t0, t1]) = edges.get(&e) else {
            continue;
        };
        if t1 == u32::MAX {
            continue;
        }
        let (a, b) = e;
        let (ta, tb) = (
            surface.triangles[t0 as usize],
            surface.triangles[t1 as usize],
        );
        // Still adjacent over (a, b)? (Earlier flips may have changed them.)
        let third = |t: [u32; 3]| {
            (t.contains(&a) && t.contains(&b)).then(|| t.into_iter().find(|&v| v != a && v != b))
        };
        let (Some(Some(c)), Some(Some(d))) = (third(ta), third(tb)) else {
            continue;
        };
        if c == d || edges.contains_key(&edge_key(c, d)) || taken.contains(&edge_key(c, d)) {
            continue;
        }
        let (na, nb) = (unit(tri_normal(surface, ta)), unit(tri_normal(surface, tb)));
        if dot(na, nb) < FLAT_COS {
            continue;
        }
        // Orient the new pair like the old: ta runs a→b or b→a.
        let k = ta.iter().position(|&v| v == a).unwrap_or(0);
        let (p, q) = if ta[(k + 1) % 3] == b { (a, b) } else { (b, a) };
        // ta = (p, q, c), tb = (q, p, d) → (p, d, c), (q, c, d).
        let (n0, n1) = ([p, d, c], [q, c, d]);
        let before = min_angle(
            pos(surface, ta[0]),
            pos(surface, ta[1]),
            pos(surface, ta[2]),
        )
        .min(min_angle(
            pos(surface, tb[0]),
            pos(surface, tb[1]),
            pos(surface, tb[2]),
        ));
        let after = min_angle(
            pos(surface, n0[0]),
            pos(surface, n0[1]),
            pos(surface, n0[2]),
        )
        .min(min_angle(
            pos(surface, n1[0]),
            pos(surface, n1[1]),
            pos(surface, n1[2]),
        ));
        let (m0, m1) = (unit(tri_normal(surface, n0)), unit(tri_normal(surface, n1)));
        if after <= before + 1e-9 || dot(m0, na) < FLAT_COS || dot(m1, na) < FLAT_COS {
            continue;
        }
        surface.triangles[t0 as usize] = n0;
        surface.triangles[t1 as usize] = n1;
        edges.remove(&e);
        edges.insert(edge_key(c, d), [t0, t1]);
        // The four outer edges now belong to other triangles of the pair.
        for (x, y, from, to) in [(q, c, t0, t1), (p, d, t1, t0)] {
            if let Some(slot) = edges.get_mut(&edge_key(x, y)) {
                for s in slot.iter_mut() {
                    if *s == from {
                        *s = to;
                    }
                }
            }
        }
    }
}

/// Tangential smoothing towards the 1-ring centroid, then re-projection.
#[allow(clippy::needless_range_loop)] // v indexes five per-vertex arrays
fn smooth(surface: &mut Surface, field: &Field, fixed: &[bool], cell: f64) {
    let nv = surface.positions.len();
    let mut sum = vec![[0.0; 3]; nv];
    let mut count = vec![0u32; nv];
    let mut normal = vec![[0.0; 3]; nv];
    for t in &surface.triangles {
        let n = tri_normal(surface, *t);
        for k in 0..3 {
            let (v, w) = (t[k] as usize, t[(k + 1) % 3] as usize);
            for (x, y) in [(v, w), (w, v)] {
                sum[x] = add(sum[x], surface.positions[y]);
                count[x] += 1;
            }
            normal[v] = add(normal[v], n);
        }
    }
    let mut moved: Vec<usize> = Vec::new();
    let mut pts: Vec<P> = Vec::new();
    for v in 0..nv {
        if fixed[v] || count[v] == 0 {
            continue;
        }
        let p = surface.positions[v];
        let c = sum[v].map(|s| s / count[v] as f64);
        let n = unit(normal[v]);
        let d = sub(c, p);
        let t = sub(d, n.map(|x| x * dot(d, n)));
        // At most half a cell per round.
        let scale = (0.5 * cell / norm(t).max(1e-300)).min(1.0);
        moved.push(v);
        pts.push([0, 1, 2].map(|i| p[i] + t[i] * scale));
    }
    field.project(&mut pts, 3);
    let before = surface.positions.clone();
    let normals: Vec<P> = surface
        .triangles
        .iter()
        .map(|t| tri_normal(surface, *t))
        .collect();
    for (m, &v) in moved.iter().enumerate() {
        if pts[m].iter().all(|x| x.is_finite()) {
            surface.positions[v] = pts[m];
        }
    }
    undo_folds(surface, &before, &normals);
}

/// Undoes the moves (positions differing from `before`) of the vertices of
/// every triangle that turned over against its normal in `normals` (taken
/// before the moves) or now folds onto a neighbour across an edge (their
/// normals more than 120° apart where they were not), repeated until none
/// does. Snapping onto a crease could turn a triangle over (the seven balls
/// at 32³, where gmsh then found a segment crossing a facet).
pub(crate) fn undo_folds(surface: &mut Surface, before: &[P], normals: &[P]) {
    let unit_normals = |s: &Surface| -> Vec<P> {
        s.triangles
            .iter()
            .map(|t| unit(tri_normal(s, *t)))
            .collect()
    };
    let mut across: HashMap<(u32, u32), Vec<usize>> = HashMap::new();
    for (ti, t) in surface.triangles.iter().enumerate() {
        for k in 0..3 {
            across
                .entry(edge_key(t[k], t[(k + 1) % 3]))
                .or_default()
                .push(ti);
        }
    }
    let mut pairs: Vec<(usize, usize)> = across
        .values()
        .filter(|ts| ts.len() == 2)
        .map(|ts| (ts[0], ts[1]))
        .collect();
    pairs.sort_unstable();
    let old: Vec<P> = normals.iter().map(|&n| unit(n)).collect();
    const FOLD_COS: f64 = -0.5;
    for _ in 0..16 {
        let now = unit_normals(surface);
        let mut bad: Vec<usize> = (0..surface.triangles.len())
            .filter(|&t| dot(now[t], old[t]) <= 0.0)
            .collect();
        for &(a, b) in &pairs {
            if dot(now[a], now[b]) < FOLD_COS && dot(old[a], old[b]) >= FOLD_COS {
                bad.push(a);
                bad.push(b);
            }
        }
        let mut undone = false;
        for t in bad {
            for &v in &surface.triangles[t] {
                let v = v as usize;
                if surface.positions[v] != before[v] {
                    surface.positions[v] = before[v];
                    undone = true;
                }
            }
        }
        if !undone {
            break;
        }
    }
}
