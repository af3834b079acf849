//! Which samples of a small triangle's box (at most 4 × 4) are inside it,
//! as the bits `4·row + column` of one integer, found without a branch per
//! sample. Most triangles of a million-triangle mesh have a box of about
//! 3 × 3 holding three samples: the sample loop's inside test per box
//! sample mispredicts about every other time, and a triangle whose box
//! holds no inside sample needs no depth plane (the set-up's division).

use super::OUTSIDE;

/// Box rows and row samples the bits hold.
pub const SIDE: u32 = 4;

/// The bits of the box's first `rows_n + 1` rows of `row_len + 1` samples
/// (each below [`SIDE`]).
#[inline(always)]
pub fn in_box(rows_n: u32, row_len: u32) -> u32 {
    let row = (1 << (row_len + 1)) - 1;
    let rows = (1u32 << (SIDE * (rows_n + 1))) - 1;
    row * (0x1111 & rows)
}

/// The samples of a 4 × 4 block whose packed edges (see `super::BIAS`) are
/// `outside` at its first sample, stepping by `sx` per sample and `sy` per
/// row, with no outside bit set. Samples past the box may give any bit:
/// the caller keeps [`in_box`]'s.
#[inline(always)]
pub fn scalar(outside: i64, sx: i64, sy: i64) -> u32 {
    let mut bits = 0;
    let mut row = outside;
    for j in 0..SIDE {
        let mut f = row;
        for k in 0..SIDE {
            bits |= u32::from(f & OUTSIDE == 0) << (SIDE * j + k);
            f = f.wrapping_add(sx);
        }
        row = row.wrapping_add(sy);
    }
    bits
}

/// [`scalar`], a box row per AVX2 vector.
///
/// # Safety
/// The processor has AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
pub unsafe fn avx2(outside: i64, sx: i64, sy: i64) -> u32 {
    use std::arch::x86_64::*;
    let along = _mm256_set_epi64x(sx.wrapping_mul(3), sx.wrapping_mul(2), sx, 0);
    let first = _mm256_add_epi64(_mm256_set1_epi64x(outside), along);
    let step = _mm256_set1_epi64x(sy);
    let (out, zero) = (_mm256_set1_epi64x(OUTSIDE), _mm256_setzero_si256());
    // Lane k of a row: sample k, its sign bit set when no outside bit is.
    let row = |v: __m256i| {
        let inside = _mm256_cmpeq_epi64(_mm256_and_si256(v, out), zero);
        _mm256_movemask_pd(_mm256_castsi256_pd(inside)) as u32
    };
    let second = _mm256_add_epi64(first, step);
    let third = _mm256_add_epi64(second, step);
    let fourth = _mm256_add_epi64(third, step);
    row(first) | row(second) << SIDE | row(third) << (2 * SIDE) | row(fourth) << (3 * SIDE)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_rng::TestRng;

    #[test]
    fn box_bits_are_the_rows_and_samples_of_the_box() {
        assert_eq!(in_box(0, 0), 0b1);
        assert_eq!(in_box(0, 3), 0xf);
        assert_eq!(in_box(1, 2), 0b0111_0111);
        assert_eq!(in_box(3, 0), 0x1111);
        assert_eq!(in_box(3, 3), 0xffff);
    }

    #[test]
    fn scalar_bits_are_the_samples_without_an_outside_bit() {
        // One field's outside bit flips as its value steps across 2^20.
        let (sx, sy) = (-3 << 18, -5 << 17);
        let start = (1 << 20) + (1 << 19);
        let bits = scalar(start, sx, sy);
        for j in 0..4 {
            for k in 0..4 {
                let f = start + k * sx + j * sy;
                let expected = !(0..1 << 20).contains(&f);
                assert_eq!(bits >> (4 * j + k) & 1 == 0, expected, "sample ({k}, {j})");
            }
        }
        assert!(bits != 0 && bits != 0xffff, "{bits:#x}");
    }

    #[test]
    fn avx2_bits_are_the_scalar_bits() {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // Random packed edges and steps, every field's outside bit
            // both ways, and wrapping sums.
            let mut rng = TestRng::new(0x5851_f42d_4c95_7f2d);
            let field = |rng: &mut TestRng| rng.within(1 << 21);
            let (mut some, mut none) = (0, 0);
            for _ in 0..20_000 {
                let [o, x, y] = [0, 1, 2]
                    .map(|_| super::super::pack(field(&mut rng), field(&mut rng), field(&mut rng)));
                let wanted = scalar(o, x, y);
                // SAFETY: the processor has AVX2 (checked above).
                assert_eq!(unsafe { avx2(o, x, y) }, wanted, "{o:#x} {x:#x} {y:#x}");
                some += usize::from(wanted != 0);
                none += usize::from(wanted != 0xffff);
            }
            assert!(
                some > 100 && none > 100,
                "{some} with an inside sample, {none} not all"
            );
        }
    }
}
