//! Charts: maps between a face's surface and a plane of parameters (u, v),
//! chosen per surface kind so that Delaunay triangulation in the plane gives
//! well-shaped triangles on the surface.
//!
//! # Guarantees
//! - `lift` puts points exactly on the surface for planes, spheres,
//!   ellipsoids, cones, cylinders and tori (closed forms); the projection
//!   fallback lifts with Newton steps onto `Surface::Quadric`/`Implicit`.
//! - Sphere, circular-cone and torus charts are conformal (angles in the
//!   parameter plane are the angles on the surface): stereographic projection
//!   for spheres, log-polar (R = exp ∫ ds/r) for cones and cylinders, isothermal
//!   coordinates (θ, ∫ dφ/(a + cos φ)) for tori. Frames that scale unevenly
//!   (ellipsoids, elliptic cylinders) keep the maps but lose conformality.
//! - A cone's apex maps to the origin of its chart (see [`Chart::singular_point`]).
//!
//! # Limitations
//! - A stereographic chart cannot hold the pole opposite the face's centre
//!   direction; faces covering more than a sphere minus a cap do not fit.
//! - A cone chart spans exp(w) for w over the face's conformal height: very
//!   long thin cylinders (height/radius above about 60) are refused.
//! - The projection fallback needs faces that are graphs over the plane
//!   perpendicular to their mean normal.

use crate::geom::point_calculus::Patch9;
use crate::geom::{Frame, Mat3, Point3, Surface, Vec3};
use std::f64::consts::{PI, TAU};

/// Largest span of the log-polar coordinate w before exp(w) loses precision.
const MAX_CONFORMAL_SPAN: f64 = 60.0;

#[derive(Debug, Clone)]
pub(crate) enum Chart {
    /// Orthonormal coordinates in the plane.
    Plane { origin: Point3, e1: Vec3, e2: Vec3 },
    /// Stereographic projection of the local unit sphere from −centre,
    /// after the rotation `to_pole` takes the centre direction to +z.
    Sphere { frame: Frame, to_pole: Mat3 },
    /// Log-polar map of the local cone x² + y² = r(z)², r = r0 + c·z.
    Cone {
        frame: Frame,
        r0: f64,
        c: f64,
        /// ln R = exponent · ln(r / r_ref), or (z − z_ref)·exponent for cylinders.
        exponent: f64,
        reference: f64,
    },
    /// Isothermal coordinates of the local torus, periodic in both.
    Torus {
        frame: Frame,
        major: f64,
        minor: f64,
        /// √(a² − 1) with a = major/minor, or 0 when not conformal (a ≤ 1).
        root: f64,
    },
    /// Orthogonal projection onto the plane through `origin` ⊥ `normal`, lifted
    /// back along the normal with Newton steps on `surface`.
    Projection {
        surface: Surface,
        origin: Point3,
        e1: Vec3,
        e2: Vec3,
        normal: Vec3,
    },
    /// A 9-point patch's own (u, v), scaled by its mean tangent lengths so
    /// that lengths in the chart approximate lengths on the surface.
    Patch {
        patch: Box<Patch9>,
        scale_u: f64,
        scale_v: f64,
    },
}

