//! Views and the orthographic camera: a view direction from azimuth and
//! elevation (or a named view), and the map from model coordinates to image
//! pixels that fits the model into the picture.

use super::RenderError;

/// A view direction in degrees. Azimuth 0, elevation 0 looks along +y (the
/// front view, z up); elevation 90 looks down −z (the top view, y up);
/// positive azimuth turns the eye towards +x.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct View {
    pub azimuth: f64,
    pub elevation: f64,
}

impl View {
    pub const FRONT: View = View {
        azimuth: 0.0,
        elevation: 0.0,
    };
    pub const TOP: View = View {
        azimuth: 0.0,
        elevation: 90.0,
    };
    /// The isometric view: the eye on the diagonal (+1, −1, +1) direction
    /// seen from the front right above.
    pub const ISO: View = View {
        azimuth: 45.0,
        elevation: 35.264_389_682_754_654,
    };

    /// `front`, `top`, `iso`, or `AZIMUTH,ELEVATION` in degrees.
    pub fn parse(text: &str) -> Result<View, RenderError> {
        let t = text.trim().to_ascii_lowercase();
        match t.as_str() {
            "front" => return Ok(View::FRONT),
            "top" => return Ok(View::TOP),
            "iso" => return Ok(View::ISO),
            _ => {}
        }
        let bad = || RenderError::View(text.to_string());
        let (a, e) = t.split_once(',').ok_or_else(bad)?;
        let azimuth: f64 = a.trim().parse().map_err(|_| bad())?;
        let elevation: f64 = e.trim().parse().map_err(|_| bad())?;
        if !azimuth.is_finite() || !(-90.0..=90.0).contains(&elevation) {
            return Err(bad());
        }
        Ok(View { azimuth, elevation })
    }
}

/// An orthographic camera: image x grows to the right, image y downwards,
/// depth grows away from the eye.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    pub right: [f64; 3],
    pub up: [f64; 3],
    /// From the model towards the eye.
    pub toward_eye: [f64; 3],
    /// Pixels per model unit.
    pub scale: f64,
    /// The model point that maps to the image centre.
    pub center: [f64; 3],
    pub width: u32,
    pub height: u32,
}

/// Fraction of the smaller image side left free around the model.
pub const MARGIN: f64 = 0.1;

impl Camera {
    /// Fits `points` into a `width`×`height` picture seen from `view`, leaving
    /// [`MARGIN`] free on each side of the tighter axis.
    pub fn fit(view: View, points: &[[f64; 3]], width: u32, height: u32) -> Camera {
        Camera::fit_with_depths(view, points, width, height).0
    }

    /// [`Camera::fit`], and what its pass over the points tells of their
    /// depths ([`DepthHint`]), so the depth range needs no pass of its own.
    pub fn fit_with_depths(
        view: View,
        points: &[[f64; 3]],
        width: u32,
        height: u32,
    ) -> (Camera, DepthHint<'_>) {
        let (az, el) = (view.azimuth.to_radians(), view.elevation.to_radians());
        let toward_eye = [az.sin() * el.cos(), -az.cos() * el.cos(), el.sin()];
        let right = [az.cos(), az.sin(), 0.0];
        let up = cross(toward_eye, right);
        let ((mut lo, mut hi), depths) = extent(points, [right, up, toward_eye]);
        if points.is_empty() {
            lo = [-1.0, -1.0];
            hi = [1.0, 1.0];
        }
        let extent = [(hi[0] - lo[0]).max(1e-300), (hi[1] - lo[1]).max(1e-300)];
        let free = 1.0 - 2.0 * MARGIN;
        let scale = (width as f64 * free / extent[0]).min(height as f64 * free / extent[1]);
        let (cu, cv) = (0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]));
        let center = [
            cu * right[0] + cv * up[0],
            cu * right[1] + cv * up[1],
            cu * right[2] + cv * up[2],
        ];
        let camera = Camera {
            right,
            up,
            toward_eye,
            scale,
            center,
            width,
            height,
        };
        let hint = DepthHint {
            points,
            toward_eye,
            blocks: depths,
        };
        (camera, hint)
    }

    /// Image x and y in pixels (continuous: pixel i covers [i, i+1)) and the
    /// depth in model units (larger is farther).
    pub fn project(&self, p: [f64; 3]) -> [f64; 3] {
        let d = [
            p[0] - self.center[0],
            p[1] - self.center[1],
            p[2] - self.center[2],
        ];
        [
            0.5 * self.width as f64 + self.scale * dot(d, self.right),
            0.5 * self.height as f64 - self.scale * dot(d, self.up),
            -dot(d, self.toward_eye),
        ]
    }

    /// The depth [`Camera::project`] gives, alone (the same arithmetic, so
    /// the same bits): the depth range of a million nodes costs one dot
    /// product each instead of three.
    #[inline]
    pub fn depth(&self, p: [f64; 3]) -> f64 {
        let d = [
            p[0] - self.center[0],
            p[1] - self.center[1],
            p[2] - self.center[2],
        ];
        -dot(d, self.toward_eye)
    }
}

