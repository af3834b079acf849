//! Exact areas and volumes of the model, from its analytic faces rather than
//! from a mesh, so a mesh can be measured against them (`geomc inspect
//! --mesh`, the convergence tests).
//!
//! Each face gets its area and its flux ⅓∫ x·n dA along the face normal; a
//! subdomain's volume is the sum of its faces' fluxes signed outward (the
//! divergence theorem), its area the sum of their areas.
//!
//! # Guarantees
//! - Planar faces bounded by segments and elliptic arcs: closed forms
//!   (Green's theorem, ½∮ p × dp).
//! - The canonical curved faces of the primitives (a hemisphere of an
//!   ellipsoid, the side of a truncated cone or cylinder between its rims, a
//!   whole torus): Gauss–Legendre quadrature over the primitive's own
//!   parametrisation, accurate to about 1e-13 relative (the integrands are
//!   smooth and periodic).
//!
//! # Limitations
//! - Other faces (explicit faces on curved surfaces, faces bounded by
//!   intersection curves, quadrics, implicit surfaces) have no exact measure:
//!   `None`, and so has every subdomain they bound.

use crate::geom::{Curve, Frame, Mat3, Point3, Surface, Vec3};
use crate::ir::{Face, Model, SubdomainCells};
use std::f64::consts::{PI, TAU};

/// A face's area and its flux ⅓∫ x·n dA along the face normal (the surface
/// gradient, negated for reversed faces).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FaceMeasure {
    pub area: f64,
    pub flux: f64,
}

/// A subdomain's exact measures: 3D its volume and boundary area, 2D its
/// area (volume 0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExactMeasure {
    pub volume: f64,
    pub area: f64,
}

/// The exact measure of every face, in face order.
pub fn face_measures(model: &Model) -> Vec<Option<FaceMeasure>> {
    let gauss = GaussLegendre::new(24);
    model
        .faces
        .iter()
        .map(|face| face_measure(model, face, &gauss))
        .collect()
}

/// The exact measure of every subdomain, in subdomain order; `None` where a
/// face of it has no exact measure.
pub fn subdomain_measures(model: &Model) -> Vec<Option<ExactMeasure>> {
    let faces = face_measures(model);
    let of = |f: usize| faces.get(f).copied().flatten();
    model
        .subdomains
        .iter()
        .map(|sub| match &sub.cells {
            SubdomainCells::Volume { boundary } => {
                let mut sum = ExactMeasure {
                    volume: 0.0,
                    area: 0.0,
                };
                for oriented in boundary {
                    let m = of(oriented.face.index())?;
                    sum.area += m.area;
                    sum.volume += if oriented.outward { m.flux } else { -m.flux };
                }
                Some(sum)
            }
            SubdomainCells::Region { faces } => {
                let mut area = 0.0;
                for f in faces {
                    area += of(f.index())?.area;
                }
                Some(ExactMeasure { volume: 0.0, area })
            }
        })
        .collect()
}

fn face_measure(model: &Model, face: &Face, gauss: &GaussLegendre) -> Option<FaceMeasure> {
    let sign = if face.reversed { -1.0 } else { 1.0 };
    let measure = match &*face.surface(&model.solids) {
        Surface::Plane { origin, normal } => planar(model, face, origin, &(normal * sign))?,
        Surface::Ellipsoid { frame } => {
            let north = hemisphere_is_north(model, face, frame)?;
            let (lo, hi) = if north {
                (0.0, 0.5 * PI)
            } else {
                (0.5 * PI, PI)
            };
            let m = integrate(frame, gauss, [lo, hi], [0.0, TAU], |theta, phi| {
                let (st, ct, sp, cp) = (theta.sin(), theta.cos(), phi.sin(), phi.cos());
                (
                    Vec3::new(st * cp, st * sp, ct),
                    Vec3::new(ct * cp, ct * sp, -st),
                    Vec3::new(-st * sp, st * cp, 0.0),
                )
            });
            scale_flux(m, sign)
        }
        Surface::Cone { frame, r0, r1 } => {
            cone_side_is_whole(model, face, frame, *r0, *r1)?;
            let (r0, r1) = (*r0, *r1);
            let m = integrate(frame, gauss, [0.0, TAU], [0.0, 1.0], |phi, z| {
                let r = r0 + (r1 - r0) * z;
                let (sp, cp) = (phi.sin(), phi.cos());
                (
                    Vec3::new(r * cp, r * sp, z),
                    Vec3::new(-r * sp, r * cp, 0.0),
                    Vec3::new((r1 - r0) * cp, (r1 - r0) * sp, 1.0),
                )
            });
            scale_flux(m, sign)
        }
        Surface::Torus {
            frame,
            major,
            minor,
        } => {
            torus_is_whole(face)?;
            let (big, small) = (*major, *minor);
            let m = integrate(frame, gauss, [0.0, TAU], [0.0, TAU], |u, v| {
                let (su, cu, sv, cv) = (u.sin(), u.cos(), v.sin(), v.cos());
                let rho = big + small * cv;
                (
                    Vec3::new(rho * cu, rho * su, small * sv),
                    Vec3::new(-rho * su, rho * cu, 0.0),
                    Vec3::new(-small * sv * cu, -small * sv * su, small * cv),
                )
            });
            scale_flux(m, sign)
        }
        Surface::Quadric { .. }
        | Surface::Implicit { .. }
        | Surface::Patch9(_)
        | Surface::Parametric(_) => return None,
    };
    (measure.area.is_finite() && measure.flux.is_finite()).then_some(measure)
}