impl Chart {
    /// The chart for a face on `surface` whose boundary points are `boundary`
    /// and whose oriented area vector (½ Σ pᵢ × pᵢ₊₁ over its loops, along the
    /// gradient side) is `area_vector`.
    pub(crate) fn new(
        surface: &Surface,
        boundary: &[Point3],
        area_vector: Vec3,
    ) -> Result<Chart, String> {
        match surface {
            Surface::Plane { origin, normal } => {
                let (e1, e2) = basis(normal).ok_or("the plane has no normal")?;
                Ok(Chart::Plane {
                    origin: *origin,
                    e1,
                    e2,
                })
            }
            Surface::Ellipsoid { frame } => {
                // The face's centre lies where the normal is the mean normal:
                // local q ∝ Lᵀ n.
                let centre = frame.linear.transpose() * area_vector;
                let centre = if centre.norm() > 0.0 {
                    centre.normalize()
                } else {
                    Vec3::z()
                };
                let rotation = nalgebra::Rotation3::rotation_between(&centre, &Vec3::z())
                    .unwrap_or_else(|| nalgebra::Rotation3::from_axis_angle(&Vec3::x_axis(), PI));
                frame.inverse().ok_or("the ellipsoid's frame is singular")?;
                Ok(Chart::Sphere {
                    frame: *frame,
                    to_pole: *rotation.matrix(),
                })
            }
            Surface::Cone { frame, r0, r1 } => cone_chart(frame, *r0, *r1, boundary),
            Surface::Torus {
                frame,
                major,
                minor,
            } => {
                frame.inverse().ok_or("the torus's frame is singular")?;
                if *minor <= 0.0 || *major <= 0.0 {
                    return Err("the torus has no positive radii".into());
                }
                let a = major / minor;
                let root = if a > 1.0 + 1e-9 {
                    (a * a - 1.0).sqrt()
                } else {
                    0.0
                };
                Ok(Chart::Torus {
                    frame: *frame,
                    major: *major,
                    minor: *minor,
                    root,
                })
            }
            Surface::Patch9(patch) => {
                let (mut su, mut sv) = (0.0, 0.0);
                for v in [0.0, 0.5, 1.0] {
                    for u in [0.0, 0.5, 1.0] {
                        let (mu, mv) = patch.derivatives(u, v);
                        su += mu.norm() / 9.0;
                        sv += mv.norm() / 9.0;
                    }
                }
                if !(su > 0.0 && sv > 0.0 && su.is_finite() && sv.is_finite()) {
                    return Err("the patch has no extent along u or v".into());
                }
                Ok(Chart::Patch {
                    patch: patch.clone(),
                    scale_u: su,
                    scale_v: sv,
                })
            }
            // Meshed by `crate::trimmed` (the mesher skips these faces).
            Surface::Parametric(_) => Err("a trimmed surface has no chart".into()),
            Surface::Quadric { .. } | Surface::Implicit { .. } => {
                let normal = if area_vector.norm() > 0.0 {
                    area_vector.normalize()
                } else {
                    return Err("its loops enclose no area to project along".into());
                };
                let (e1, e2) = basis(&normal).ok_or("no projection plane")?;
                let n = boundary.len().max(1) as f64;
                let origin = Point3::from(boundary.iter().map(|p| p.coords).sum::<Vec3>() / n);
                Ok(Chart::Projection {
                    surface: surface.clone(),
                    origin,
                    e1,
                    e2,
                    normal,
                })
            }
        }
    }

    /// Periods of (u, v): loops are unwrapped so that consecutive points are
    /// nearest modulo these.
    pub(crate) fn periods(&self) -> [Option<f64>; 2] {
        match self {
            Chart::Torus { root, .. } => {
                let period = if *root > 0.0 { TAU / root } else { TAU };
                [Some(TAU), Some(period)]
            }
            _ => [None, None],
        }
    }

    /// A parameter point where the chart is singular and the surface has a
    /// point the boundary does not reach (a cone's apex), to be inserted as a
    /// node when it lies inside the face.
    pub(crate) fn singular_point(&self) -> Option<([f64; 2], Point3)> {
        match self {
            Chart::Cone {
                frame,
                r0,
                c,
                exponent,
                ..
            } if *c != 0.0 && exponent.is_finite() => {
                let z = -r0 / c;
                Some(([0.0, 0.0], frame.to_global(&Point3::new(0.0, 0.0, z))))
            }
            _ => None,
        }
    }

    pub(crate) fn to_param(&self, p: &Point3) -> Option<[f64; 2]> {
        let uv = match self {
            Chart::Plane { origin, e1, e2 } | Chart::Projection { origin, e1, e2, .. } => {
                let d = p - origin;
                [d.dot(e1), d.dot(e2)]
            }
            Chart::Sphere { frame, to_pole } => {
                let q = frame.to_local(p)?.coords;
                let q = to_pole * q.try_normalize(0.0)?;
                let w = 1.0 + q.z;
                if w <= 1e-12 {
                    return None;
                }
                [q.x / w, q.y / w]
            }
            Chart::Cone {
                frame,
                r0,
                c,
                exponent,
                reference,
            } => {
                let q = frame.to_local(p)?;
                let theta = q.y.atan2(q.x);
                let ln_radius = if *c == 0.0 {
                    (q.z - reference) * exponent
                } else {
                    let r = r0 + c * q.z;
                    if r <= 0.0 {
                        return Some([0.0, 0.0]);
                    }
                    (r / reference).ln() * exponent
                };
                let radius = ln_radius.exp();
                [radius * theta.cos(), radius * theta.sin()]
            }
            Chart::Torus {
                frame,
                major,
                minor,
                root,
            } => {
                let q = frame.to_local(p)?;
                let theta = q.y.atan2(q.x);
                let phi = q.z.atan2(q.x.hypot(q.y) - major);
                [theta, torus_psi(phi, major / minor, *root)]
            }
            Chart::Patch {
                patch,
                scale_u,
                scale_v,
            } => {
                let ([u, v], _) = patch.project(p)?;
                [u * scale_u, v * scale_v]
            }
        };
        uv.iter().all(|x| x.is_finite()).then_some(uv)
    }

