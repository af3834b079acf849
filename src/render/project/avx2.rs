//! The projection four nodes at a time: each quantity of [`NodeMap::block_sse2`]
//! (the differences to the centre, the depth, image x and y, the clamp and
//! the snap) is one AVX2 vector of four nodes instead of one lane pair per
//! node, so a node takes about half the instructions. Every lane does the
//! same IEEE operations in the same order as the scalar code (nothing
//! fused; the depth's division and the conversions are exactly rounded), so
//! the same bits.

use super::{LIMIT, NodeMap, XyOut};
use crate::render::camera::{Camera, above, below};
use crate::render::raster::Snapped;
use std::arch::x86_64::*;
use std::mem::MaybeUninit;

impl NodeMap {
    /// [`NodeMap::block`] with AVX2: whole groups of four nodes here, the
    /// last one to three by [`NodeMap::block_sse2`].
    #[target_feature(enable = "avx2")]
    pub(super) fn block_avx2(
        self,
        points: &[[f64; 3]],
        snapped: &mut [MaybeUninit<Snapped>],
        mut xy_f: impl XyOut,
    ) {
        let whole = points.len() / 4 * 4;
        let splat = |v: f64| _mm256_set1_pd(v);
        let [c0, c1, c2] = self.center.map(splat);
        let [t0, t1, t2] = self.toward_eye.map(splat);
        let [r0, r1, r2] = self.right_up.map(|f| splat(f[0]));
        let [u0, u1, u2] = self.right_up.map(|f| splat(f[1]));
        let (half_x, half_y) = (splat(self.half[0]), splat(self.half[1]));
        let (scale_x, scale_y) = (splat(self.scale[0]), splat(self.scale[1]));
        let (ss, lo, range) = (splat(self.ss), splat(self.lo), splat(self.range));
        let (limit_lo, limit_hi) = (splat(-LIMIT), splat(LIMIT));
        let (sixteen, sign, one_half) = (splat(16.0), splat(-0.0), splat(0.5));
        assert_eq!(xy_f.len(), points.len());
        let four = (points[..whole].as_chunks::<4>().0.iter())
            .zip(snapped[..whole].chunks_exact_mut(4))
            .enumerate();
        for (i, (q, s)) in four {
            let [x, y, z] = four_points_by_axis(q);
            let d = [
                _mm256_sub_pd(x, c0),
                _mm256_sub_pd(y, c1),
                _mm256_sub_pd(z, c2),
            ];
            // `dot`'s sum: (d0·a0 + d1·a1) + d2·a2.
            let dot = |a0: __m256d, a1: __m256d, a2: __m256d| {
                _mm256_add_pd(
                    _mm256_add_pd(_mm256_mul_pd(d[0], a0), _mm256_mul_pd(d[1], a1)),
                    _mm256_mul_pd(d[2], a2),
                )
            };
            // `Camera::depth` (negation flips the sign bit), normalised.
            let depth = _mm256_xor_pd(dot(t0, t1, t2), sign);
            let z = _mm256_cvtpd_ps(_mm256_div_pd(_mm256_sub_pd(depth, lo), range));
            // Image x or y scaled to samples and clamped (`maxpd`/`minpd`
            // keep a NaN as `f64::clamp` does, as in the SSE2 lanes).
            let clamped = |half: __m256d, scale: __m256d, dots: __m256d| {
                let image = _mm256_add_pd(half, _mm256_mul_pd(scale, dots));
                _mm256_min_pd(limit_hi, _mm256_max_pd(limit_lo, _mm256_mul_pd(image, ss)))
            };
            let vx = clamped(half_x, scale_x, dot(r0, r1, r2));
            let vy = clamped(half_y, scale_y, dot(u0, u1, u2));
            // `snap`: v·16 plus a half with its sign, a NaN zeroed, truncated.
            let snap = |v: __m256d| {
                let v16 = _mm256_mul_pd(v, sixteen);
                let rounded = _mm256_add_pd(v16, _mm256_or_pd(_mm256_and_pd(v16, sign), one_half));
                let ordered = _mm256_cmp_pd::<_CMP_ORD_Q>(rounded, rounded);
                _mm256_cvttpd_epi32(_mm256_and_pd(rounded, ordered))
            };
            let (fx, fy) = (_mm256_cvtpd_ps(vx), _mm256_cvtpd_ps(vy));
            // SAFETY: `4i + 3 < whole`, at most `xy_f.len()` (asserted).
            unsafe { xy_f.four(4 * i, fx, fy) };
            let (mut sx, mut sy, mut sz) = ([0i32; 4], [0i32; 4], [0f32; 4]);
            // SAFETY: each array is four 32-bit values.
            unsafe {
                _mm_storeu_si128(sx.as_mut_ptr().cast(), snap(vx));
                _mm_storeu_si128(sy.as_mut_ptr().cast(), snap(vy));
                _mm_storeu_ps(sz.as_mut_ptr(), z);
            }
            for (k, slot) in s.iter_mut().enumerate() {
                slot.write(Snapped {
                    x: sx[k],
                    y: sy[k],
                    z: sz[k],
                });
            }
        }
        self.block_sse2(&points[whole..], &mut snapped[whole..], xy_f.from(whole));
    }
}