/// Nodes per unit of parallel work in [`extent`].
const BLOCK: usize = 1 << 13;

/// What [`Camera::fit`]'s pass learnt of the depths of a block of points:
/// the least and greatest `p·toward_eye` (as computed, NaN skipped) and the
/// greatest magnitude of each coordinate. A node's depth
/// (`−(p − centre)·toward_eye`) differs from `centre·toward_eye − p·toward_eye`
/// by rounding alone, which the magnitudes bound: only blocks whose
/// `p·toward_eye` comes that close to the least or greatest can hold the
/// nearest or farthest node.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DepthBlock {
    pub toward: (f64, f64),
    pub magnitude: [f64; 3],
}

/// The [`DepthBlock`]s of the points a camera was fitted to, per [`BLOCK`]
/// of them in order, kept with those points (borrowed: they cannot change
/// meanwhile) and the view's direction; `None` without AVX2.
pub struct DepthHint<'p> {
    points: &'p [[f64; 3]],
    toward_eye: [f64; 3],
    blocks: Option<Vec<DepthBlock>>,
}

impl<'p> DepthHint<'p> {
    /// Per block of `points` (the points the camera was fitted to, seen
    /// along `toward_eye`), the block and its [`DepthBlock`]; `None` for other
    /// points or another view, or without the blocks.
    pub fn blocks(
        &self,
        points: &[[f64; 3]],
        toward_eye: [f64; 3],
    ) -> Option<impl Iterator<Item = (&'p [[f64; 3]], DepthBlock)>> {
        let same = std::ptr::eq(self.points, points)
            && self.toward_eye.map(f64::to_bits) == toward_eye.map(f64::to_bits);
        let blocks = self.blocks.as_ref().filter(|_| same)?;
        Some(self.points.chunks(BLOCK).zip(blocks.iter().copied()))
    }
}

/// The least and greatest `p·right` and `p·up` over the points (infinite
/// bounds when there are none), with AVX2 also the [`DepthBlock`]s along
/// `toward_eye` (`axes` is right, up, toward_eye). Blocks are folded in
/// order and joined in block order with the same comparisons, so the bounds
/// are the serial fold's (on ties the first value is kept either way) for
/// any thread count.
fn extent(points: &[[f64; 3]], axes: [[f64; 3]; 3]) -> (Bounds, Option<Vec<DepthBlock>>) {
    use rayon::prelude::*;
    let empty = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    let blocks: Vec<(Bounds, Option<DepthBlock>)> = points
        .par_chunks(BLOCK)
        .map(|block| block_extent(block, axes))
        .collect();
    let depths = blocks.iter().map(|(_, d)| *d).collect();
    let bounds = blocks.into_iter().fold(empty, |(lo, hi), ((bl, bh), _)| {
        (
            [below(bl[0], lo[0]), below(bl[1], lo[1])],
            [above(bh[0], hi[0]), above(bh[1], hi[1])],
        )
    });
    (bounds, depths)
}

