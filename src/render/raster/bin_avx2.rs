//! Binning eight triangles at a time with AVX2: their corners loaded,
//! signed areas, seen sides and sample boxes computed in lanes, and only the
//! survivors listed one by one, in id order as the scalar loop lists them.
//! The back-facing half of a closed mesh and the boxes holding no sample
//! centre then cost a few vector instructions instead of unpredictable
//! branches. Every lane computes exactly what the scalar code does: the
//! areas as exact 64-bit products, the rounding of `sample_span` as shifts.

use super::{ChunkBins, Projected, Run, Snapped, Tris, bin_one};
use crate::render::triangle::SUB;
use std::arch::x86_64::*;

// `sample_span`'s `div_euclid(SUB)` is an arithmetic shift by this.
const SHIFT: i32 = SUB.trailing_zeros() as i32;
const _: () = assert!(SUB == 1 << SHIFT);

/// Corners within ±2^30 keep their differences in an `i32` lane (and the
/// scalar area's products in an `i64`); a group with a corner beyond goes
/// to the scalar code.
const REACH: i32 = 1 << 30;

/// Bins the whole groups of eight of `tris` (as [`super::bin_chunk`] does,
/// into `run` and `bins`) and returns how many triangles it binned; the
/// caller bins the rest. `same_visible`, when every face shows the same
/// sides, says which are `seen` (`seen` then only repeats it); otherwise a
/// triangle's side is asked of `seen`. A band has `band_rows` sample rows.
///
/// # Safety
/// The CPU must have AVX2.
#[target_feature(enable = "avx2")]
#[allow(clippy::too_many_arguments)]
pub(super) unsafe fn bin_groups(
    proj: &Projected,
    tris: Tris,
    width: usize,
    band_of: &[u32],
    bins: &mut ChunkBins,
    run: &mut Run,
    band_rows: usize,
    same_visible: Option<[bool; 2]>,
    seen: &impl Fn(usize, u32) -> bool,
) -> usize {
    let Some(last_node) = proj.snapped.len().checked_sub(1) else {
        return 0;
    };
    // Ids are `u32`s: all of them index more nodes than that.
    let last_node = _mm256_set1_epi32(last_node.min(u32::MAX as usize) as u32 as i32);
    let zero = _mm256_setzero_si256();
    let side = |s: bool| _mm256_set1_epi32(-i32::from(s));
    let may_see = same_visible.unwrap_or([true; 2]);
    let (see_back, see_front) = (side(may_see[1]), side(may_see[0]));
    // The run's band's rows (none before the first), for telling whether
    // a whole group's survivors join the run.
    let rows_of = |band: usize| {
        let lo = band.saturating_mul(band_rows).min(i32::MAX as usize);
        let hi = lo
            .saturating_add(band_rows.max(1) - 1)
            .min(i32::MAX as usize);
        (_mm256_set1_epi32(lo as i32), _mm256_set1_epi32(hi as i32))
    };
    let mut run_rows = rows_of(run.band);
    let last_col = _mm256_set1_epi32(width.min(i32::MAX as usize) as i32 - 1);
    let last_row = _mm256_set1_epi32(band_of.len().min(i32::MAX as usize) as i32 - 1);
    let (round_up, centre) = (
        _mm256_set1_epi32((SUB - 1 - SUB / 2) as i32),
        _mm256_set1_epi32((SUB / 2) as i32),
    );
    let groups = tris.corners.as_chunks::<8>().0;
    for (g, group) in groups.iter().enumerate() {
        let first = tris.first + 8 * g;
        // Ids past the nodes go to the scalar code, which panics on them.
        if !all_at_most(load_ids(group), last_node) {
            bin_scalar(proj, first, group, width, band_of, bins, run, seen);
            run_rows = rows_of(run.band);
            continue;
        }
        // SAFETY: every id is below `nodes` (checked above).
        let ([ax, bx, cx], [ay, by, cy]) = unsafe { load_xy(&proj.snapped, group) };
        let (min_x, max_x) = min_max(ax, bx, cx);
        let (min_y, max_y) = min_max(ay, by, cy);
        if !within_reach([min_x, max_x, min_y, max_y]) {
            bin_scalar(proj, first, group, width, band_of, bins, run, seen);
            run_rows = rows_of(run.band);
            continue;
        }
        let (front, back) = area_signs(
            _mm256_sub_epi32(bx, ax),
            _mm256_sub_epi32(cy, ay),
            _mm256_sub_epi32(by, ay),
            _mm256_sub_epi32(cx, ax),
        );
        // `facing` gives side 1 for a positive area.
        let shown = _mm256_or_si256(
            _mm256_and_si256(back, see_back),
            _mm256_and_si256(front, see_front),
        );
        // `sample_span`: the first centre at or after `lo`, the last at or
        // before `hi`, clamped to the picture.
        let first_centre = |lo| {
            _mm256_max_epi32(
                _mm256_srai_epi32::<SHIFT>(_mm256_add_epi32(lo, round_up)),
                zero,
            )
        };
        let last_centre = |hi, last| {
            _mm256_min_epi32(
                _mm256_srai_epi32::<SHIFT>(_mm256_sub_epi32(hi, centre)),
                last,
            )
        };
        let (x0, x1) = (first_centre(min_x), last_centre(max_x, last_col));
        let (y0, y1) = (first_centre(min_y), last_centre(max_y, last_row));
        let empty = _mm256_or_si256(_mm256_cmpgt_epi32(x0, x1), _mm256_cmpgt_epi32(y0, y1));
        let keep = _mm256_andnot_si256(empty, shown);
        let mut left = _mm256_movemask_ps(_mm256_castsi256_ps(keep)) as u32;
        if left == 0 {
            continue;
        }
        let outside = _mm256_or_si256(
            _mm256_cmpgt_epi32(run_rows.0, y0),
            _mm256_cmpgt_epi32(y1, run_rows.1),
        );
        if same_visible.is_some() && _mm256_testz_si256(outside, keep) == 1 {
            // Every survivor lies in the run's band alone: listed at once.
            join_run(run, first, left, keep, x0, x1);
            continue;
        }
        let backs = _mm256_movemask_ps(_mm256_castsi256_ps(back)) as u32;
        let lanes = [x0, x1, y0, y1].map(|v| {
            let mut out = [0i32; 8];
            // SAFETY: `out` holds eight `i32`s (an unaligned store).
            unsafe { _mm256_storeu_si256(out.as_mut_ptr().cast(), v) };
            out
        });
        while left != 0 {
            let k = left.trailing_zeros() as usize;
            left &= left - 1;
            let tri = first + k;
            if !seen(tri, (backs >> k) & 1) {
                continue;
            }
            // Non-negative and within the picture (clamped above).
            let span = lanes.map(|l| l[k] as usize);
            run.place(
                bins,
                band_of,
                tri as u32,
                (span[0], span[1], span[2], span[3]),
            );
        }
        run_rows = rows_of(run.band);
    }
    groups.len() * 8
}

