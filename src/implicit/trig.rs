//! sin and cos over the f64 tape's lanes without a libm call per lane.
//!
//! Why: on the gyroid (M2) the root finding's f64 `sin`/`cos` calls were
//! over a quarter of the whole path's CPU time; libm evaluates one value per
//! call and cannot be vectorised. Here each lane is reduced by π/2 (Cody and
//! Waite: π/2 split into three parts, the first two of 33 bits so that
//! k · part is exact for |k| < 2²⁰) and the sine or cosine of the remainder
//! (|r| ≤ π/4 and a little) comes from its Taylor polynomial, cut where the
//! next term is below 10⁻¹⁶ of the value. The loop has no branches, so the
//! compiler vectorises it (and an AVX2 copy is chosen at run time); only
//! add, subtract and multiply are used, so the result is the same with and
//! without AVX2. The values agree with libm's to within a few units in the
//! last place (test `lanes_agree_with_libm`); arguments beyond ±10⁵ (and
//! NaN, ±∞) take libm.

/// 2/π rounded to f64.
const FRAC_2_PI: f64 = std::f64::consts::FRAC_2_PI;
/// π/2 = P1 + P2 + P3 (to 10⁻³⁷); P1 and P2 have 33 significant bits.
const P1: f64 = f64::from_bits(0x3FF9_21FB_5440_0000);
const P2: f64 = f64::from_bits(0x3DD0_B461_1A60_0000);
const P3: f64 = f64::from_bits(0x3BA3_198A_2E03_7073);
/// 1.5 · 2⁵²: adding it rounds a value below 2⁵¹ in magnitude to an integer
/// (to nearest, ties to even) whose low bits are then those of the result.
const ROUND: f64 = 6_755_399_441_055_744.0;
/// Beyond this the reduction's k · P1 is no longer exact: libm.
const LIMIT: f64 = 1e5;

/// Taylor coefficients of sin r / r − 1 in r² (−1/3!, 1/5!, …, 1/17!).
const SIN: [f64; 8] = [
    -1.0 / 6.0,
    1.0 / 120.0,
    -1.0 / 5040.0,
    1.0 / 362_880.0,
    -1.0 / 39_916_800.0,
    1.0 / 6_227_020_800.0,
    -1.0 / 1_307_674_368_000.0,
    1.0 / 355_687_428_096_000.0,
];
/// Taylor coefficients of cos r − 1 in r² (−1/2!, 1/4!, …, 1/16!).
const COS: [f64; 8] = [
    -0.5,
    1.0 / 24.0,
    -1.0 / 720.0,
    1.0 / 40_320.0,
    -1.0 / 3_628_800.0,
    1.0 / 479_001_600.0,
    -1.0 / 87_178_291_200.0,
    1.0 / 20_922_789_888_000.0,
];

/// o[i] = sin a[i].
pub fn sin_lanes(o: &mut [f64], a: &[f64]) {
    lanes(o, a, 0);
}

/// o[i] = cos a[i].
pub fn cos_lanes(o: &mut [f64], a: &[f64]) {
    lanes(o, a, 1);
}

/// s[i] = sin a[i] and c[i] = cos a[i] in one pass: both polynomials are
/// evaluated for every lane anyway, so a sine and a cosine of the same
/// argument (the gyroid's sin 6x and cos 6x) cost one reduction and one
/// pair of polynomials instead of two. The same operations as
/// [`sin_lanes`] and [`cos_lanes`], so the same bits.
pub fn sin_cos_lanes(s: &mut [f64], c: &mut [f64], a: &[f64]) {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has AVX2 (checked just above).
            unsafe { sin_cos_avx2(s, c, a) };
            return;
        }
    }
    sin_cos_generic(s, c, a);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn sin_cos_avx2(s: &mut [f64], c: &mut [f64], a: &[f64]) {
    sin_cos_generic(s, c, a);
}

#[inline(always)]
fn sin_cos_generic(s: &mut [f64], c: &mut [f64], a: &[f64]) {
    let mut far = false;
    for ((s, c), &x) in s.iter_mut().zip(c.iter_mut()).zip(a) {
        [*s, *c] = kernel_pair(x);
        far |= !reduced(x);
    }
    if far {
        for ((s, c), &x) in s.iter_mut().zip(c.iter_mut()).zip(a) {
            if !reduced(x) {
                (*s, *c) = (x.sin(), x.cos());
            }
        }
    }
}

/// `quarter` 0: sine, 1: cosine (cos x = sin(x + π/2): one quadrant on).
fn lanes(o: &mut [f64], a: &[f64], quarter: u64) {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has AVX2 (checked just above).
            unsafe { lanes_avx2(o, a, quarter) };
            return;
        }
    }
    lanes_generic(o, a, quarter);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn lanes_avx2(o: &mut [f64], a: &[f64], quarter: u64) {
    lanes_generic(o, a, quarter);
}

#[inline(always)]
fn lanes_generic(o: &mut [f64], a: &[f64], quarter: u64) {
    let mut far = false;
    for (o, &x) in o.iter_mut().zip(a) {
        *o = kernel(x, quarter);
        far |= !reduced(x);
    }
    if far {
        for (o, &x) in o.iter_mut().zip(a) {
            if !reduced(x) {
                *o = if quarter == 0 { x.sin() } else { x.cos() };
            }
        }
    }
}

