//! Triangles drawn eight at a time (AVX-512): the set-up of eight
//! triangles in the lanes of vectors, then each one's sample loop eight
//! samples at a time. A triangle of a million-triangle mesh covers a few
//! samples of a box of about nine, so the scalar code spends its time in the
//! set-up (about 270 instructions a triangle, long dependent chains through
//! the depth plane's division) and in inside and nearer tests that
//! mispredict about every other sample; here the set-up is about 15 vector
//! instructions a triangle and a box row of up to eight samples is one pass
//! of straight-line code.
//!
//! Every lane computes what the scalar code computes, with the same integer
//! and IEEE operations in the same order (the plane in `f64` from the same
//! values, `zy + dzdx × x` in `f32`, then the larger of that and 0 as
//! `maxss` takes it), so the band gets the same bits.

use super::{BIAS, FIELD, OUTSIDE, SMALL, SUB, Snapped, set_up};
use std::arch::x86_64::*;

/// Whether this processor has the instructions of [`draw_ids`].
pub(super) fn available() -> bool {
    is_x86_feature_detected!("avx512f")
        && is_x86_feature_detected!("avx512dq")
        && is_x86_feature_detected!("avx512vl")
}

/// Up to eight small triangles set up, one entry per triangle: what the
/// sample loop reads.
#[derive(Default)]
struct Set {
    outside: [i64; 8],
    sx: [i64; 8],
    sy: [i64; 8],
    first: [i64; 8],
    id: [i64; 8],
    z_ref: [f32; 8],
    dzdx: [f32; 8],
    dzdy: [f32; 8],
    off_x: [i32; 8],
    off_y: [i32; 8],
    rows_n: [i32; 8],
    row_len: [i32; 8],
}

/// Draws triangles `ids` into rows `ys` of the z-buffer as
/// [`super::draw_chunks`] does.
///
/// # Safety
/// The processor has AVX-512 F, DQ and VL ([`available`]), `ys.start <=
/// ys.end` and `rows` holds at least `ys.len() × width` samples.
#[target_feature(enable = "avx512f,avx512dq,avx512vl")]
pub(super) unsafe fn draw_ids(
    rows: &mut [u64],
    width: usize,
    ys: &std::ops::Range<usize>,
    tris: &[[u32; 3]],
    nodes: &[Snapped],
    ids: &[u32],
) {
    let mut set = Set::default();
    for (g, group) in ids.chunks(8).enumerate() {
        // The triangles of the group after next and the corners of the
        // next one, so the dependent loads overlap (a hint reads nothing).
        for &far in ids.iter().skip(g * 8 + 16).take(8) {
            super::prefetch_at(tris.as_ptr().wrapping_add(far as usize));
        }
        for &near in ids.iter().skip(g * 8 + 8).take(8) {
            if let Some(near) = tris.get(near as usize) {
                for &c in near {
                    super::prefetch_at(nodes.as_ptr().wrapping_add(c as usize));
                }
            }
        }
        let lanes = ((1u32 << group.len()) - 1) as __mmask8;
        // SAFETY: the caller's promises, and the set-up's lanes index
        // `tris` and `nodes` only after checking them.
        let (small, wide) = unsafe { set_up_lanes(group, lanes, width, ys, tris, nodes, &mut set) };
        for (l, &tri) in group.iter().enumerate() {
            if wide & (1 << l) != 0 {
                // A large triangle: the scalar set-up draws it.
                let [a, b, c] = tris[tri as usize];
                let corners = [nodes[a as usize], nodes[b as usize], nodes[c as usize]];
                let mut unused = super::Small::default();
                // SAFETY: the caller's promise.
                unsafe { set_up(rows, width, ys, corners, tri, &mut unused) };
            }
        }
        // SAFETY: the set-up placed each small triangle's box in the band.
        unsafe { fill(&set, small, rows.as_mut_ptr(), width) };
    }
}