/// The least and greatest [`Camera::depth`] of `points` (the serial fold of
/// `below` and `above`), four nodes per vector: the same depth bits per lane
/// as [`NodeMap::block_avx2`] computes, and `minpd`/`maxpd` are `below` and
/// `above` lane by lane. The lanes meet the nodes in another order than the
/// serial fold, which only matters for equal values of different bits: a
/// zero (the fold keeps the sign of the first zero it meets). So `None` when
/// either bound is a zero: the caller folds serially.
#[target_feature(enable = "avx2")]
pub(super) fn depth_bounds(points: &[[f64; 3]], camera: &Camera) -> Option<(f64, f64)> {
    let whole = points.len() / 4 * 4;
    let splat = |v: f64| _mm256_set1_pd(v);
    let [c0, c1, c2] = camera.center.map(splat);
    let [t0, t1, t2] = camera.toward_eye.map(splat);
    let sign = splat(-0.0);
    let (mut lo, mut hi) = (splat(f64::INFINITY), splat(f64::NEG_INFINITY));
    for q in points[..whole].as_chunks::<4>().0 {
        let [x, y, z] = four_points_by_axis(q);
        // `dot(p − centre, toward_eye)`: (d0·t0 + d1·t1) + d2·t2, negated.
        let dot = _mm256_add_pd(
            _mm256_add_pd(
                _mm256_mul_pd(_mm256_sub_pd(x, c0), t0),
                _mm256_mul_pd(_mm256_sub_pd(y, c1), t1),
            ),
            _mm256_mul_pd(_mm256_sub_pd(z, c2), t2),
        );
        let depth = _mm256_xor_pd(dot, sign);
        // `minpd z, l` is `z < l ? z : l`: `below(z, l)`, a NaN skipped.
        lo = _mm256_min_pd(depth, lo);
        hi = _mm256_max_pd(depth, hi);
    }
    let (mut lows, mut highs) = ([0.0; 4], [0.0; 4]);
    // SAFETY: each array is four f64s.
    unsafe {
        _mm256_storeu_pd(lows.as_mut_ptr(), lo);
        _mm256_storeu_pd(highs.as_mut_ptr(), hi);
    }
    let (mut l, mut h) = (f64::INFINITY, f64::NEG_INFINITY);
    for (a, b) in lows.into_iter().zip(highs) {
        (l, h) = (below(a, l), above(b, h));
    }
    for q in &points[whole..] {
        let z = camera.depth(*q);
        (l, h) = (below(z, l), above(z, h));
    }
    (l != 0.0 && h != 0.0).then_some((l, h))
}

/// Four points' coordinates as one vector per axis (lane i is point i): the
/// twelve coordinates x0 y0 z0 x1 y1 z1 … read as three vectors of pairs
/// (halves: points 0–1 and 2–3), then shuffled. Shared by the projection,
/// the depth range and the camera's extent, which must read alike.
#[inline]
#[target_feature(enable = "avx2")]
pub(in crate::render) fn four_points_by_axis(q: &[[f64; 3]; 4]) -> [__m256d; 3] {
    let p = q.as_ptr().cast::<f64>();
    // SAFETY: `q` is four points, twelve contiguous f64s from `p`; each
    // load reads two of them at `k` and `6 + k` (k ≤ 4).
    let pairs = |k: usize| unsafe {
        _mm256_insertf128_pd::<1>(
            _mm256_castpd128_pd256(_mm_loadu_pd(p.add(k))),
            _mm_loadu_pd(p.add(6 + k)),
        )
    };
    let (xy, zx, yz) = (pairs(0), pairs(2), pairs(4));
    [
        _mm256_shuffle_pd::<0b1010>(xy, zx),
        _mm256_shuffle_pd::<0b0101>(xy, yz),
        _mm256_shuffle_pd::<0b1010>(zx, yz),
    ]
}
