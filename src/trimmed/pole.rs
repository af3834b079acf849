//! Poles: a side u = const of the parameter rectangle that is a single
//! point in 3D (a sphere's pole, a cone's apex, a Bezier patch with a
//! collapsed row). No chart of the rectangle is faithful there (the rings
//! shrink to a point while their parameter length stays), so a small cap
//! u ∈ [u_pole, u_ring] is cut off: the rest (the band) is meshed as usual
//! with the ring u = u_ring fixed at `segments` equal steps in v, and the cap
//! is closed by a fan of triangles from one pole vertex to the ring nodes.
//! The ring is placed as far out as the fan triangles still meet the element
//! size and the tolerance, so they are about as large as their neighbours.
//! A fan triangle's angle at the pole is the angle the pole's surroundings
//! span (360° on a sphere, less at a cone's apex) divided by `segments`, at
//! most 45°; that is the one place the min-angle threshold is not enforced
//! (a sharp apex with its full angle under 3 × the threshold).

use super::TrimmedSurface;
use super::boundary::{U_MAX, U_MIN};
use super::measure::centroid_distance;
use super::triangulate::{TrimSettings, TrimmedMesh, is_periodic, join_runs};
use crate::geom::Point3;
use std::collections::HashSet;

/// The largest angle a fan triangle makes at the pole.
const FAN_ANGLE: f64 = std::f64::consts::FRAC_PI_4;

/// One pole and the cap cut off around it.
#[derive(Debug, Clone, Copy)]
pub struct Cap {
    /// U_MIN or U_MAX: the side that is the pole.
    pub bit: u8,
    pub u_pole: f64,
    pub u_ring: f64,
    /// Ring steps in v (the fan's triangles).
    pub segments: usize,
    /// False when the trim removes the whole cap: it is left out.
    pub material: bool,
}

impl Cap {
    /// The index in `rect` the band moves to the ring.
    pub fn side_index(&self) -> usize {
        if self.bit == U_MIN { 0 } else { 1 }
    }
}

/// True when a side v = const of `s` is a single point (a pole there):
/// such a surface is meshed as its transpose (`TrimmedSurface::transposed`).
pub fn has_v_pole(s: &TrimmedSurface) -> bool {
    let [_, _, v0, v1] = s.rect;
    let Some(scale) = sample_scale(s) else {
        return false;
    };
    [v0, v1]
        .into_iter()
        .any(|v| is_point_side(s, scale, false, v))
}

/// The diagonal of the box of a 16×16 sample of `s`, or `None` for an
/// empty or unbounded sample.
fn sample_scale(s: &TrimmedSurface) -> Option<f64> {
    let (lo, hi) = s.samples(16).iter().fold(
        (
            Point3::new(f64::INFINITY, f64::INFINITY, f64::INFINITY),
            Point3::new(f64::NEG_INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY),
        ),
        |(lo, hi), p| (lo.inf(p), hi.sup(p)),
    );
    let scale = (hi - lo).norm();
    (scale.is_finite() && scale > 0.0).then_some(scale)
}

/// True when the side `u = t` (`fixed_u`) or `v = t` of `s` is a single
/// point within 1e-9 of `scale` (a pole).
fn is_point_side(s: &TrimmedSurface, scale: f64, fixed_u: bool, t: f64) -> bool {
    let [u0, u1, v0, v1] = s.rect;
    let at = |x: f64| {
        if fixed_u {
            s.point(t, x)
        } else {
            s.point(x, t)
        }
    };
    let (a, b) = if fixed_u { (v0, v1) } else { (u0, u1) };
    let first = at(a);
    (1..=16).all(|k| (at(a + (b - a) * k as f64 / 16.0) - first).norm() <= 1e-9 * scale)
}