/// Sets up the triangles `group` (lanes `lanes`): the small ones that draw
/// something into the first entries of `set` (their count returned), and
/// the mask of the large ones.
#[target_feature(enable = "avx512f,avx512dq,avx512vl")]
unsafe fn set_up_lanes(
    group: &[u32],
    lanes: __mmask8,
    width: usize,
    ys: &std::ops::Range<usize>,
    tris: &[[u32; 3]],
    nodes: &[Snapped],
    set: &mut Set,
) -> (usize, __mmask8) {
    let zero = _mm512_setzero_si512();
    let set1 = |v: i64| _mm512_set1_epi64(v);
    // SAFETY: `lanes` covers exactly `group`'s entries.
    let tri =
        _mm512_cvtepu32_epi64(unsafe { _mm256_maskz_loadu_epi32(lanes, group.as_ptr().cast()) });
    assert!(
        _mm512_mask_cmpge_epu64_mask(lanes, tri, set1(tris.len() as i64)) == 0,
        "a triangle id beyond the mesh"
    );
    let at = _mm512_mullo_epi64(tri, set1(3));
    let corner = |k: i64| {
        // SAFETY: every lane's triangle is in `tris` (checked above).
        let n = unsafe {
            _mm512_mask_i64gather_epi32::<4>(
                _mm256_setzero_si256(),
                lanes,
                _mm512_add_epi64(at, set1(k)),
                tris.as_ptr().cast(),
            )
        };
        _mm512_cvtepu32_epi64(n)
    };
    let (na, nb, nc) = (corner(0), corner(1), corner(2));
    let limit = set1(nodes.len() as i64);
    assert!(
        (_mm512_mask_cmpge_epu64_mask(lanes, na, limit)
            | _mm512_mask_cmpge_epu64_mask(lanes, nb, limit)
            | _mm512_mask_cmpge_epu64_mask(lanes, nc, limit))
            == 0,
        "a corner beyond the mesh's nodes"
    );
    // Snapped nodes are three 4-byte fields: x, y, z.
    let field = |n: __m512i, k: i64| {
        // SAFETY: every lane's node is in `nodes` (checked above).
        unsafe {
            _mm512_mask_i64gather_epi32::<4>(
                _mm256_setzero_si256(),
                lanes,
                _mm512_add_epi64(_mm512_mullo_epi64(n, set1(3)), set1(k)),
                nodes.as_ptr().cast(),
            )
        }
    };
    // x and y as one 8-byte gather at 12 bytes × the node (six node
    // gathers per eight triangles instead of nine), split in the lanes.
    let xyz = |n: __m512i| {
        // SAFETY: every lane's node is in `nodes` (checked above).
        let xy = unsafe {
            _mm512_mask_i64gather_epi64::<4>(
                zero,
                lanes,
                _mm512_mullo_epi64(n, set1(3)),
                nodes.as_ptr().cast(),
            )
        };
        (
            _mm512_srai_epi64::<32>(_mm512_slli_epi64::<32>(xy)),
            _mm512_srai_epi64::<32>(xy),
            _mm256_castsi256_ps(field(n, 2)),
        )
    };
    let ((ax, ay, az), (bx, by, bz), (cx, cy, cz)) = (xyz(na), xyz(nb), xyz(nc));
    let (qx, qy) = (_mm512_sub_epi64(bx, ax), _mm512_sub_epi64(by, ay));
    let (rx, ry) = (_mm512_sub_epi64(cx, ax), _mm512_sub_epi64(cy, ay));
    // Differences of snapped coordinates fit 32 bits: the low halves' product.
    let signed = _mm512_sub_epi64(_mm512_mul_epi32(qx, ry), _mm512_mul_epi32(qy, rx));
    let facing = _mm512_mask_cmpneq_epi64_mask(lanes, signed, zero);
    let back = _mm512_cmpgt_epi64_mask(signed, zero);
    let (ux, uy) = (
        _mm512_mask_blend_epi64(back, rx, qx),
        _mm512_mask_blend_epi64(back, ry, qy),
    );
    let (wx, wy) = (
        _mm512_mask_blend_epi64(back, qx, rx),
        _mm512_mask_blend_epi64(back, qy, ry),
    );
    let (zb, zc) = (
        _mm256_mask_blend_ps(back, cz, bz),
        _mm256_mask_blend_ps(back, bz, cz),
    );
    let area = _mm512_abs_epi64(signed);
    let (lo_x, hi_x) = (
        _mm512_min_epi64(_mm512_min_epi64(zero, ux), wx),
        _mm512_max_epi64(_mm512_max_epi64(zero, ux), wx),
    );
    let (lo_y, hi_y) = (
        _mm512_min_epi64(_mm512_min_epi64(zero, uy), wy),
        _mm512_max_epi64(_mm512_max_epi64(zero, uy), wy),
    );
    let (y0, y1) = (ys.start as i64, ys.end as i64);
    // div_euclid(16) is an arithmetic shift by 4.
    let centre = |v: __m512i, add: i64| _mm512_srai_epi64::<4>(_mm512_add_epi64(v, set1(add)));
    let sx0 = centre(_mm512_add_epi64(ax, lo_x), SUB / 2 - 1);
    let sx1 = _mm512_min_epi64(
        centre(_mm512_add_epi64(ax, hi_x), -SUB / 2),
        set1(width as i64 - 1),
    );
    let sy0 = centre(_mm512_add_epi64(ay, lo_y), SUB / 2 - 1);
    let sy1 = _mm512_min_epi64(centre(_mm512_add_epi64(ay, hi_y), -SUB / 2), set1(y1 - 1));
    let (x_first, y_first) = (_mm512_max_epi64(sx0, zero), _mm512_max_epi64(sy0, set1(y0)));
    let drawn =
        _mm512_mask_cmple_epi64_mask(facing, x_first, sx1) & _mm512_cmple_epi64_mask(y_first, sy1);
    let small = _mm512_mask_cmplt_epi64_mask(drawn, _mm512_sub_epi64(hi_x, lo_x), set1(SMALL))
        & _mm512_cmplt_epi64_mask(_mm512_sub_epi64(hi_y, lo_y), set1(SMALL));
    let wide = drawn & !small;

    // The depth plane, as `Plane::new`.
    let f64s = |v: __m512i| _mm512_cvtepi64_pd(v);
    let inv = _mm512_div_pd(_mm512_set1_pd(1.0), f64s(area));
    let (x1, y1f, x2, y2) = (f64s(ux), f64s(uy), f64s(wx), f64s(wy));
    let (z1, z2) = (
        _mm512_cvtps_pd(_mm256_sub_ps(zb, az)),
        _mm512_cvtps_pd(_mm256_sub_ps(zc, az)),
    );
    let gx = _mm512_mul_pd(
        _mm512_sub_pd(_mm512_mul_pd(z1, y2), _mm512_mul_pd(z2, y1f)),
        inv,
    );
    let gy = _mm512_mul_pd(
        _mm512_sub_pd(_mm512_mul_pd(z2, x1), _mm512_mul_pd(z1, x2)),
        inv,
    );
    let corner_centre = |s: __m512i, a: __m512i| {
        _mm512_sub_epi64(
            _mm512_add_epi64(_mm512_slli_epi64::<4>(s), set1(SUB / 2)),
            a,
        )
    };
    let (r0, r1) = (corner_centre(sx0, ax), corner_centre(sy0, ay));
    let z_ref = _mm512_add_pd(
        _mm512_add_pd(_mm512_cvtps_pd(az), _mm512_mul_pd(gx, f64s(r0))),
        _mm512_mul_pd(gy, f64s(r1)),
    );
    let sub = _mm512_set1_pd(SUB as f64);
    let (dzdx, dzdy) = (_mm512_mul_pd(gx, sub), _mm512_mul_pd(gy, sub));

    // The edges, as the scalar set-up packs them.
    let (dx0, dy0) = (ux, uy);
    let (dx1, dy1) = (_mm512_sub_epi64(wx, ux), _mm512_sub_epi64(wy, uy));
    let (dx2, dy2) = (_mm512_sub_epi64(zero, wx), _mm512_sub_epi64(zero, wy));
    let (px, py) = (corner_centre(x_first, ax), corner_centre(y_first, ay));
    let pack = |a: __m512i, b: __m512i, c: __m512i| {
        _mm512_add_epi64(
            _mm512_add_epi64(a, _mm512_slli_epi64::<{ FIELD }>(b)),
            _mm512_slli_epi64::<{ 2 * FIELD }>(c),
        )
    };
    let not_owned = |dx: __m512i, dy: __m512i| {
        _mm512_add_epi64(
            set1(1),
            _mm512_srai_epi64::<63>(_mm512_sub_epi64(_mm512_slli_epi64::<32>(dy), dx)),
        )
    };
    let (dxs, dys) = (pack(dx0, dx1, dx2), pack(dy0, dy1, dy2));
    let owned = pack(
        not_owned(dx0, dy0),
        not_owned(dx1, dy1),
        not_owned(dx2, dy2),
    );
    let e = _mm512_add_epi64(
        _mm512_sub_epi64(_mm512_mullo_epi64(dxs, py), _mm512_mullo_epi64(dys, px)),
        _mm512_slli_epi64::<{ FIELD }>(area),
    );
    let outside = _mm512_sub_epi64(_mm512_add_epi64(set1(BIAS), owned), e);
    let id = _mm512_mask_add_epi64(
        _mm512_add_epi64(tri, tri),
        back,
        _mm512_add_epi64(tri, tri),
        set1(1),
    );
    let first = _mm512_add_epi64(
        _mm512_mullo_epi64(_mm512_sub_epi64(y_first, set1(y0)), set1(width as i64)),
        x_first,
    );

    // The small triangles' lanes, packed to the front of `set`.
    let keep = |v: __m512i, to: &mut [i64; 8]| {
        // SAFETY: eight `i64` fit `to`.
        unsafe {
            _mm512_storeu_si512(
                to.as_mut_ptr().cast(),
                _mm512_maskz_compress_epi64(small, v),
            )
        }
    };
    keep(outside, &mut set.outside);
    keep(_mm512_slli_epi64::<4>(dys), &mut set.sx);
    keep(
        _mm512_sub_epi64(zero, _mm512_slli_epi64::<4>(dxs)),
        &mut set.sy,
    );
    keep(first, &mut set.first);
    keep(id, &mut set.id);
    let keep_f32 = |v: __m512d, to: &mut [f32; 8]| {
        // SAFETY: eight `f32` fit `to`.
        unsafe {
            _mm256_storeu_ps(
                to.as_mut_ptr(),
                _mm256_maskz_compress_ps(small, _mm512_cvtpd_ps(v)),
            )
        }
    };
    keep_f32(z_ref, &mut set.z_ref);
    keep_f32(dzdx, &mut set.dzdx);
    keep_f32(dzdy, &mut set.dzdy);
    let keep_i32 = |v: __m512i, to: &mut [i32; 8]| {
        // SAFETY: eight `i32` fit `to`.
        unsafe {
            _mm256_storeu_si256(
                to.as_mut_ptr().cast(),
                _mm256_maskz_compress_epi32(small, _mm512_cvtepi64_epi32(v)),
            )
        }
    };
    keep_i32(_mm512_sub_epi64(x_first, sx0), &mut set.off_x);
    keep_i32(_mm512_sub_epi64(y_first, sy0), &mut set.off_y);
    keep_i32(_mm512_sub_epi64(sy1, y_first), &mut set.rows_n);
    keep_i32(_mm512_sub_epi64(sx1, x_first), &mut set.row_len);
    (small.count_ones() as usize, wide)
}

