//! The plane the triangulation works in: v mapped by the arc length along the
//! middle line u = u_m, and u by the conformal coordinate ∫ |R_u| g(u_m) / g(u) du
//! with g = |R_v| along v = v_m. For a surface of revolution (sphere, torus,
//! cone) the chart is then exactly conformal (Mercator-like), so angles in the
//! chart are the angles on the surface and the Delaunay triangulation in the
//! chart is close to the one on the surface even where the rings shrink
//! towards a pole; for tensor-product-like surfaces it is close to arc length.

use super::TrimmedSurface;

const SAMPLES: usize = 256;

#[derive(Debug, Clone)]
pub struct ArcChart {
    u: Axis,
    v: Axis,
    /// The 3D arc lengths along the middle lines.
    lengths: (f64, f64),
}

/// Parameter values and the cumulative arc length at each (strictly increasing).
#[derive(Debug, Clone)]
struct Axis {
    t: Vec<f64>,
    s: Vec<f64>,
}

impl Axis {
    fn new(t0: f64, t1: f64, speed: impl Fn(f64) -> f64) -> Result<Axis, String> {
        let t: Vec<f64> = (0..=SAMPLES)
            .map(|i| t0 + (t1 - t0) * i as f64 / SAMPLES as f64)
            .collect();
        let mut s = Vec::with_capacity(t.len());
        s.push(0.0);
        let mut mean = 0.0;
        for w in t.windows(2) {
            mean += speed(0.5 * (w[0] + w[1]));
        }
        mean /= SAMPLES as f64;
        if !(mean.is_finite() && mean > 0.0) {
            return Err("the surface has no finite, non-zero tangents over its rectangle".into());
        }
        for w in t.windows(2) {
            // A floor keeps the map invertible where the surface degenerates.
            let ds = speed(0.5 * (w[0] + w[1])).max(1e-3 * mean) * (w[1] - w[0]);
            let last = *s.last().unwrap_or(&0.0);
            s.push(
                last + if ds.is_finite() {
                    ds
                } else {
                    mean * (w[1] - w[0])
                },
            );
        }
        Ok(Axis { t, s })
    }

    fn forward(&self, t: f64) -> f64 {
        interpolate(&self.t, &self.s, t)
    }

    fn back(&self, s: f64) -> f64 {
        interpolate(&self.s, &self.t, s)
    }

    fn length(&self) -> f64 {
        self.s.last().copied().unwrap_or(0.0)
    }
}

/// Piecewise-linear y(x) for increasing xs, extended linearly at the ends.
fn interpolate(xs: &[f64], ys: &[f64], x: f64) -> f64 {
    let n = xs.len();
    let k = xs.partition_point(|&a| a <= x).clamp(1, n - 1);
    let (x0, x1, y0, y1) = (xs[k - 1], xs[k], ys[k - 1], ys[k]);
    y0 + (y1 - y0) * (x - x0) / (x1 - x0)
}

impl ArcChart {
    pub fn new(s: &TrimmedSurface) -> Result<ArcChart, String> {
        let [u0, u1, v0, v1] = s.rect;
        let (um, vm) = (0.5 * (u0 + u1), 0.5 * (v0 + v1));
        let arc_u = Axis::new(u0, u1, |u| s.tangents(u, vm).0.norm())?;
        let v = Axis::new(v0, v1, |v| s.tangents(um, v).1.norm())?;
        let g_mid = s.tangents(um, vm).1.norm();
        // Where the rings shrink (g → 0) the factor grows; capped so the map
        // stays finite next to a degenerate side.
        let u = if g_mid.is_finite() && g_mid > 0.0 {
            Axis::new(u0, u1, |u| {
                let (du, dv) = s.tangents(u, vm);
                du.norm() * (g_mid / dv.norm().max(1e-3 * g_mid)).min(1e3)
            })?
        } else {
            arc_u.clone()
        };
        Ok(ArcChart {
            lengths: (arc_u.length(), v.length()),
            u,
            v,
        })
    }

    pub fn to_chart(&self, uv: [f64; 2]) -> [f64; 2] {
        [self.u.forward(uv[0]), self.v.forward(uv[1])]
    }

    pub fn to_param(&self, xy: [f64; 2]) -> [f64; 2] {
        [self.u.back(xy[0]), self.v.back(xy[1])]
    }

    /// The surface's extent: the 3D arc lengths along the middle lines in u and in v.
    pub fn lengths(&self) -> (f64, f64) {
        self.lengths
    }
}