/// The caps of the degenerate sides of `s` (none for most surfaces).
pub fn plan(s: &TrimmedSurface, settings: &TrimSettings, h: f64) -> Result<Vec<Cap>, String> {
    let [u0, u1, v0, v1] = s.rect;
    let Some(scale) = sample_scale(s) else {
        return Ok(Vec::new());
    };
    let point_side = |fixed_u: bool, t: f64| is_point_side(s, scale, fixed_u, t);
    for v in [v0, v1] {
        if point_side(false, v) {
            return Err(format!(
                "the side v = {v} of the parameter rectangle is a single point (a pole), and so \
                 is a side u = const; poles are supported along one parameter only: split the \
                 rectangle so that each part has its poles on sides of one kind"
            ));
        }
    }
    let poles: Vec<(u8, f64, f64)> = [(U_MIN, u0, 1.0), (U_MAX, u1, -1.0)]
        .into_iter()
        .filter(|&(_, u, _)| point_side(true, u))
        .collect();
    if poles.is_empty() {
        return Ok(Vec::new());
    }
    let span = (u1 - u0) * if poles.len() == 2 { 0.25 } else { 0.4 };
    let periodic = is_periodic(s, 1, scale);
    let mut caps = Vec::new();
    for (bit, u_pole, sign) in poles {
        caps.push(cap(s, settings, h, bit, u_pole, sign * span, periodic)?);
    }
    Ok(caps)
}

enum Status {
    Material,
    Void,
    Mixed,
}

fn cap(
    s: &TrimmedSurface,
    settings: &TrimSettings,
    h: f64,
    bit: u8,
    u_pole: f64,
    span: f64,
    periodic: bool,
) -> Result<Cap, String> {
    for k in 0..40 {
        let u_ring = u_pole + span * 0.5f64.powi(k);
        let segments = segments(s, u_pole, u_ring, periodic);
        let cap = Cap {
            bit,
            u_pole,
            u_ring,
            segments,
            material: true,
        };
        match status(s, &cap) {
            Status::Mixed => continue,
            Status::Void => {
                return Ok(Cap {
                    material: false,
                    ..cap
                });
            }
            Status::Material => {
                if fan_fits(s, &cap, settings, h) {
                    return Ok(cap);
                }
            }
        }
    }
    Err(format!(
        "the trim curve passes through the pole at u = {u_pole}, or the surface is not smooth \
         next to it; keep the trim away from the pole"
    ))
}

/// Ring steps: the angle the ring spans seen from the pole in pieces of at
/// most FAN_ANGLE (at least 3 around a closed ring).
fn segments(s: &TrimmedSurface, u_pole: f64, u_ring: f64, periodic: bool) -> usize {
    let [_, _, v0, v1] = s.rect;
    let p = s.point(u_pole, v0);
    let mut total = 0.0;
    let steps = 64;
    for k in 0..steps {
        let (a, b) = (
            v0 + (v1 - v0) * k as f64 / steps as f64,
            v0 + (v1 - v0) * (k + 1) as f64 / steps as f64,
        );
        let angle = (s.point(u_ring, a) - p).angle(&(s.point(u_ring, b) - p));
        if angle.is_finite() {
            total += angle;
        }
    }
    let n = (total / FAN_ANGLE).ceil() as usize;
    n.max(if periodic { 3 } else { 1 })
}

/// Whether the trim keeps all of the cap, none of it, or cuts it.
fn status(s: &TrimmedSurface, cap: &Cap) -> Status {
    let [_, _, v0, v1] = s.rect;
    let (mut kept, mut cut) = (false, false);
    let nv = 8 * cap.segments;
    for i in 0..=8 {
        let u = cap.u_pole + (cap.u_ring - cap.u_pole) * i as f64 / 8.0;
        for j in 0..=nv {
            let w = s.material(u, v0 + (v1 - v0) * j as f64 / nv as f64);
            if w >= 0.0 {
                kept = true;
            } else {
                cut = true;
            }
        }
    }
    match (kept, cut) {
        (true, false) => Status::Material,
        (false, true) => Status::Void,
        _ => Status::Mixed,
    }
}