    /// The surface point of parameters `uv`.
    pub(crate) fn lift(&self, uv: [f64; 2]) -> Option<Point3> {
        let [u, v] = uv;
        let p = match self {
            Chart::Plane { origin, e1, e2 } => origin + e1 * u + e2 * v,
            Chart::Sphere { frame, to_pole } => {
                let s = u * u + v * v;
                let q = Vec3::new(2.0 * u, 2.0 * v, 1.0 - s) / (1.0 + s);
                frame.to_global(&Point3::from(to_pole.transpose() * q))
            }
            Chart::Cone {
                frame,
                r0,
                c,
                exponent,
                reference,
            } => {
                let radius = u.hypot(v);
                let theta = v.atan2(u);
                let z = if *c == 0.0 {
                    reference + radius.ln() / exponent
                } else {
                    let r = if radius > 0.0 {
                        reference * (radius.ln() / exponent).exp()
                    } else {
                        0.0
                    };
                    (r - r0) / c
                };
                let r = r0 + c * z;
                frame.to_global(&Point3::new(r * theta.cos(), r * theta.sin(), z))
            }
            Chart::Torus {
                frame,
                major,
                minor,
                root,
            } => {
                let phi = torus_phi(v, major / minor, *root);
                let rho = major + minor * phi.cos();
                frame.to_global(&Point3::new(
                    rho * u.cos(),
                    rho * u.sin(),
                    minor * phi.sin(),
                ))
            }
            Chart::Projection {
                surface,
                origin,
                e1,
                e2,
                normal,
            } => lift_along(surface, origin + e1 * u + e2 * v, normal)?,
            Chart::Patch {
                patch,
                scale_u,
                scale_v,
            } => patch.point(u / scale_u, v / scale_v),
        };
        p.coords.iter().all(|x| x.is_finite()).then_some(p)
    }
}

/// An orthonormal pair (e1, e2) with e1 × e2 along `normal`.
fn basis(normal: &Vec3) -> Option<(Vec3, Vec3)> {
    let n = normal.try_normalize(0.0)?;
    let helper = if n.x.abs() < 0.9 {
        Vec3::x()
    } else {
        Vec3::y()
    };
    let e1 = (helper - n * helper.dot(&n)).normalize();
    Some((e1, n.cross(&e1)))
}

/// The log-polar chart of a cone side. Its scale uses the global lengths of
/// the frame's columns so that it is conformal for circular cones whose axis
/// is perpendicular to the rims.
fn cone_chart(frame: &Frame, r0: f64, r1: f64, boundary: &[Point3]) -> Result<Chart, String> {
    let inverse = frame.inverse().ok_or("the cone's frame is singular")?;
    let sigma = 0.5 * (frame.linear.column(0).norm() + frame.linear.column(1).norm());
    let height = frame.linear.column(2).norm();
    let c = r1 - r0;
    let local: Vec<Vec3> = boundary
        .iter()
        .map(|p| inverse * (p - frame.origin))
        .collect();
    let n = local.len().max(1) as f64;
    let (exponent, reference, span) = if (c * sigma).abs() <= 1e-9 * height {
        // Cylinder: ln R = (z − z_ref)·height/(σ r0).
        if r0 <= 0.0 {
            return Err("the cylinder has no radius".into());
        }
        let exponent = height / (sigma * r0);
        let z_ref = local.iter().map(|q| q.z).sum::<f64>() / n;
        let (lo, hi) = min_max(local.iter().map(|q| q.z));
        (exponent, z_ref, (hi - lo) * exponent)
    } else {
        // Cone: ln R = K·ln(r/r_ref), K = slant/|Δr| ≥ 1 (the apex goes to R = 0).
        let exponent = (height * height + (c * sigma).powi(2)).sqrt() / (c.abs() * sigma);
        let radii: Vec<f64> = local
            .iter()
            .map(|q| r0 + c * q.z)
            .filter(|r| *r > 0.0)
            .collect();
        if radii.is_empty() {
            return Err("its boundary lies at the cone's apex".into());
        }
        let reference = (radii.iter().map(|r| r.ln()).sum::<f64>() / radii.len() as f64).exp();
        let (lo, hi) = min_max(radii.iter().map(|r| r.ln()));
        (exponent, reference, (hi - lo) * exponent)
    };
    if !(span.is_finite() && span <= MAX_CONFORMAL_SPAN) {
        return Err(format!(
            "the cone side is too long for its radius (conformal span {span:.1} > {MAX_CONFORMAL_SPAN})"
        ));
    }
    Ok(Chart::Cone {
        frame: *frame,
        r0,
        c,
        exponent,
        reference,
    })
}