/// Whether `kernel` serves x (false for NaN and ±∞ too).
#[inline(always)]
fn reduced(x: f64) -> bool {
    x.abs() <= LIMIT
}

/// sin(x + quarter · π/2) for |x| ≤ `LIMIT`.
#[inline(always)]
fn kernel(x: f64, quarter: u64) -> f64 {
    let (rounded, sin, cos) = reduced_polynomials(x);
    quadrant(rounded, quarter, sin, cos)
}

/// [sin x, cos x] for |x| ≤ `LIMIT`: `kernel` for both quarters, sharing
/// the reduction and the polynomials.
#[inline(always)]
fn kernel_pair(x: f64) -> [f64; 2] {
    let (rounded, sin, cos) = reduced_polynomials(x);
    [0, 1].map(|quarter| quadrant(rounded, quarter, sin, cos))
}

/// x reduced by π/2: (the rounding carrying k's low bits, sin r, cos r).
#[inline(always)]
fn reduced_polynomials(x: f64) -> (f64, f64, f64) {
    let rounded = x * FRAC_2_PI + ROUND;
    let k = rounded - ROUND;
    let r = ((x - k * P1) - k * P2) - k * P3;
    let r2 = r * r;
    let mut s = SIN[7];
    let mut c = COS[7];
    for i in (0..7).rev() {
        s = s * r2 + SIN[i];
        c = c * r2 + COS[i];
    }
    (rounded, r + r * r2 * s, 1.0 + r2 * c)
}

/// sin(x + quarter · π/2) from the reduction of x.
#[inline(always)]
fn quadrant(rounded: f64, quarter: u64, sin: f64, cos: f64) -> f64 {
    // k mod 4 from the low bits (two's complement, so negative k too).
    let q = rounded.to_bits().wrapping_add(quarter) & 3;
    let v = if q & 1 == 0 { sin } else { cos };
    // Quadrants 2 and 3 negate.
    f64::from_bits(v.to_bits() ^ ((q & 2) << 62))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// |a − b| in units of b's last place (b ≠ 0).
    fn ulps(a: f64, b: f64) -> f64 {
        (a - b).abs() / (b.abs() * f64::EPSILON).max(f64::MIN_POSITIVE)
    }

    #[test]
    fn lanes_agree_with_libm() {
        // Spread over ±200, the grid coordinates times 6 (M2's arguments),
        // points next to multiples of π/4 and π/2 (where the quadrant or
        // the polynomial changes), tiny values, and the fallbacks.
        let mut xs: Vec<f64> = (0..20_001).map(|i| (i as f64 - 10_000.0) * 0.02).collect();
        xs.extend((0..=256).map(|i| 6.0 * (-1.0 + 2.0 * (i as f64 / 256.0))));
        for k in -40..=40 {
            let m = k as f64 * std::f64::consts::FRAC_PI_4;
            for d in [-1e-9, -1e-15, 0.0, 1e-15, 1e-9] {
                xs.push(m + d);
            }
            xs.push(f64::from_bits(m.to_bits() + 1));
        }
        xs.extend([0.0, -0.0, 1e-300, -1e-30, 5e-8, 1e5, -1e5, 3e5, -7e8]);
        xs.extend([f64::NAN, f64::INFINITY, f64::NEG_INFINITY]);
        let (mut s, mut c) = (vec![0.0; xs.len()], vec![0.0; xs.len()]);
        sin_lanes(&mut s, &xs);
        cos_lanes(&mut c, &xs);
        let mut worst: f64 = 0.0;
        for (i, &x) in xs.iter().enumerate() {
            if !x.is_finite() {
                assert!(s[i].is_nan() && c[i].is_nan(), "{x}");
                continue;
            }
            for (got, want) in [(s[i], x.sin()), (c[i], x.cos())] {
                // Within 4 units in the last place of libm's value (near a
                // zero too: the reduction keeps r to 10⁻³⁷ · k absolute).
                assert!(
                    ulps(got, want) <= 4.0,
                    "x = {x:e}: {got:e} against libm's {want:e}"
                );
                if want.abs() > 1e-3 {
                    worst = worst.max(ulps(got, want));
                }
            }
        }
        assert!(worst <= 2.0, "worst {worst} ulps away from libm");
        // The same bits whatever the lane count (scalar tails, vector bodies).
        for len in [1, 3, 7, 128] {
            let mut part = vec![0.0; len];
            sin_lanes(&mut part, &xs[100..100 + len]);
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&part), bits(&s[100..100 + len]));
        }
        // Without AVX2 (the generic loop): the same bits.
        let mut g = vec![0.0; xs.len()];
        lanes_generic(&mut g, &xs, 0);
        let same = g
            .iter()
            .zip(&s)
            .all(|(a, b)| a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan()));
        assert!(same, "the AVX2 and generic loops differ");
        // Both at once: the bits of the separate passes, with and without AVX2.
        let (mut s2, mut c2) = (vec![0.0; xs.len()], vec![0.0; xs.len()]);
        sin_cos_lanes(&mut s2, &mut c2, &xs);
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!((bits(&s2), bits(&c2)), (bits(&s), bits(&c)));
        let (mut s3, mut c3) = (vec![0.0; xs.len()], vec![0.0; xs.len()]);
        sin_cos_generic(&mut s3, &mut c3, &xs);
        assert_eq!((bits(&s3), bits(&c3)), (bits(&s), bits(&c)));
    }
}