/// Least and greatest `p·right` and `p·up`.
type Bounds = ([f64; 2], [f64; 2]);

/// [`extent`] of one block, serially: with SSE2 the two dot products are the
/// lanes of one vector (the same products and sums in the same order as
/// [`dot`]), and `minpd`/`maxpd` are [`below`]/[`above`] lane by lane.
#[inline]
fn block_extent(points: &[[f64; 3]], axes: [[f64; 3]; 3]) -> (Bounds, Option<DepthBlock>) {
    let [right, up, _] = axes;
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has AVX2 (checked just above).
            let (bounds, depths) = unsafe { block_extent_avx2(points, axes) };
            // SAFETY: SSE2 is part of every x86-64.
            let bounds = bounds.unwrap_or_else(|| unsafe { block_extent_sse2(points, right, up) });
            return (bounds, Some(depths));
        }
        // SAFETY: SSE2 is part of every x86-64.
        (unsafe { block_extent_sse2(points, right, up) }, None)
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        (scalar_extent(points, right, up), None)
    }
}

/// [`block_extent`] four nodes per vector: the same products and sums per
/// lane as [`dot`], and `minpd`/`maxpd` are [`below`]/[`above`] lane by
/// lane. The lanes meet the nodes in another order than the serial fold,
/// which only matters for equal values of different bits, zeros (the fold
/// keeps the first zero's sign): `None` when any bound is a zero. The
/// [`DepthBlock`] too, alike (its zeros' signs do not matter).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn block_extent_avx2(points: &[[f64; 3]], axes: [[f64; 3]; 3]) -> (Option<Bounds>, DepthBlock) {
    use std::arch::x86_64::*;
    let whole = points.len() / 4 * 4;
    let splat = |v: f64| _mm256_set1_pd(v);
    let [[r0, r1, r2], [u0, u1, u2], [t0, t1, t2]] = axes.map(|a| a.map(splat));
    let mut lo = [splat(f64::INFINITY); 3];
    let mut hi = [splat(f64::NEG_INFINITY); 3];
    let mut magnitude = [splat(0.0); 3];
    let sign = splat(-0.0);
    for q in points[..whole].as_chunks::<4>().0 {
        let xyz = crate::render::project::avx2::four_points_by_axis(q);
        let [x, y, z] = xyz;
        let dot = |a0: __m256d, a1: __m256d, a2: __m256d| {
            _mm256_add_pd(
                _mm256_add_pd(_mm256_mul_pd(x, a0), _mm256_mul_pd(y, a1)),
                _mm256_mul_pd(z, a2),
            )
        };
        let dots = [dot(r0, r1, r2), dot(u0, u1, u2), dot(t0, t1, t2)];
        for (k, v) in dots.into_iter().enumerate() {
            lo[k] = _mm256_min_pd(v, lo[k]);
            hi[k] = _mm256_max_pd(v, hi[k]);
            // `maxpd` keeps the old magnitude for a NaN coordinate.
            magnitude[k] = _mm256_max_pd(_mm256_andnot_pd(sign, xyz[k]), magnitude[k]);
        }
    }
    let lanes = |v: __m256d| {
        let mut a = [0.0; 4];
        // SAFETY: `a` is four f64s.
        unsafe { _mm256_storeu_pd(a.as_mut_ptr(), v) };
        a
    };
    let (mut l, mut h) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    let mut m = [0.0f64; 3];
    for k in 0..3 {
        for ((a, b), c) in lanes(lo[k])
            .into_iter()
            .zip(lanes(hi[k]))
            .zip(lanes(magnitude[k]))
        {
            (l[k], h[k], m[k]) = (below(a, l[k]), above(b, h[k]), above(c, m[k]));
        }
    }
    for p in &points[whole..] {
        for k in 0..3 {
            let v = dot(*p, axes[k]);
            (l[k], h[k], m[k]) = (below(v, l[k]), above(v, h[k]), above(p[k].abs(), m[k]));
        }
    }
    let depths = DepthBlock {
        toward: (l[2], h[2]),
        magnitude: m,
    };
    let bounds = ([l[0], l[1]], [h[0], h[1]]);
    let no_zero = l[..2].iter().chain(&h[..2]).all(|&b| b != 0.0);
    (no_zero.then_some(bounds), depths)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "sse2")]
