//! Point calculus (paper 003): curves and surfaces written as point equations
//! M = Σ Pᵢ·wᵢ(u, …) with Σ wᵢ = 1. Because the weights sum to one, every
//! object is an affine combination of its defining points: it moves exactly
//! with them under affine maps, and its x, y and z coordinates are the same
//! scalar equation applied to three streams ([`eval`]).
//!
//! Objects: the segment, the conic arc of "engineering discriminant" k, the
//! cubic Desargues arc, the parabola through three points (a side of a
//! 9-point patch) and the 9-point parabolic patch.

mod eval;
mod project;
mod sampling;
#[cfg(test)]
mod tests;
mod weights;

pub use eval::{Streams, eval_curve, eval_patch_grid};
pub use sampling::adaptive_samples;
pub use weights::{conic_weights, desargues_weights, parabola_weights};

use super::{Point3, Vec3};

/// The type of a conic arc, fixed by its discriminant k.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ConicKind {
    /// 0 < k < 0.5.
    Hyperbola,
    /// k = 0.5.
    Parabola,
    /// 0.5 < k < 1.
    Ellipse,
}

impl ConicKind {
    /// The type for k in (0, 1); `None` outside.
    pub fn of(k: f64) -> Option<ConicKind> {
        if !(k > 0.0 && k < 1.0) {
            None
        } else if k < 0.5 {
            Some(ConicKind::Hyperbola)
        } else if k == 0.5 {
            Some(ConicKind::Parabola)
        } else {
            Some(ConicKind::Ellipse)
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            ConicKind::Hyperbola => "hyperbola",
            ConicKind::Parabola => "parabola",
            ConicKind::Ellipse => "ellipse",
        }
    }
}

/// A curve of point calculus over u ∈ [0, 1].
#[derive(Debug, Clone, PartialEq)]
pub enum PcCurve {
    /// M = A·ū + B·u.
    Segment { a: Point3, b: Point3 },
    /// The arc from A to B whose end tangents meet at C, with discriminant k:
    /// M = [(A−C)·k·ū² + (B−C)·k·u²] / [k(1−2u)² + 2uū] + C.
    Conic {
        a: Point3,
        b: Point3,
        c: Point3,
        k: f64,
    },
    /// M = (A ū³ + B u² ū + C ū² u + D u³) / (2u² − 2u + 1), from A to D.
    Desargues { points: [Point3; 4] },
    /// The parabola through `points` at u = 0, ½, 1 (a side of a 9-point patch).
    Parabola { points: [Point3; 3] },
}

impl PcCurve {
    /// The defining points, in the order the weights use.
    pub fn points(&self) -> Vec<Point3> {
        match self {
            PcCurve::Segment { a, b } => vec![*a, *b],
            PcCurve::Conic { a, b, c, .. } => vec![*a, *b, *c],
            PcCurve::Desargues { points } => points.to_vec(),
            PcCurve::Parabola { points } => points.to_vec(),
        }
    }

    /// The weights of the defining points at u and their derivatives in u.
    /// The weights sum to 1 (and the derivatives to 0) for every u.
    pub fn weights(&self, u: f64) -> ([f64; 4], [f64; 4]) {
        match self {
            PcCurve::Segment { .. } => ([1.0 - u, u, 0.0, 0.0], [-1.0, 1.0, 0.0, 0.0]),
            PcCurve::Conic { k, .. } => {
                let (w, d) = conic_weights(*k, u);
                ([w[0], w[1], w[2], 0.0], [d[0], d[1], d[2], 0.0])
            }
            PcCurve::Desargues { .. } => desargues_weights(u),
            PcCurve::Parabola { .. } => {
                let (w, d) = parabola_weights(u);
                ([w[0], w[1], w[2], 0.0], [d[0], d[1], d[2], 0.0])
            }
        }
    }

    pub fn begin(&self) -> Point3 {
        match self {
            PcCurve::Segment { a, .. } | PcCurve::Conic { a, .. } => *a,
            PcCurve::Desargues { points } => points[0],
            PcCurve::Parabola { points } => points[0],
        }
    }

    pub fn end(&self) -> Point3 {
        match self {
            PcCurve::Segment { b, .. } | PcCurve::Conic { b, .. } => *b,
            PcCurve::Desargues { points } => points[3],
            PcCurve::Parabola { points } => points[2],
        }
    }