/// True when every fan triangle has its sides within the element size and
/// its edges' middles and centroid within the tolerance of the surface.
fn fan_fits(s: &TrimmedSurface, cap: &Cap, settings: &TrimSettings, h: f64) -> bool {
    let [_, _, v0, v1] = s.rect;
    let tol = settings.tolerance;
    let p = s.point(cap.u_pole, v0);
    let step = (v1 - v0) / cap.segments as f64;
    let mid = |a: Point3, b: Point3| Point3::from((a.coords + b.coords) / 2.0);
    (0..cap.segments).all(|k| {
        let (va, vb) = (v0 + step * k as f64, v0 + step * (k + 1) as f64);
        let (a, b) = (s.point(cap.u_ring, va), s.point(cap.u_ring, vb));
        let ring_mid = s.point(cap.u_ring, 0.5 * (va + vb));
        let spoke_mid = s.point(0.5 * (cap.u_pole + cap.u_ring), va);
        let c = Point3::from((p.coords + a.coords + b.coords) / 3.0);
        let start = [(cap.u_pole + 2.0 * cap.u_ring) / 3.0, 0.5 * (va + vb)];
        (a - b).norm() <= h
            && (a - p).norm() <= h
            && (ring_mid - mid(a, b)).norm() <= 0.5 * tol
            && (spoke_mid - mid(p, a)).norm() <= 0.5 * tol
            && centroid_distance(s, c, start) <= tol
    })
}

/// Adds the pole vertex and the fan from it to the ring nodes of `mesh`
/// (the band's mesh), and takes the ring out of the boundary chains (a side
/// chain through the cap now runs through the pole).
pub fn close(mesh: &mut TrimmedMesh, s: &TrimmedSurface, cap: &Cap) {
    let [_, _, v0, v1] = s.rect;
    let eps = 1e-12 * (s.rect[1] - s.rect[0]).abs().max(cap.u_ring.abs());
    let mut ring: Vec<u32> = (0..mesh.uv.len() as u32)
        .filter(|&i| (mesh.uv[i as usize][0] - cap.u_ring).abs() <= eps)
        .collect();
    if ring.len() < 2 {
        return;
    }
    ring.sort_by(|&a, &b| mesh.uv[a as usize][1].total_cmp(&mesh.uv[b as usize][1]));
    // Welded by the seam: the ring closes on itself.
    let closed = ring.len() == cap.segments;
    let pole = mesh.nodes.len() as u32;
    mesh.nodes.push(s.point(cap.u_pole, v0));
    mesh.uv.push([cap.u_pole, 0.5 * (v0 + v1)]);
    let directed: HashSet<(u32, u32)> = mesh
        .triangles
        .iter()
        .flat_map(|t| (0..3).map(move |k| (t[k], t[(k + 1) % 3])))
        .collect();
    let pairs = if closed { ring.len() } else { ring.len() - 1 };
    for k in 0..pairs {
        let (a, b) = (ring[k], ring[(k + 1) % ring.len()]);
        // The band uses the ring edge one way; the fan the other way.
        if directed.contains(&(a, b)) {
            mesh.triangles.push([b, a, pole]);
        } else {
            mesh.triangles.push([a, b, pole]);
        }
    }
    let on_ring: HashSet<u32> = ring.iter().copied().collect();
    let ring_edge = |a: u32, b: u32| on_ring.contains(&a) && on_ring.contains(&b);
    let mut runs = Vec::new();
    for chain in std::mem::take(&mut mesh.boundary) {
        if chain.len() < 2 {
            continue;
        }
        let closed_chain = chain.len() > 2 && chain.first() == chain.last();
        let n = chain.len() - 1;
        let Some(start) = (0..n).find(|&k| !ring_edge(chain[k], chain[k + 1])) else {
            // The ring alone (a closed seam): now inside.
            continue;
        };
        let seq: Vec<u32> = if closed_chain {
            (0..=n).map(|k| chain[(start + k) % n]).collect()
        } else {
            chain.clone()
        };
        let mut out: Vec<u32> = vec![seq[0]];
        let mut k = 0;
        while k + 1 < seq.len() {
            if ring_edge(seq[k], seq[k + 1]) {
                // Skip the run along the ring; go through the pole instead.
                let mut j = k + 1;
                while j + 1 < seq.len() && ring_edge(seq[j], seq[j + 1]) {
                    j += 1;
                }
                out.push(pole);
                out.push(seq[j]);
                k = j;
            } else {
                out.push(seq[k + 1]);
                k += 1;
            }
        }
        runs.push(out.into_iter().map(|x| x as usize).collect::<Vec<usize>>());
    }
    mesh.boundary = join_runs(runs)
        .into_iter()
        .map(|c| c.into_iter().map(|x| x as u32).collect())
        .collect();
}
