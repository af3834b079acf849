//! Binning eight triangles at a time (AVX-512): their corner indices loaded
//! from the chunk and spread to lanes by three permutes, each corner's snapped
//! x and y gathered as one 8-byte load, then the signed area, the seen
//! side and the sample box in the lanes, and the triangles that reach the
//! picture compressed to the front of [`Kept`] for the pushes to the bands.
//! The scalar binning spends about 55 instructions a triangle on the same
//! (three bounds-checked corner lookups, branches on the area and the box),
//! half of them on back faces that need only the area.
//!
//! Every lane computes what [`super::facing`] and [`super::sample_box`]
//! compute, with the same integer operations, so the bins are the same.

use super::{SUB, Snapped};
use std::arch::x86_64::*;

/// Up to eight triangles of a group that reach the picture, in order: the
/// triangle, its corners, its seen side (1 the back) and its sample box.
#[derive(Default)]
pub(super) struct Kept {
    pub tri: [u32; 8],
    pub a: [u32; 8],
    pub b: [u32; 8],
    pub c: [u32; 8],
    pub back: [u32; 8],
    pub x0: [u32; 8],
    pub x1: [u32; 8],
    pub y0: [u32; 8],
    pub y1: [u32; 8],
}

/// Sets the first entries of `kept` to the triangles of `group` (numbered
/// from `first_id`, at most eight, corners in `nodes`) that face the eye
/// edge-on excluded, show a side `seen` lets through (when given: front,
/// back) and whose box holds a sample centre of the `width`×`height`
/// samples; returns their count.
///
/// # Safety
/// The processor has AVX-512 F, DQ and VL
/// ([`crate::render::triangle::lanes_available`]).
#[target_feature(enable = "avx512f,avx512dq,avx512vl")]
pub(super) unsafe fn group(
    group: &[[u32; 3]],
    first_id: u32,
    nodes: &[Snapped],
    (width, height): (usize, usize),
    seen: Option<[bool; 2]>,
    kept: &mut Kept,
) -> usize {
    assert!(group.len() <= 8, "a group of at most eight triangles");
    let n = group.len();
    let lanes = ((1u32 << n) - 1) as __mmask8;
    let set1 = |v: i64| _mm512_set1_epi64(v);
    let zero = _mm512_setzero_si512();
    // The group's 3n corner indices: dwords 0..16 and 16..24.
    let words = 3 * n;
    let (low, high) = (
        ((1u32 << words.min(16)) - 1) as __mmask16,
        ((1u32 << words.saturating_sub(16)) - 1) as __mmask16,
    );
    let at = group.as_ptr().cast::<i32>();
    // SAFETY: the masks cover exactly the group's 3n dwords.
    let (lo, hi) = unsafe {
        (
            _mm512_maskz_loadu_epi32(low, at),
            _mm512_maskz_loadu_epi32(high, at.wrapping_add(16)),
        )
    };
    let corner = |k: i32| {
        let pick = _mm512_setr_epi32(
            k,
            k + 3,
            k + 6,
            k + 9,
            k + 12,
            k + 15,
            k + 18,
            k + 21,
            0,
            0,
            0,
            0,
            0,
            0,
            0,
            0,
        );
        _mm512_castsi512_si256(_mm512_permutex2var_epi32(lo, pick, hi))
    };
    let (a, b, c) = (corner(0), corner(1), corner(2));
    let (na, nb, nc) = (
        _mm512_cvtepu32_epi64(a),
        _mm512_cvtepu32_epi64(b),
        _mm512_cvtepu32_epi64(c),
    );
    let limit = set1(nodes.len() as i64);
    assert!(
        (_mm512_mask_cmpge_epu64_mask(lanes, na, limit)
            | _mm512_mask_cmpge_epu64_mask(lanes, nb, limit)
            | _mm512_mask_cmpge_epu64_mask(lanes, nc, limit))
            == 0,
        "a corner beyond the mesh's nodes"
    );
    // A snapped node is x, y, z (4 bytes each): x and y are one 8-byte
    // load at 12 bytes × the node.
    let xy = |n: __m512i| {
        // SAFETY: every lane's node is in `nodes` (checked above).
        let v = unsafe {
            _mm512_mask_i64gather_epi64::<4>(
                zero,
                lanes,
                _mm512_mullo_epi64(n, set1(3)),
                nodes.as_ptr().cast(),
            )
        };
        (
            _mm512_srai_epi64::<32>(_mm512_slli_epi64::<32>(v)),
            _mm512_srai_epi64::<32>(v),
        )
    };
    let ((ax, ay), (bx, by), (cx, cy)) = (xy(na), xy(nb), xy(nc));
    // Differences of snapped coordinates fit 32 bits: the low halves' product.
    let area = _mm512_sub_epi64(
        _mm512_mul_epi32(_mm512_sub_epi64(bx, ax), _mm512_sub_epi64(cy, ay)),
        _mm512_mul_epi32(_mm512_sub_epi64(by, ay), _mm512_sub_epi64(cx, ax)),
    );
    let facing = _mm512_mask_cmpneq_epi64_mask(lanes, area, zero);
    let back = _mm512_cmpgt_epi64_mask(area, zero);
    let shown = match seen {
        Some([front, rear]) => {
            facing & ((if rear { back } else { 0 }) | (if front { !back } else { 0 }))
        }
        None => facing,
    };
    // As `sample_span`: div_euclid(16) is an arithmetic shift by 4.
    let span = |a: __m512i, b: __m512i, c: __m512i, size: usize| {
        let lo = _mm512_min_epi64(_mm512_min_epi64(a, b), c);
        let hi = _mm512_max_epi64(_mm512_max_epi64(a, b), c);
        (
            _mm512_max_epi64(
                _mm512_srai_epi64::<4>(_mm512_add_epi64(lo, set1(SUB / 2 - 1))),
                zero,
            ),
            _mm512_min_epi64(
                _mm512_srai_epi64::<4>(_mm512_sub_epi64(hi, set1(SUB / 2))),
                set1(size as i64 - 1),
            ),
        )
    };
    let (x0, x1) = span(ax, bx, cx, width);
    let (y0, y1) = span(ay, by, cy, height);
    let keep = _mm512_mask_cmple_epi64_mask(shown, x0, x1) & _mm512_cmple_epi64_mask(y0, y1);
    let store = |v: __m256i, to: &mut [u32; 8]| {
        // SAFETY: eight `u32` fit `to`.
        unsafe { _mm256_storeu_si256(to.as_mut_ptr().cast(), _mm256_maskz_compress_epi32(keep, v)) }
    };
    let ids = _mm256_add_epi32(
        _mm256_set1_epi32(first_id as i32),
        _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7),
    );
    store(ids, &mut kept.tri);
    store(a, &mut kept.a);
    store(b, &mut kept.b);
    store(c, &mut kept.c);
    store(_mm256_maskz_set1_epi32(back, 1), &mut kept.back);
    // Box bounds are in 0..size: they fit 32 bits.
    store(_mm512_cvtepi64_epi32(x0), &mut kept.x0);
    store(_mm512_cvtepi64_epi32(x1), &mut kept.x1);
    store(_mm512_cvtepi64_epi32(y0), &mut kept.y0);
    store(_mm512_cvtepi64_epi32(y1), &mut kept.y1);
    keep.count_ones() as usize
}