    /// The point at u: Σ wᵢ(u)·Pᵢ, the same arithmetic as [`eval_curve`].
    /// u = 0 and u = 1 give the end points exactly.
    pub fn point(&self, u: f64) -> Point3 {
        if u <= 0.0 {
            return self.begin();
        }
        if u >= 1.0 {
            return self.end();
        }
        let w = eval::curve_weights(self, u);
        let mut m = Vec3::zeros();
        for (p, wi) in self.points().iter().zip(w) {
            m += p.coords * wi;
        }
        Point3::from(m)
    }

    /// dM/du: Σ wᵢ'·(Pᵢ − P_ref) with a reference point whose weight
    /// derivative vanishes at the ends, so end tangents point exactly along
    /// the defining chords (AC and CB for the conic).
    pub fn derivative(&self, u: f64) -> Vec3 {
        let u = u.clamp(0.0, 1.0);
        let (_, d) = self.weights(u);
        let points = self.points();
        // The conic's tangents run along A−C and B−C: measure from C.
        let reference = match self {
            PcCurve::Conic { c, .. } => *c,
            _ if u < 0.5 => points[0],
            _ => points[points.len() - 1],
        };
        points
            .iter()
            .zip(d)
            .map(|(p, di)| (p - reference) * di)
            .sum()
    }

    /// The unit tangent at u (zero where the derivative vanishes).
    pub fn tangent(&self, u: f64) -> Vec3 {
        let d = self.derivative(u);
        let n = d.norm();
        if n > 0.0 && n.is_finite() {
            d / n
        } else {
            Vec3::zeros()
        }
    }

    /// The same curve traversed from its end to its begin.
    pub fn reversed(&self) -> PcCurve {
        match self {
            PcCurve::Segment { a, b } => PcCurve::Segment { a: *b, b: *a },
            PcCurve::Conic { a, b, c, k } => PcCurve::Conic {
                a: *b,
                b: *a,
                c: *c,
                k: *k,
            },
            PcCurve::Desargues {
                points: [a, b, c, d],
            } => PcCurve::Desargues {
                // u → 1 − u swaps A↔D and the roles of B and C.
                points: [*d, *c, *b, *a],
            },
            PcCurve::Parabola { points: [a, m, b] } => PcCurve::Parabola {
                points: [*b, *m, *a],
            },
        }
    }

    /// The image under p ↦ map(p): exact, since the weights sum to one.
    pub fn mapped(&self, map: impl Fn(&Point3) -> Point3) -> PcCurve {
        match self {
            PcCurve::Segment { a, b } => PcCurve::Segment {
                a: map(a),
                b: map(b),
            },
            PcCurve::Conic { a, b, c, k } => PcCurve::Conic {
                a: map(a),
                b: map(b),
                c: map(c),
                k: *k,
            },
            PcCurve::Desargues { points } => PcCurve::Desargues {
                points: points.map(|p| map(&p)),
            },
            PcCurve::Parabola { points } => PcCurve::Parabola {
                points: points.map(|p| map(&p)),
            },
        }
    }

    /// The element name this curve comes from, for messages.
    pub fn element(&self) -> &'static str {
        match self {
            PcCurve::Segment { .. } => "segment",
            PcCurve::Conic { .. } => "conic_arc",
            PcCurve::Desargues { .. } => "desargues_arc",
            PcCurve::Parabola { .. } => "patch9 side",
        }
    }

    /// "conic_arc k = 0.25: hyperbola", "desargues_arc", … for reports.
    pub fn describe(&self) -> String {
        match self {
            PcCurve::Conic { k, .. } => format!(
                "conic_arc k = {}: {}",
                crate::resolve_fmt(*k),
                ConicKind::of(*k).map_or("no conic", ConicKind::name)
            ),
            _ => self.element().to_string(),
        }
    }

    /// `n + 1` points at u = 0, 1/n, …, 1 (n ≥ 1).
    pub fn samples(&self, n: usize) -> Vec<Point3> {
        let n = n.max(1);
        (0..=n).map(|i| self.point(i as f64 / n as f64)).collect()
    }

    /// The length by the chords of 1024 samples.
    pub fn length(&self) -> f64 {
        self.samples(1024)
            .windows(2)
            .map(|w| (w[1] - w[0]).norm())
            .sum()
    }

    /// The nearest curve point to `p` (u clamped to [0, 1]) with its parameter.
    pub fn project(&self, p: &Point3) -> Option<(f64, Point3)> {
        project::curve(self, p)
    }
}