fn block_extent_sse2(points: &[[f64; 3]], right: [f64; 3], up: [f64; 3]) -> ([f64; 2], [f64; 2]) {
    {
        use std::arch::x86_64::*;
        let lanes = |k: usize| _mm_set_pd(up[k], right[k]);
        let (r0, r1, r2) = (lanes(0), lanes(1), lanes(2));
        let mut lo = _mm_set1_pd(f64::INFINITY);
        let mut hi = _mm_set1_pd(f64::NEG_INFINITY);
        for p in points {
            let uv = _mm_add_pd(
                _mm_add_pd(
                    _mm_mul_pd(_mm_set1_pd(p[0]), r0),
                    _mm_mul_pd(_mm_set1_pd(p[1]), r1),
                ),
                _mm_mul_pd(_mm_set1_pd(p[2]), r2),
            );
            // `minpd a, b` is `a < b ? a : b`: `below(uv, lo)` per lane.
            lo = _mm_min_pd(uv, lo);
            hi = _mm_max_pd(uv, hi);
        }
        let pair = |v: __m128d| [_mm_cvtsd_f64(v), _mm_cvtsd_f64(_mm_unpackhi_pd(v, v))];
        (pair(lo), pair(hi))
    }
}

/// The serial fold [`block_extent`]'s lanes follow (and the path off x86-64).
#[cfg_attr(target_arch = "x86_64", allow(dead_code))]
fn scalar_extent(points: &[[f64; 3]], right: [f64; 3], up: [f64; 3]) -> ([f64; 2], [f64; 2]) {
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for p in points {
        let (u, v) = (dot(*p, right), dot(*p, up));
        lo = [below(u, lo[0]), below(v, lo[1])];
        hi = [above(u, hi[0]), above(v, hi[1])];
    }
    (lo, hi)
}

/// `v` when it is below `bound`, else `bound`: `f64::min` for a bound that is
/// never NaN (a NaN `v` keeps the bound), in one `minsd` instead of the
/// three or four instructions `f64::min`'s NaN rule costs; a million nodes
/// make it count.
#[inline]
pub fn below(v: f64, bound: f64) -> f64 {
    if v < bound { v } else { bound }
}

/// `v` when it is above `bound`, else `bound` (see [`below`]).
#[inline]
pub fn above(v: f64, bound: f64) -> f64 {
    if v > bound { v } else { bound }
}

