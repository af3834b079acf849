//! Inside/outside sign bits of a sampled grid, one bit per sample, one run
//! of 64-bit words per grid row (x fastest).
//!
//! Why: contouring a 256³ grid visits 17 M cells and 50 M edges, of which
//! only a few percent are crossed. With the signs packed, a whole row's
//! crossed x edges are `r ^ (r >> 1)`, its crossed y/z edges are `r ^ r'`
//! of the neighbouring row, and its cells with mixed corners come from the
//! AND and OR of four rows — 64 samples per instruction — so the contouring
//! loops only touch the samples next to the surface (the idea of VTK's
//! flying edges: find the crossings in one cheap pass, then work only there).

/// The sign bits: bit i of row (j, k) is set when sample (i, j, k) is inside
/// (value > 0; NaN and 0 count as outside, as in `polygonize`).
pub struct SignRows {
    /// Words per row.
    pub words: usize,
    n1: [usize; 3],
    bits: Vec<u64>,
}

impl SignRows {
    /// Packs the signs of `values` (x fastest, then y, then z).
    pub fn new(values: &[f32], n1: [usize; 3]) -> SignRows {
        use rayon::prelude::*;
        let words = n1[0].div_ceil(64);
        let mut bits = vec![0u64; words * n1[1] * n1[2]];
        bits.par_chunks_mut(words * n1[1])
            .zip(values.par_chunks(n1[0] * n1[1]))
            .for_each(|(plane_bits, plane)| {
                for (row_bits, row) in plane_bits.chunks_mut(words).zip(plane.chunks(n1[0])) {
                    for (w, chunk) in row_bits.iter_mut().zip(row.chunks(64)) {
                        *w = pack(chunk);
                    }
                }
            });
        SignRows { words, n1, bits }
    }

    /// The bits made row by row: `fill(j, k, words)` sets row (j, k)'s
    /// words (zeroed before; bits past the row must stay 0), rows of a z
    /// plane in order, planes in parallel.
    pub fn from_rows(n1: [usize; 3], fill: impl Fn(usize, usize, &mut [u64]) + Sync) -> SignRows {
        use rayon::prelude::*;
        let words = n1[0].div_ceil(64);
        let mut bits = vec![0u64; words * n1[1] * n1[2]];
        bits.par_chunks_mut(words * n1[1])
            .enumerate()
            .for_each(|(k, plane_bits)| {
                for (j, row_bits) in plane_bits.chunks_mut(words).enumerate() {
                    fill(j, k, row_bits);
                }
            });
        SignRows { words, n1, bits }
    }

    /// The words of row (j, k).
    pub fn row(&self, j: usize, k: usize) -> &[u64] {
        let start = (k * self.n1[1] + j) * self.words;
        &self.bits[start..start + self.words]
    }
}

/// Bit b: `chunk[b] > 0` (at most 64 values).
#[inline]
fn pack(chunk: &[f32]) -> u64 {
    #[cfg(target_arch = "x86_64")]
    if chunk.len() == 64 && std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: AVX2 is present (checked above) and the chunk holds 64 values.
        return unsafe { pack64_avx2(chunk) };
    }
    chunk
        .iter()
        .enumerate()
        .fold(0u64, |m, (b, &v)| m | (u64::from(v > 0.0) << b))
}

/// [`pack`] of 64 values, 8 per compare (ordered `>`: NaN and 0 give 0,
/// as in the scalar loop, so the bits are the same).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn pack64_avx2(chunk: &[f32]) -> u64 {
    use std::arch::x86_64::*;
    let zero = _mm256_setzero_ps();
    let mut m = 0u64;
    for (g, eight) in chunk.chunks_exact(8).enumerate() {
        // SAFETY: `eight` holds 8 f32 (unaligned load).
        let x = unsafe { _mm256_loadu_ps(eight.as_ptr()) };
        let gt = _mm256_cmp_ps::<_CMP_GT_OQ>(x, zero);
        m |= u64::from(_mm256_movemask_ps(gt) as u8) << (8 * g);
    }
    m
}

/// Word w of `r >> 1` over the whole row (bit i is bit i + 1 of the row).
#[inline]
pub fn shifted(r: &[u64], w: usize) -> u64 {
    let carry = r.get(w + 1).map_or(0, |&n| n << 63);
    (r[w] >> 1) | carry
}

/// The mask of the first `n` bits of word w.
#[inline]
pub fn low_bits(n: usize, w: usize) -> u64 {
    let start = w * 64;
    if n >= start + 64 {
        u64::MAX
    } else if n <= start {
        0
    } else {
        (1u64 << (n - start)) - 1
    }
}

/// The set bits of `mask` (word w) as sample indices, ascending.
#[inline]
pub fn bits(mask: u64, w: usize) -> impl Iterator<Item = usize> {
    let mut mask = mask;
    std::iter::from_fn(move || {
        if mask == 0 {
            return None;
        }
        let b = mask.trailing_zeros() as usize;
        mask &= mask - 1;
        Some(w * 64 + b)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_hold_the_signs_and_shifts_carry_across_words() {
        // 70 samples per row (two words), 2 rows, 1 plane.
        let n1 = [70, 2, 1];
        let values: Vec<f32> = (0..140)
            .map(|i| match i % 70 {
                3 | 63 | 64 | 69 => 1.0,
                5 => 0.0,
                6 => f32::NAN,
                _ => -1.0,
            })
            .collect();
        let s = SignRows::new(&values, n1);
        assert_eq!(s.words, 2);
        let r = s.row(1, 0);
        assert_eq!(r[0], (1 << 3) | (1 << 63));
        assert_eq!(r[1], 1 | (1 << 5));
        // Bit 62 of the shifted row is sample 63, bit 63 is sample 64.
        assert_eq!(shifted(r, 0), (1 << 2) | (1 << 62) | (1 << 63));
        assert_eq!(shifted(r, 1), 1 << 4);
        assert_eq!(low_bits(69, 0), u64::MAX);
        assert_eq!(low_bits(69, 1), (1 << 5) - 1);
        assert_eq!(low_bits(64, 1), 0);
        assert_eq!(bits(r[1], 1).collect::<Vec<_>>(), vec![64, 69]);
    }

    #[test]
    fn packing_64_at_once_matches_the_scalar_rule() {
        let specials = [
            0.0,
            -0.0,
            f32::NAN,
            f32::MIN_POSITIVE,
            -1.5,
            2.0,
            f32::INFINITY,
        ];
        let chunk: Vec<f32> = (0..64).map(|i| specials[(i * 5 + i / 7) % 7]).collect();
        let want = chunk
            .iter()
            .enumerate()
            .fold(0u64, |m, (b, &v)| m | (u64::from(v > 0.0) << b));
        assert_eq!(pack(&chunk), want);
        assert_ne!(want, 0);
    }
}