/// The 9-point parabolic patch: rows A, B, C (v = 0, ½, 1) of three points
/// each (u = 0, ½, 1): M = M_A·v̄(1−2v) + 4·M_B·v̄v + M_C·v(2v−1), each row
/// M_A = A1·ū(1−2u) + 4·A2·ūu + A3·u(2u−1).
#[derive(Debug, Clone, PartialEq)]
pub struct Patch9 {
    /// `rows[i][j]`: row i (v), column j (u).
    pub rows: [[Point3; 3]; 3],
}

impl Patch9 {
    /// The point at (u, v): rows combined first (Q_j = Σᵢ wᵢ(v)·P_ij), then
    /// Σ_j w_j(u)·Q_j — the same arithmetic as [`eval_patch_grid`], so the
    /// nine points are interpolated exactly at u, v ∈ {0, ½, 1}.
    pub fn point(&self, u: f64, v: f64) -> Point3 {
        let (wu, _) = parabola_weights(u);
        let (wv, _) = parabola_weights(v);
        let mut m = Vec3::zeros();
        for (j, wj) in wu.iter().enumerate() {
            let q = self.rows[0][j].coords * wv[0]
                + self.rows[1][j].coords * wv[1]
                + self.rows[2][j].coords * wv[2];
            m += q * *wj;
        }
        Point3::from(m)
    }

    /// ∂M/∂u and ∂M/∂v.
    pub fn derivatives(&self, u: f64, v: f64) -> (Vec3, Vec3) {
        let (wu, du) = parabola_weights(u);
        let (wv, dv) = parabola_weights(v);
        let origin = self.rows[0][0];
        let (mut mu, mut mv) = (Vec3::zeros(), Vec3::zeros());
        for i in 0..3 {
            for j in 0..3 {
                let d = self.rows[i][j] - origin;
                mu += d * (wv[i] * du[j]);
                mv += d * (dv[i] * wu[j]);
            }
        }
        (mu, mv)
    }

    /// The unit normal ∂M/∂u × ∂M/∂v (zero where the patch is singular).
    pub fn normal(&self, u: f64, v: f64) -> Vec3 {
        let (mu, mv) = self.derivatives(u, v);
        let n = mu.cross(&mv);
        let len = n.norm();
        if len > 0.0 && len.is_finite() {
            n / len
        } else {
            Vec3::zeros()
        }
    }

    /// The four corners: (u, v) = (0,0), (1,0), (0,1), (1,1).
    pub fn corners(&self) -> [Point3; 4] {
        [
            self.rows[0][0],
            self.rows[0][2],
            self.rows[2][0],
            self.rows[2][2],
        ]
    }

    /// The side between corners `i` and `j` (indices into [`Patch9::corners`]),
    /// running from corner i to corner j; `None` when they are not adjacent.
    pub fn side(&self, i: usize, j: usize) -> Option<PcCurve> {
        let r = &self.rows;
        let forward = |i: usize, j: usize| -> Option<[Point3; 3]> {
            match (i, j) {
                (0, 1) => Some(r[0]),
                (2, 3) => Some(r[2]),
                (0, 2) => Some([r[0][0], r[1][0], r[2][0]]),
                (1, 3) => Some([r[0][2], r[1][2], r[2][2]]),
                _ => None,
            }
        };
        if let Some(points) = forward(i, j) {
            return Some(PcCurve::Parabola { points });
        }
        forward(j, i).map(|[a, m, b]| PcCurve::Parabola { points: [b, m, a] })
    }

    /// The nearest patch point to `p`: parameters (u, v), allowed a little
    /// beyond [0, 1] so that points on the sides project cleanly.
    pub fn project(&self, p: &Point3) -> Option<([f64; 2], Point3)> {
        project::patch(self, p)
    }

    pub fn mapped(&self, map: impl Fn(&Point3) -> Point3) -> Patch9 {
        Patch9 {
            rows: self.rows.map(|row| row.map(|p| map(&p))),
        }
    }
}