/// Lists the lanes `kept` (mask `keep`, columns `x0..=x1`) of the group
/// from triangle `first` in the run's band: their ids packed to the front of
/// one store past the list's end, its columns widened to theirs.
#[target_feature(enable = "avx2")]
fn join_run(run: &mut Run, first: usize, kept: u32, keep: __m256i, x0: __m256i, x1: __m256i) {
    let lanes = _mm256_cvtepu8_epi32(_mm_cvtsi64_si128(PACKED[kept as usize] as i64));
    let ids = _mm256_add_epi32(lanes, _mm256_set1_epi32(first as u32 as i32));
    let len = run.ids.len();
    run.ids.reserve(8);
    // SAFETY: the list has room for eight more (reserved above); the first
    // `kept.count_ones()` stored are the ids, so initialised.
    unsafe {
        _mm256_storeu_si256(run.ids.as_mut_ptr().add(len).cast(), ids);
        run.ids.set_len(len + kept.count_ones() as usize);
    }
    // Lanes not kept take the identity of each reduction (columns are
    // non-negative).
    let from = lanes_min(_mm256_blendv_epi8(_mm256_set1_epi32(i32::MAX), x0, keep));
    let to = lanes_max(_mm256_and_si256(x1, keep));
    run.cols = super::widen(run.cols, (from as u32, to as u32));
}

/// For each 8-bit mask, the positions of its set bits, lowest first, one
/// to a byte.
const PACKED: [u64; 256] = {
    let mut table = [0u64; 256];
    let mut mask = 0;
    while mask < 256 {
        let (mut bit, mut at) = (0, 0);
        while bit < 8 {
            if mask >> bit & 1 == 1 {
                table[mask] |= (bit as u64) << (8 * at);
                at += 1;
            }
            bit += 1;
        }
        mask += 1;
    }
    table
};

#[target_feature(enable = "avx2")]
fn lanes_min(v: __m256i) -> i32 {
    let m = _mm_min_epi32(_mm256_castsi256_si128(v), _mm256_extracti128_si256::<1>(v));
    let m = _mm_min_epi32(m, _mm_shuffle_epi32::<0b01_00_11_10>(m));
    _mm_cvtsi128_si32(_mm_min_epi32(m, _mm_shuffle_epi32::<0b10_11_00_01>(m)))
}