pub fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extent_lanes_are_the_serial_fold_bit_for_bit() {
        // Values whose products round, ties of +0 and −0 (the first is
        // kept), a NaN (never taken) and more than one block.
        let mut points: Vec<[f64; 3]> = (0..3 * BLOCK + 17)
            .map(|i| {
                let t = i as f64 * 0.618_033_988_749_895;
                [
                    t.sin() * 1.3e3,
                    (t * 1.7).cos() * 0.37,
                    t.fract() * 1e-3 - 7.0,
                ]
            })
            .collect();
        points[5] = [f64::NAN, 1.0, 2.0];
        let right = [0.6, 0.8, 0.0];
        let up = [-0.48, 0.36, 0.8];
        let toward = [0.64, -0.48, 0.6];
        let cuts = [(0, points.len()), (0, 40), (1, 42), (2, 43), (3, 4099)];
        for (from, to) in cuts {
            let part = &points[from..to];
            let ((lo, hi), _) = extent(part, [right, up, toward]);
            let (want_lo, want_hi) = scalar_extent(part, right, up);
            assert_eq!(lo.map(f64::to_bits), want_lo.map(f64::to_bits));
            assert_eq!(hi.map(f64::to_bits), want_hi.map(f64::to_bits));
            assert!(lo[0] < hi[0] && lo[1] < hi[1]);
        }
        let zeros = [[-0.0, -0.0, -0.0], [0.0, 0.0, 0.0], [-0.0, 0.0, -0.0]];
        let ((lo, hi), _) = extent(&zeros, [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], toward]);
        assert_eq!(lo.map(f64::to_bits), [(-0.0f64).to_bits(); 2]);
        assert_eq!(hi.map(f64::to_bits), [(-0.0f64).to_bits(); 2]);
        // Zeros of either sign in every lane, the first of them in turn
        // in each: the serial fold's signs.
        for first in 0..5 {
            let zeros: Vec<[f64; 3]> = (0..103)
                .map(|i| {
                    let z = if (i + first) % 3 == 0 { -0.0 } else { 0.0 };
                    [z, -z, z]
                })
                .collect();
            for (r, u) in [([1.0, 0.0, 0.0], [0.0, 0.0, 1.0]), (right, up)] {
                let ((lo, hi), _) = extent(&zeros, [r, u, toward]);
                let (want_lo, want_hi) = scalar_extent(&zeros, r, u);
                assert_eq!(lo.map(f64::to_bits), want_lo.map(f64::to_bits));
                assert_eq!(hi.map(f64::to_bits), want_hi.map(f64::to_bits));
            }
        }
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has AVX2 (checked just above).
            let (lanes, depths) =
                unsafe { block_extent_avx2(&points[..BLOCK], [right, up, toward]) };
            let want = scalar_extent(&points[..BLOCK], right, up);
            let bits = |(l, h): ([f64; 2], [f64; 2])| (l.map(f64::to_bits), h.map(f64::to_bits));
            assert_eq!(lanes.map(bits), Some(bits(want)));
            // The depth block: the serial bounds of `p·toward` and of each
            // coordinate's magnitude (the NaN node skipped).
            let (least, most) = scalar_extent(&points[..BLOCK], right, toward);
            assert_eq!(depths.toward, (least[1], most[1]));
            let most = |k: usize| (points[..BLOCK].iter()).fold(0.0, |m, p| above(p[k].abs(), m));
            assert_eq!(depths.magnitude, [most(0), most(1), most(2)]);
            // Node 0 is (0, 0.37, −7): the greatest |z|.
            assert_eq!(depths.magnitude[2], 7.0);
            let zeros = [[0.0, -0.0, 0.0]; 9];
            // SAFETY: as above.
            assert_eq!(
                unsafe { block_extent_avx2(&zeros, [right, up, toward]) }.0,
                None
            );
        }
        assert_eq!(
            extent(&[], [right, up, toward]).0,
            ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2])
        );
    }

    #[test]
    fn named_views_and_projection() {
        let pts = [[-1.0, -1.0, -1.0], [1.0, 1.0, 1.0]];
        let front = Camera::fit(View::FRONT, &pts, 100, 100);
        // x to the right, z up, y away from the eye.
        let p = front.project([1.0, -1.0, 1.0]);
        assert!((p[0] - 90.0).abs() < 1e-9 && (p[1] - 10.0).abs() < 1e-9);
        assert!(front.project([0.0, 1.0, 0.0])[2] > front.project([0.0, -1.0, 0.0])[2]);
        let top = Camera::fit(View::TOP, &pts, 100, 100);
        let q = top.project([1.0, 1.0, 0.0]);
        assert!((q[0] - 90.0).abs() < 1e-9 && (q[1] - 10.0).abs() < 1e-9);
        assert_eq!(
            View::parse("30, 20").ok(),
            Some(View {
                azimuth: 30.0,
                elevation: 20.0
            })
        );
        assert!(View::parse("sideways").is_err());
        assert!(View::parse("0,91").is_err());
    }
}