fn scale_flux(m: FaceMeasure, sign: f64) -> FaceMeasure {
    FaceMeasure {
        area: m.area,
        flux: sign * m.flux,
    }
}

/// A planar face: ½ n·∮ p × dp over its loops (counter-clockwise about `n`,
/// holes clockwise) is its area; x·n is constant on it, so the flux is
/// (n·origin)·area / 3.
fn planar(model: &Model, face: &Face, origin: &Point3, normal: &Vec3) -> Option<FaceMeasure> {
    let n = normal.try_normalize(0.0)?;
    let mut twice = Vec3::zeros();
    for oriented in face.loops.iter().flatten() {
        let edge = model.edges.get(oriented.edge.index())?;
        let along = loop_integral(&edge.curve(&model.solids))?;
        twice += if oriented.forward { along } else { -along };
    }
    let area = 0.5 * n.dot(&twice);
    Some(FaceMeasure {
        area: area.abs(),
        flux: n.dot(&origin.coords) * area / 3.0,
    })
}

/// ∫ p × dp along a curve from its begin to its end, in closed form.
fn loop_integral(curve: &Curve) -> Option<Vec3> {
    match curve {
        Curve::Segment { a, b } => Some(a.coords.cross(&b.coords)),
        // The chord's: the region's area is that of its traced polygon.
        Curve::Contour { a, b, .. } => Some(a.coords.cross(&b.coords)),
        Curve::Ellipse {
            center,
            major,
            minor,
            t0,
            t1,
        } => {
            // p = c + M cos t + N sin t: p × p' = c × p' + M × N.
            let chord = major * (t1.cos() - t0.cos()) + minor * (t1.sin() - t0.sin());
            Some(center.coords.cross(&chord) + major.cross(minor) * (t1 - t0))
        }
        Curve::Intersection { .. } | Curve::PointCalculus(_) | Curve::Chain { .. } => None,
    }
}

/// Whether an ellipsoid face is the local z ≥ 0 half: it must be bounded by
/// the local equator alone, and its loop runs counter-clockwise about the
/// face normal, which decides the side.
fn hemisphere_is_north(model: &Model, face: &Face, frame: &Frame) -> Option<bool> {
    let (1, Some(single)) = (face.loops.len(), face.loops.first()) else {
        return None;
    };
    let [oriented] = single else {
        return None;
    };
    let Curve::Ellipse {
        center,
        major,
        minor,
        t0,
        t1,
    } = *model.edges.get(oriented.edge.index())?.curve(&model.solids)
    else {
        return None;
    };
    let inv = frame.inverse()?;
    let (c, m, n) = (inv * (center - frame.origin), inv * major, inv * minor);
    let unit_circle_at_z0 = c.norm() < 1e-9
        && (m.norm() - 1.0).abs() < 1e-9
        && (n.norm() - 1.0).abs() < 1e-9
        && m.z.abs() < 1e-9
        && n.z.abs() < 1e-9
        && ((t1 - t0).abs() - TAU).abs() < 1e-9;
    if !unit_circle_at_z0 {
        return None;
    }
    // Turning sense about local +z, as the face's loop runs.
    let mut turn = m.cross(&n).z * (t1 - t0).signum();
    if !oriented.forward {
        turn = -turn;
    }
    // Counter-clockwise about the outward normal of the north half is
    // counter-clockwise about +z; a mirroring frame or a reversed face flips it.
    Some(((turn > 0.0) == (frame.determinant() > 0.0)) != face.reversed)
}

/// A cone or cylinder face must be bounded by its rims at local z = 0 and
/// z = 1 (those with a positive radius), one loop each.
fn cone_side_is_whole(model: &Model, face: &Face, frame: &Frame, r0: f64, r1: f64) -> Option<()> {
    let inv = frame.inverse()?;
    let mut rims = Vec::new();
    for lp in &face.loops {
        let [oriented] = lp else {
            return None;
        };
        let Curve::Ellipse { center, t0, t1, .. } =
            *model.edges.get(oriented.edge.index())?.curve(&model.solids)
        else {
            return None;
        };
        let c = inv * (center - frame.origin);
        if c.x.hypot(c.y) > 1e-9 || ((t1 - t0).abs() - TAU).abs() > 1e-9 {
            return None;
        }
        rims.push(c.z);
    }
    rims.sort_by(f64::total_cmp);
    let mut expected = Vec::new();
    if r0 > 0.0 {
        expected.push(0.0);
    }
    if r1 > 0.0 {
        expected.push(1.0);
    }
    (rims.len() == expected.len()
        && rims
            .iter()
            .zip(&expected)
            .all(|(a, b)| (a - b).abs() < 1e-9))
    .then_some(())
}