#[target_feature(enable = "avx2")]
fn lanes_max(v: __m256i) -> i32 {
    let m = _mm_max_epi32(_mm256_castsi256_si128(v), _mm256_extracti128_si256::<1>(v));
    let m = _mm_max_epi32(m, _mm_shuffle_epi32::<0b01_00_11_10>(m));
    _mm_cvtsi128_si32(_mm_max_epi32(m, _mm_shuffle_epi32::<0b10_11_00_01>(m)))
}

/// Group `group`'s triangles by the scalar code.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn bin_scalar(
    proj: &Projected,
    first: usize,
    group: &[[u32; 3]; 8],
    width: usize,
    band_of: &[u32],
    bins: &mut ChunkBins,
    run: &mut Run,
    seen: &impl Fn(usize, u32) -> bool,
) {
    for (tri, &t) in (first..).zip(group) {
        bin_one(proj, tri, t, width, band_of, bins, run, seen);
    }
}

/// The 24 corner ids of eight triangles, in three loads of eight (in no
/// useful lane order: they are only checked).
#[target_feature(enable = "avx2")]
fn load_ids(group: &[[u32; 3]; 8]) -> [__m256i; 3] {
    let words = group.as_flattened();
    // SAFETY: `words` holds 24 `u32`s: three unaligned loads of eight.
    [0, 8, 16].map(|at| unsafe { _mm256_loadu_si256(words.as_ptr().add(at).cast()) })
}

/// The x and y of each corner of eight triangles, in triangle order: one
/// 8-byte load of (x, y) per corner (a gather of four is microcoded and
/// waited on), two triangles to a 128-bit half, the halves then split into
/// x and y lanes.
///
/// # Safety
/// Every corner id must index `nodes`.
#[target_feature(enable = "avx2")]
unsafe fn load_xy(nodes: &[Snapped], group: &[[u32; 3]; 8]) -> ([__m256i; 3], [__m256i; 3]) {
    let xy = [0, 1, 2].map(|k| {
        // SAFETY: the caller's ids index `nodes`, whose `repr(C)` nodes
        // start with x and y: 8 bytes read unaligned.
        let pair =
            |t: usize| unsafe { _mm_loadl_epi64(nodes.as_ptr().add(group[t][k] as usize).cast()) };
        let two = |t: usize| _mm_unpacklo_epi64(pair(t), pair(t + 1));
        // Low holds triangles 0 1 | 4 5, high 2 3 | 6 7, as (x, y) pairs.
        let low = _mm256_set_m128i(two(4), two(0));
        let high = _mm256_set_m128i(two(6), two(2));
        let (low, high) = (_mm256_castsi256_ps(low), _mm256_castsi256_ps(high));
        (
            _mm256_castps_si256(_mm256_shuffle_ps::<0b10_00_10_00>(low, high)),
            _mm256_castps_si256(_mm256_shuffle_ps::<0b11_01_11_01>(low, high)),
        )
    });
    (xy.map(|p| p.0), xy.map(|p| p.1))
}

/// Whether every lane of `ids` is at most `last` (unsigned).
#[target_feature(enable = "avx2")]
fn all_at_most(ids: [__m256i; 3], last: __m256i) -> bool {
    let top = ids.into_iter().fold(last, |m, v| _mm256_max_epu32(m, v));
    _mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(top, last))) == 0xff
}

/// Whether every lane of `bounds` lies in `-REACH..REACH`.
#[target_feature(enable = "avx2")]
fn within_reach(bounds: [__m256i; 4]) -> bool {
    let (lo, hi) = (_mm256_set1_epi32(-REACH), _mm256_set1_epi32(REACH - 1));
    let beyond = bounds.into_iter().fold(_mm256_setzero_si256(), |out, v| {
        let v_out = _mm256_or_si256(_mm256_cmpgt_epi32(lo, v), _mm256_cmpgt_epi32(v, hi));
        _mm256_or_si256(out, v_out)
    });
    _mm256_testz_si256(beyond, beyond) == 1
}

#[target_feature(enable = "avx2")]
fn min_max(a: __m256i, b: __m256i, c: __m256i) -> (__m256i, __m256i) {
    (
        _mm256_min_epi32(_mm256_min_epi32(a, b), c),
        _mm256_max_epi32(_mm256_max_epi32(a, b), c),
    )
}

