//! Parametric surfaces trimmed by implicit functions (paper 002): a surface
//! R(u, v) over a parameter rectangle, kept where the trim F(R(u, v)) has the
//! material sign. `boundary.rs` finds the trim curve by marching squares in
//! (u, v); `triangulate.rs` meshes the kept part with a constrained Delaunay
//! triangulation refined by 3D criteria; `measure.rs` has the quality figures.

pub(crate) mod boundary;
mod chart;
mod measure;
mod pole;
pub mod program;
pub mod shared;
mod split;
pub mod topology;
mod triangulate;

pub use measure::{TrimmedQuality, centroid_distance, volume_share};
pub use triangulate::{TrimSettings, TrimmedMesh, mesh_trimmed, mesh_trimmed_shared};

use crate::geom::point_calculus::Patch9;
use crate::geom::{Frame, Point3, Vec3};
use crate::implicit::ir::{Ctx, NodeId};
use crate::implicit::tape::Ssa;

/// The carrier surface in its local frame.
#[derive(Debug, Clone, PartialEq)]
pub enum Carrier {
    /// Tensor-product Bezier: `rows[i][j]`, i along u, j along v, u, v ∈ [0, 1].
    Bezier { rows: Vec<Vec<Point3>> },
    /// Paper 002's truncated cone about the local y axis: x = r(u) cos v,
    /// y = u, z = r(u) sin v, r(u) = r1 + (r2 − r1) u / l.
    Cone { r1: f64, r2: f64, length: f64 },
    /// A sphere about the local origin: x = ρ cos u cos v, y = ρ sin u,
    /// z = ρ cos u sin v (u the latitude, v the angle about the local y axis).
    Sphere { radius: f64 },
    /// A torus about the local y axis: x = (R + r cos u) cos v, y = r sin u,
    /// z = (R + r cos u) sin v (u about the tube, v about the axis).
    Torus { major: f64, minor: f64 },
    /// x(u, v), y(u, v), z(u, v) as programs in the variables u (0) and v (1).
    Expressions { xyz: Box<[Ssa; 3]> },
    /// Paper 003's 9-point parabolic patch (point calculus), u, v ∈ [0, 1].
    Patch9(Box<Patch9>),
    /// The inner carrier with u and v exchanged: R(u, v) = inner(v, u). A
    /// surface with a pole on a side v = const is meshed as its transpose
    /// (`TrimmedSurface::transposed`), the pole then on a side u = const.
    Swapped(Box<Carrier>),
}

/// The trim: F over global x, y, z; material where F ≥ 0, or F ≤ 0 when `negative`.
#[derive(Debug, Clone, PartialEq)]
pub struct Trim {
    pub program: Ssa,
    pub negative: bool,
}

impl Trim {
    pub fn new(ctx: &Ctx, root: NodeId, negative: bool) -> Trim {
        Trim {
            program: Ssa::from_ctx(ctx, root),
            negative,
        }
    }
}

/// One trimmed surface of the model.
#[derive(Debug, Clone, PartialEq)]
pub struct TrimmedSurface {
    pub name: String,
    pub carrier: Carrier,
    /// Local → global placement (the element's cs=).
    pub frame: Frame,
    /// u_min, u_max, v_min, v_max.
    pub rect: [f64; 4],
    pub trim: Option<Trim>,
}

/// R(u, v) of a carrier in its local frame (NaN when an expression fails).
fn local_point(carrier: &Carrier, u: f64, v: f64) -> Point3 {
    match carrier {
        Carrier::Bezier { rows } => bezier(rows, u, v),
        Carrier::Cone { r1, r2, length } => {
            let r = r1 + (r2 - r1) * u / length;
            Point3::new(r * v.cos(), u, r * v.sin())
        }
        Carrier::Sphere { radius } => {
            let ring = radius * u.cos();
            Point3::new(ring * v.cos(), radius * u.sin(), ring * v.sin())
        }
        Carrier::Torus { major, minor } => {
            let ring = major + minor * u.cos();
            Point3::new(ring * v.cos(), minor * u.sin(), ring * v.sin())
        }
        Carrier::Patch9(patch) => patch.point(u, v),
        Carrier::Expressions { xyz } => {
            let p = [u, v, 0.0];
            Point3::new(
                xyz[0].eval_point(p),
                xyz[1].eval_point(p),
                xyz[2].eval_point(p),
            )
        }
        Carrier::Swapped(inner) => local_point(inner, v, u),
    }
}