/// A torus face is whole when its one loop is the seam ring: a parallel and
/// a meridian, each run both ways.
fn torus_is_whole(face: &Face) -> Option<()> {
    let (1, Some(ring)) = (face.loops.len(), face.loops.first()) else {
        return None;
    };
    let mut edges: Vec<u32> = ring.iter().map(|oe| oe.edge.0).collect();
    edges.sort_unstable();
    edges.dedup();
    (ring.len() == 4 && edges.len() == 2).then_some(())
}

/// Area and outward flux of the image under `frame` of a local patch q(u, v)
/// whose q_u × q_v points out of the primitive. `patch` gives (q, q_u, q_v).
fn integrate(
    frame: &Frame,
    gauss: &GaussLegendre,
    u_range: [f64; 2],
    v_range: [f64; 2],
    patch: impl Fn(f64, f64) -> (Vec3, Vec3, Vec3),
) -> FaceMeasure {
    let l: Mat3 = frame.linear;
    // L q_u × L q_v = det(L) L⁻ᵀ (q_u × q_v): outward when det(L) > 0.
    let orientation = frame.determinant().signum();
    const PANELS: usize = 8;
    let (mut area, mut flux) = (0.0, 0.0);
    for pu in 0..PANELS {
        let (u0, u1) = panel(u_range, pu, PANELS);
        for pv in 0..PANELS {
            let (v0, v1) = panel(v_range, pv, PANELS);
            let jacobian = 0.25 * (u1 - u0) * (v1 - v0);
            for (xu, wu) in gauss.nodes.iter().zip(&gauss.weights) {
                let u = 0.5 * (u0 + u1) + 0.5 * (u1 - u0) * xu;
                for (xv, wv) in gauss.nodes.iter().zip(&gauss.weights) {
                    let v = 0.5 * (v0 + v1) + 0.5 * (v1 - v0) * xv;
                    let (q, qu, qv) = patch(u, v);
                    let normal = (l * qu).cross(&(l * qv)) * orientation;
                    let x = frame.origin.coords + l * q;
                    let w = wu * wv * jacobian;
                    area += w * normal.norm();
                    flux += w * x.dot(&normal) / 3.0;
                }
            }
        }
    }
    FaceMeasure { area, flux }
}

fn panel(range: [f64; 2], i: usize, n: usize) -> (f64, f64) {
    let step = (range[1] - range[0]) / n as f64;
    (range[0] + step * i as f64, range[0] + step * (i + 1) as f64)
}

/// Gauss–Legendre nodes and weights on [−1, 1].
struct GaussLegendre {
    nodes: Vec<f64>,
    weights: Vec<f64>,
}

impl GaussLegendre {
    /// The n-point rule: Newton's method on P_n from Chebyshev guesses.
    fn new(n: usize) -> GaussLegendre {
        let mut nodes = Vec::with_capacity(n);
        let mut weights = Vec::with_capacity(n);
        for i in 0..n {
            let mut x = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut derivative = 1.0;
            for _ in 0..100 {
                // Legendre recurrence for P_n(x) and P_n'(x).
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=n {
                    let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                    p0 = p1;
                    p1 = p2;
                }
                derivative = n as f64 * (x * p1 - p0) / (x * x - 1.0);
                let step = p1 / derivative;
                x -= step;
                if step.abs() < 1e-16 {
                    break;
                }
            }
            nodes.push(x);
            weights.push(2.0 / ((1.0 - x * x) * derivative * derivative));
        }
        GaussLegendre { nodes, weights }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_legendre_integrates_polynomials_exactly() {
        let g = GaussLegendre::new(24);
        let sum: f64 = g.weights.iter().sum();
        assert!((sum - 2.0).abs() < 1e-14, "{sum}");
        // ∫ x^46 over [−1, 1] = 2/47 (degree 2n − 1 = 47 is exact).
        let moment: f64 = g
            .nodes
            .iter()
            .zip(&g.weights)
            .map(|(x, w)| w * x.powi(46))
            .sum();
        assert!((moment - 2.0 / 47.0).abs() < 1e-14, "{moment}");
    }

    #[test]
    fn half_ellipse_arc_integral_is_closed_form() {
        // The upper half of the unit circle: ∫ p × dp = π ẑ.
        let arc = Curve::Ellipse {
            center: Point3::origin(),
            major: Vec3::x(),
            minor: Vec3::y(),
            t0: 0.0,
            t1: PI,
        };
        let v = loop_integral(&arc).expect("closed form");
        assert!((v - Vec3::z() * PI).norm() < 1e-15, "{v}");
    }
}