/// Masks of the lanes whose area `d1x·d2y − d1y·d2x` is negative (front)
/// and positive (back), from 32-bit differences: exact 64-bit products of
/// the even lanes, then of the odd ones shifted down.
#[target_feature(enable = "avx2")]
fn area_signs(d1x: __m256i, d2y: __m256i, d1y: __m256i, d2x: __m256i) -> (__m256i, __m256i) {
    let area = |p: __m256i, q: __m256i, r: __m256i, s: __m256i| {
        _mm256_sub_epi64(_mm256_mul_epi32(p, q), _mm256_mul_epi32(r, s))
    };
    let odd = |v: __m256i| _mm256_srli_epi64::<32>(v);
    let even_area = area(d1x, d2y, d1y, d2x);
    let odd_area = area(odd(d1x), odd(d2y), odd(d1y), odd(d2x));
    let zero = _mm256_setzero_si256();
    // A 64-bit mask covers both 32-bit lanes: the even lane from the even
    // areas, the odd from the odd.
    let join = |even: __m256i, odd: __m256i| _mm256_blend_epi32::<0b1010_1010>(even, odd);
    (
        join(
            _mm256_cmpgt_epi64(zero, even_area),
            _mm256_cmpgt_epi64(zero, odd_area),
        ),
        join(
            _mm256_cmpgt_epi64(even_area, zero),
            _mm256_cmpgt_epi64(odd_area, zero),
        ),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lanes(v: __m256i) -> [i32; 8] {
        // SAFETY: `__m256i` and `[i32; 8]` are 32 plain bytes alike.
        unsafe { std::mem::transmute(v) }
    }

    fn from_lanes(v: [i32; 8]) -> __m256i {
        // SAFETY: as in `lanes`.
        unsafe { std::mem::transmute(v) }
    }

    #[test]
    fn lanes_take_corners_in_triangle_order_and_check_their_bounds() {
        if !std::arch::is_x86_feature_detected!("avx2") {
            return;
        }
        // Triangle t's corners are nodes 10t, 10t + 1, 10t + 2, node n at
        // x = n, y = -3n.
        let group: [[u32; 3]; 8] = std::array::from_fn(|t| [0, 1, 2].map(|k| 10 * t as u32 + k));
        let nodes: Vec<Snapped> = (0..80)
            .map(|n| Snapped {
                x: n,
                y: -3 * n,
                z: 0.25,
            })
            .collect();
        // SAFETY: the CPU has AVX2 (checked above); every id is below 80.
        let (ids, (xs, ys)) = unsafe { (load_ids(&group), load_xy(&nodes, &group)) };
        for k in 0..3 {
            let want = |scale: i32| std::array::from_fn(|t| scale * (10 * t as i32 + k as i32));
            assert_eq!(lanes(xs[k]), want(1));
            assert_eq!(lanes(ys[k]), want(-3));
            let id = |w: usize| (10 * (w / 3) + w % 3) as i32;
            assert_eq!(lanes(ids[k]), std::array::from_fn(|l| id(8 * k + l)));
        }
        let at_most = |ids, last| {
            // SAFETY: the CPU has AVX2 (checked above).
            unsafe { all_at_most(ids, _mm256_set1_epi32(last)) }
        };
        assert!(at_most(ids, 72));
        assert!(!at_most(ids, 71));
        let mut high = lanes(ids[1]);
        high[5] = -1;
        assert!(!at_most([ids[0], from_lanes(high), ids[2]], 72));
        let reach = |v: i32| {
            let bounds = [0, 1, 2, 3].map(|k| {
                from_lanes(std::array::from_fn(
                    |l| if l == 2 * k { v } else { k as i32 },
                ))
            });
            // SAFETY: the CPU has AVX2 (checked above).
            unsafe { within_reach(bounds) }
        };
        assert!(reach(REACH - 1) && reach(-REACH));
        assert!(!reach(REACH) && !reach(-REACH - 1) && !reach(i32::MAX));
    }

    #[test]
    fn area_signs_are_exact_at_the_lanes_reach() {
        if !std::arch::is_x86_feature_detected!("avx2") {
            return;
        }
        // Differences up to 2^31 − 1: products near 2^62 differing by one.
        let big = i32::MAX;
        let d1x = [big, big, -big, 3, 0, big, 1, -7];
        let d2y = [big, big, big, 5, 9, 1, 1, 2];
        let d1y = [big - 1, big, big, 5, 1, 1, 0, 1];
        let d2x = [big, big, -big, 3, 4, big, 0, -14];
        // SAFETY: the CPU has AVX2 (checked above).
        let (front, back) = unsafe {
            area_signs(
                from_lanes(d1x),
                from_lanes(d2y),
                from_lanes(d1y),
                from_lanes(d2x),
            )
        };
        let expected = |sign: i64| {
            std::array::from_fn(|l| {
                let area =
                    i64::from(d1x[l]) * i64::from(d2y[l]) - i64::from(d1y[l]) * i64::from(d2x[l]);
                -i32::from(area.signum() == sign)
            })
        };
        assert_eq!(lanes(front), expected(-1));
        assert_eq!(lanes(back), expected(1));
        assert_eq!(lanes(back)[0], -1, "big² − (big − 1)·big = big > 0");
    }
}