impl TrimmedSurface {
    /// R(u, v) in global coordinates (NaN when an expression fails).
    pub fn point(&self, u: f64, v: f64) -> Point3 {
        self.frame.to_global(&local_point(&self.carrier, u, v))
    }

    /// The same surface with u and v exchanged (its normal R_u × R_v turned over).
    pub fn transposed(&self) -> TrimmedSurface {
        let carrier = match &self.carrier {
            Carrier::Swapped(inner) => (**inner).clone(),
            c => Carrier::Swapped(Box::new(c.clone())),
        };
        let [u0, u1, v0, v1] = self.rect;
        TrimmedSurface {
            carrier,
            rect: [v0, v1, u0, u1],
            ..self.clone()
        }
    }

    /// Surface points on an (n + 1) × (n + 1) parameter grid.
    pub fn samples(&self, n: usize) -> Vec<Point3> {
        let [u0, u1, v0, v1] = self.rect;
        let mut out = Vec::with_capacity((n + 1) * (n + 1));
        for i in 0..=n {
            for j in 0..=n {
                let t = (i as f64 / n as f64, j as f64 / n as f64);
                out.push(self.point(u0 + (u1 - u0) * t.0, v0 + (v1 - v0) * t.1));
            }
        }
        out
    }

    /// The partial derivatives (R_u, R_v) by central differences.
    pub fn tangents(&self, u: f64, v: f64) -> (Vec3, Vec3) {
        let hu = 1e-6 * (self.rect[1] - self.rect[0]);
        let hv = 1e-6 * (self.rect[3] - self.rect[2]);
        let du = (self.point(u + hu, v) - self.point(u - hu, v)) / (2.0 * hu);
        let dv = (self.point(u, v + hv) - self.point(u, v - hv)) / (2.0 * hv);
        (du, dv)
    }

    /// The surface point nearest `p` (best of a 16 × 16 parameter grid, then
    /// Gauss–Newton, kept in the rectangle) with the unit normal
    /// R_u × R_v there; `None` where the normal is undefined.
    pub fn project(&self, p: &Point3) -> Option<(Point3, Vec3)> {
        let [u0, u1, v0, v1] = self.rect;
        let n = 16;
        let k = shared::nearest_point(&self.samples(n), p);
        let start = [
            u0 + (u1 - u0) * (k / (n + 1)) as f64 / n as f64,
            v0 + (v1 - v0) * (k % (n + 1)) as f64 / n as f64,
        ];
        let uv = triangulate::nearest_parameter(self, *p, start);
        let uv = [uv[0].clamp(u0, u1), uv[1].clamp(v0, v1)];
        let uv = if uv[0].is_finite() && uv[1].is_finite() {
            uv
        } else {
            start
        };
        let q = self.point(uv[0], uv[1]);
        let (du, dv) = self.tangents(uv[0], uv[1]);
        let normal = du.cross(&dv);
        let len = normal.norm();
        (len > 0.0 && len.is_finite()).then(|| (q, normal / len))
    }

    /// W(u, v): the trim value with the material sign positive (1 without a trim).
    pub fn material(&self, u: f64, v: f64) -> f64 {
        match &self.trim {
            None => 1.0,
            Some(t) => {
                let p = self.point(u, v);
                let f = t.program.eval_point([p.x, p.y, p.z]);
                if t.negative { -f } else { f }
            }
        }
    }
}

/// De Casteljau in v within each row, then in u across the results.
fn bezier(rows: &[Vec<Point3>], u: f64, v: f64) -> Point3 {
    let column: Vec<Point3> = rows.iter().map(|row| de_casteljau(row, v)).collect();
    de_casteljau(&column, u)
}

fn de_casteljau(points: &[Point3], t: f64) -> Point3 {
    let mut work: Vec<Point3> = points.to_vec();
    let n = work.len();
    for level in 1..n {
        for i in 0..n - level {
            work[i] = work[i] + (work[i + 1] - work[i]) * t;
        }
    }
    work.first()
        .copied()
        .unwrap_or(Point3::new(f64::NAN, f64::NAN, f64::NAN))
}

#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_patch9;
#[cfg(test)]
mod tests_seam_cut;
#[cfg(test)]
mod tests_seams;
