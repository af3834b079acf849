//! Light intensity from a normal: a square root and a division per slot,
//! half a million of them for a large smooth mesh. [`intensities`] does four
//! slots at once with AVX2 when the CPU has it: the same IEEE operations in
//! the same order as [`intensity`] (nothing fused; a square root and a
//! division are exactly rounded either way), so the same bits.

use super::camera::dot;
use super::normal_sum::Sum;
use std::mem::MaybeUninit;

/// Seen on the front and the back side: 0.25 ambient plus 0.75 times the
/// cosine to the light on that side; 0.6 for a normal of no direction.
#[inline]
pub fn intensity(normal: [f64; 3], light: [f64; 3]) -> [f32; 2] {
    let len = dot(normal, normal).sqrt();
    if len == 0.0 || !len.is_finite() {
        return [0.6, 0.6];
    }
    let c = dot(normal, light) / len;
    [
        (0.25 + 0.75 * c.max(0.0)) as f32,
        (0.25 + 0.75 * (-c).max(0.0)) as f32,
    ]
}

/// `out[i] = intensity(sums[i], light)`; `out` and `sums` have one length.
/// Every element of `out` is written (it need not be initialised before:
/// the light of half a million nodes is not zeroed first).
pub fn intensities(sums: &[Sum], light: [f64; 3], out: &mut [MaybeUninit<[f32; 2]>]) {
    assert_eq!(out.len(), sums.len());
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has AVX2 (checked just above).
            unsafe { intensities_avx2(sums, light, out) };
            return;
        }
    }
    for (o, s) in out.iter_mut().zip(sums) {
        o.write(intensity(s.xyz(), light));
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn intensities_avx2(sums: &[Sum], light: [f64; 3], out: &mut [MaybeUninit<[f32; 2]>]) {
    use std::arch::x86_64::*;
    let mut four_out = out.chunks_exact_mut(4);
    let mut four_sums = sums.chunks_exact(4);
    let [l0, l1, l2] = light.map(|v| _mm256_set1_pd(v));
    let (zero, quarter, three_quarters) = (
        _mm256_setzero_pd(),
        _mm256_set1_pd(0.25),
        _mm256_set1_pd(0.75),
    );
    let (sign, infinity, flat) = (
        _mm256_set1_pd(-0.0),
        _mm256_set1_pd(f64::INFINITY),
        _mm256_set1_pd(0.6),
    );
    for (o, s) in (&mut four_out).zip(&mut four_sums) {
        // SAFETY: each `Sum` is four f64s aligned to 32 bytes.
        let [r0, r1, r2, r3] = [0, 1, 2, 3].map(|k| unsafe { _mm256_load_pd(s[k].0.as_ptr()) });
        // Rows (x, y, z, 0) of four slots to columns x, y, z.
        let (t0, t1) = (_mm256_unpacklo_pd(r0, r1), _mm256_unpackhi_pd(r0, r1));
        let (t2, t3) = (_mm256_unpacklo_pd(r2, r3), _mm256_unpackhi_pd(r2, r3));
        let x = _mm256_permute2f128_pd::<0x20>(t0, t2);
        let y = _mm256_permute2f128_pd::<0x20>(t1, t3);
        let z = _mm256_permute2f128_pd::<0x31>(t0, t2);
        let dot = |a: __m256d, b: __m256d, c: __m256d| {
            _mm256_add_pd(
                _mm256_add_pd(_mm256_mul_pd(x, a), _mm256_mul_pd(y, b)),
                _mm256_mul_pd(z, c),
            )
        };
        let len = _mm256_sqrt_pd(dot(x, y, z));
        // Finite and not zero (a length is never negative; NaN fails both).
        let ok = _mm256_and_pd(
            _mm256_cmp_pd::<_CMP_LT_OQ>(len, infinity),
            _mm256_cmp_pd::<_CMP_GT_OQ>(len, zero),
        );
        let c = _mm256_div_pd(dot(l0, l1, l2), len);
        // `max(v, 0)` gives 0 for NaN, as `f64::max` does.
        let side = |v: __m256d| {
            let lit = _mm256_add_pd(
                quarter,
                _mm256_mul_pd(three_quarters, _mm256_max_pd(v, zero)),
            );
            _mm256_cvtpd_ps(_mm256_blendv_pd(flat, lit, ok))
        };
        let (front, back) = (side(c), side(_mm256_xor_pd(c, sign)));
        let pairs = _mm256_set_m128(_mm_unpackhi_ps(front, back), _mm_unpacklo_ps(front, back));
        // SAFETY: `o` is four slots of [f32; 2], 32 contiguous bytes.
        unsafe { _mm256_storeu_ps(o.as_mut_ptr().cast(), pairs) };
    }
    for (o, s) in four_out
        .into_remainder()
        .iter_mut()
        .zip(four_sums.remainder())
    {
        o.write(intensity(s.xyz(), light));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn four_at_a_time_matches_one_at_a_time_bit_for_bit() {
        let light = {
            let l = [0.3f64, -0.55, 0.77];
            let n = dot(l, l).sqrt();
            l.map(|v| v / n)
        };
        let mut sums: Vec<Sum> = (0..1001)
            .map(|i| {
                let t = i as f64 * 0.754_877_666;
                Sum([
                    t.sin() * 3.1e-3,
                    (1.3 * t).cos(),
                    (0.7 * t).sin() * 17.0,
                    0.0,
                ])
            })
            .collect();
        // No direction, a zero of either sign, overflow and NaN: 0.6 each.
        sums[3] = Sum([0.0; 4]);
        sums[8] = Sum([-0.0, 0.0, -0.0, 0.0]);
        sums[9] = Sum([1e300, 1e300, 0.0, 0.0]);
        sums[10] = Sum([f64::NAN, 1.0, 0.0, 0.0]);
        sums[11] = Sum([f64::INFINITY, 0.0, 0.0, 0.0]);
        // Facing the light and facing away.
        sums[12] = Sum([light[0], light[1], light[2], 0.0]);
        sums[13] = Sum([-light[0], -light[1], -light[2], 0.0]);
        let mut got = vec![MaybeUninit::new([7.0f32; 2]); sums.len()];
        intensities(&sums, light, &mut got);
        // SAFETY: every element was initialised above (and written again).
        let got: Vec<[f32; 2]> = got
            .into_iter()
            .map(|v| unsafe { v.assume_init() })
            .collect();
        // Every slot was written: none keeps the 7 it had.
        assert!(got.iter().all(|v| v[0] <= 1.0 && v[1] <= 1.0));
        for (g, s) in got.iter().zip(&sums) {
            let want = intensity(s.xyz(), light);
            assert_eq!(g.map(f32::to_bits), want.map(f32::to_bits), "{s:?}");
        }
        for k in [3, 8, 9, 10, 11] {
            assert_eq!(got[k], [0.6, 0.6]);
        }
        assert_eq!(got[12], [1.0, 0.25]);
        assert_eq!(got[13], [0.25, 1.0]);
    }
}