/// Fills the samples of the first `n` triangles of `set` as the scalar
/// sample loop does.
///
/// # Safety
/// Each triangle's box from `rows.add(first)` (rows `width` apart) lies in
/// the band.
#[target_feature(enable = "avx512f,avx512dq,avx512vl")]
unsafe fn fill(set: &Set, n: usize, rows: *mut u64, width: usize) {
    let lanes = _mm512_set_epi64(7, 6, 5, 4, 3, 2, 1, 0);
    let lanes32 = _mm256_set_epi32(7, 6, 5, 4, 3, 2, 1, 0);
    let outside = _mm512_set1_epi64(OUTSIDE);
    let zero = _mm256_setzero_ps();
    for t in 0..n.min(8) {
        let sx = set.sx[t];
        let mut row_edges = _mm512_add_epi64(
            _mm512_set1_epi64(set.outside[t]),
            _mm512_mullo_epi64(lanes, _mm512_set1_epi64(sx)),
        );
        let edges_step = _mm512_set1_epi64(sx.wrapping_mul(8));
        let row_step = _mm512_set1_epi64(set.sy[t]);
        let id = _mm512_set1_epi64(set.id[t]);
        let (z_ref, dzdx_1, dzdy) = (set.z_ref[t], set.dzdx[t], set.dzdy[t]);
        let dzdx = _mm256_set1_ps(dzdx_1);
        let x_first = _mm256_add_epi32(_mm256_set1_epi32(set.off_x[t]), lanes32);
        let (off_y, row_samples) = (i64::from(set.off_y[t]), set.row_len[t] as u32 + 1);
        // SAFETY: the caller's promise.
        let mut row = unsafe { rows.add(set.first[t] as usize) };
        for j in 0..=i64::from(set.rows_n[t]) {
            // As `Fill::row_depth`.
            let zy = _mm256_set1_ps(z_ref + dzdy * (j + off_y) as f32);
            let (mut edges, mut x, mut k) = (row_edges, x_first, 0);
            loop {
                let left = row_samples - k;
                let in_box = ((1u32 << left.min(8)) - 1) as __mmask8;
                let inside = _mm512_mask_testn_epi64_mask(in_box, edges, outside);
                let depth = _mm256_max_ps(
                    _mm256_add_ps(zy, _mm256_mul_ps(dzdx, _mm256_cvtepi32_ps(x))),
                    zero,
                );
                let bits = _mm512_cvtepu32_epi64(_mm256_castps_si256(depth));
                let value = _mm512_or_si512(_mm512_slli_epi64::<32>(bits), id);
                // SAFETY: lanes `inside` are samples of the box (the
                // caller's promise); the others are not touched.
                unsafe {
                    let at = row.add(k as usize).cast::<i64>();
                    let old = _mm512_maskz_loadu_epi64(inside, at);
                    let nearer = _mm512_mask_cmplt_epu64_mask(inside, value, old);
                    _mm512_mask_storeu_epi64(at, nearer, value);
                }
                if left <= 8 {
                    break;
                }
                k += 8;
                edges = _mm512_add_epi64(edges, edges_step);
                x = _mm256_add_epi32(x, _mm256_set1_epi32(8));
            }
            row = row.wrapping_add(width);
            row_edges = _mm512_add_epi64(row_edges, row_step);
        }
    }
}