fn min_max(values: impl Iterator<Item = f64>) -> (f64, f64) {
    values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
        (lo.min(x), hi.max(x))
    })
}

/// ψ(φ) = ∫₀^φ dφ/(a + cos φ) (isothermal torus coordinate), continued
/// periodically-plus-linearly beyond (−π, π]; φ itself when not conformal.
fn torus_psi(phi: f64, a: f64, root: f64) -> f64 {
    if root <= 0.0 {
        return phi;
    }
    let turns = ((phi + PI) / TAU).floor();
    let reduced = phi - turns * TAU;
    let k = ((a - 1.0) / (a + 1.0)).sqrt();
    2.0 / root * (k * (reduced / 2.0).tan()).atan() + turns * TAU / root
}

/// The inverse of [`torus_psi`].
fn torus_phi(psi: f64, a: f64, root: f64) -> f64 {
    if root <= 0.0 {
        return psi;
    }
    let period = TAU / root;
    let turns = (psi / period + 0.5).floor();
    let reduced = psi - turns * period;
    let k = ((a - 1.0) / (a + 1.0)).sqrt();
    2.0 * ((reduced * root / 2.0).tan() / k).atan() + turns * TAU
}

/// The point of `surface` on the line through `start` along `direction`,
/// nearest `start` (1D Newton), or the surface's own projection when that fails.
fn lift_along(surface: &Surface, start: Point3, direction: &Vec3) -> Option<Point3> {
    let mut t = 0.0;
    for _ in 0..60 {
        let p = start + direction * t;
        let (value, gradient) = surface.value_and_gradient(&p);
        let slope = gradient.dot(direction);
        if !value.is_finite() || !slope.is_finite() || slope.abs() <= 1e-12 * gradient.norm() {
            break;
        }
        let step = value / slope;
        t -= step;
        if step.abs() <= 1e-13 * (1.0 + start.coords.amax() + t.abs()) {
            let p = start + direction * t;
            return p.coords.iter().all(|x| x.is_finite()).then_some(p);
        }
    }
    surface.project(&start)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn torus_coordinates_invert() {
        let frame = Frame::identity();
        let chart = Chart::Torus {
            frame,
            major: 2.0,
            minor: 0.5,
            root: 15f64.sqrt(),
        };
        for &(theta, phi) in &[(0.3, 0.2), (1.0, 3.0), (-2.0, -3.1), (0.1, 1.5)] {
            let p = Point3::new(
                (2.0 + 0.5 * f64::cos(phi)) * f64::cos(theta),
                (2.0 + 0.5 * f64::cos(phi)) * f64::sin(theta),
                0.5 * f64::sin(phi),
            );
            let uv = chart.to_param(&p).expect("param");
            let back = chart.lift(uv).expect("lift");
            assert!((back - p).norm() < 1e-12, "{p} → {uv:?} → {back}");
        }
    }

    #[test]
    fn sphere_and_cone_charts_invert() {
        let sphere = Chart::new(
            &Surface::Ellipsoid {
                frame: Frame::scaling(Vec3::new(2.0, 1.0, 3.0)),
            },
            &[],
            Vec3::new(0.2, 0.1, 1.0),
        )
        .expect("chart");
        let p = Point3::new(2.0 * 0.6, 0.0, 3.0 * 0.8);
        let back = sphere.lift(sphere.to_param(&p).expect("uv")).expect("lift");
        assert!((back - p).norm() < 1e-12);

        let frame = Frame::scaling(Vec3::new(1.0, 1.0, 2.0));
        let boundary = [Point3::new(1.0, 0.0, 0.0), Point3::new(0.5, 0.0, 2.0)];
        for (r0, r1) in [(1.0, 0.5), (1.0, 1.0), (1.0, 0.0)] {
            let cone = cone_chart(&frame, r0, r1, &boundary[..1]).expect("cone");
            let z: f64 = 0.4;
            let r = r0 + (r1 - r0) * z;
            let p = Point3::new(r * 0.6, r * 0.8, 2.0 * z);
            let back = cone.lift(cone.to_param(&p).expect("uv")).expect("lift");
            assert!((back - p).norm() < 1e-12, "{r0} {r1}: {back}");
        }
    }
}
