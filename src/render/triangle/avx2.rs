//! Triangles set up eight at a time with AVX2 (for processors without
//! AVX-512): the corners fetched by eight-lane gathers, then the set-up in
//! two halves of four `i64`/`f64` lanes, then each small triangle's scalar
//! sample loop. The scalar set-up is most of the drawing (long dependent
//! chains through the depth plane's division); here a division serves four
//! triangles and the orientation, box, clamp and packed edges are a few
//! vector instructions each.
//!
//! Every lane computes what the scalar code computes, with the same integer
//! and IEEE operations in the same order, so the band gets the same bits.
//! AVX2 lacks some of them, built here exactly: the `i64` products of
//! values that fit 32 bits (`vpmuldq`), `i64` minimum and maximum (compare
//! and blend), the arithmetic shift (`div_euclid(16)`) and the `i64` to
//! `f64` conversion of a small triangle's values (below 2^51: the
//! magic-number addition).

use super::lanes::Set;
use super::{BIAS, FIELD, Fill, Plane, SMALL, SUB, Small, Snapped, prefetch_at, set_up};
use std::arch::x86_64::*;

/// Whether this processor has the instructions of [`draw_ids`] and the
/// mesh and picture fit its 32-bit gather indices and products.
pub(super) fn available(tris: usize, nodes: usize, width: usize) -> bool {
    is_x86_feature_detected!("avx2") && fits(tris, nodes, width)
}

/// Whether three times the triangles and nodes (the gathers' 32-bit
/// element indices) and the width (a 32-bit product) are below 2^31.
fn fits(tris: usize, nodes: usize, width: usize) -> bool {
    let limit = 1 << 31;
    tris.saturating_mul(3) < limit && nodes.saturating_mul(3) < limit && width < limit
}

/// Draws triangles `ids` into rows `ys` of the z-buffer as
/// [`super::draw_chunks`] does.
///
/// # Safety
/// [`available`]`(tris.len(), nodes.len(), width)`, `ys.start <= ys.end`
/// and `rows` holds at least `ys.len() × width` samples.
#[target_feature(enable = "avx2")]
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
            prefetch_at(tris.as_ptr().wrapping_add(far as usize));
        }
        for &near in ids.iter().skip(g * 8 + 8).take(8) {
            if let Some(near) = tris.get(near as usize) {
                for &c in near {
                    prefetch_at(nodes.as_ptr().wrapping_add(c as usize));
                }
            }
        }
        // SAFETY: the caller's promises; the set-up gathers from `tris`
        // and `nodes` only after checking the indices.
        let (small, wide) = unsafe { set_up_lanes(group, width, ys, tris, nodes, &mut set) };
        for (l, &tri) in group.iter().enumerate() {
            if wide & (1 << l) != 0 {
                // A large triangle: the scalar set-up draws it.
                let [a, b, c] = tris[tri as usize];
                let corners = [nodes[a as usize], nodes[b as usize], nodes[c as usize]];
                let mut unused = Small::default();
                // SAFETY: the caller's promise.
                unsafe { set_up(rows, width, ys, corners, tri, &mut unused) };
            }
        }
        let mut left = small;
        while left != 0 {
            let t = left.trailing_zeros() as usize;
            left &= left - 1;
            // SAFETY: the set-up placed each small triangle's box in the
            // band.
            unsafe { set.small(t).fill(rows.as_mut_ptr(), width) };
        }
    }
}

/// The ids of `group` (1 to 8) in eight lanes, the missing ones repeating
/// the first.
#[inline(always)]
fn eight(group: &[u32]) -> [u32; 8] {
    let mut ids = [group[0]; 8];
    ids[..group.len()].copy_from_slice(group);
    ids
}

/// Sets up the triangles `group` (at most eight): each small triangle that
/// draws something into its lane of `set`; the masks of those lanes and of
/// the large triangles that draw something.
///
/// # Safety
/// [`available`]`(tris.len(), nodes.len(), width)`.
#[target_feature(enable = "avx2")]
unsafe fn set_up_lanes(
    group: &[u32],
    width: usize,
    ys: &std::ops::Range<usize>,
    tris: &[[u32; 3]],
    nodes: &[Snapped],
    set: &mut Set,
) -> (u32, u32) {
    let lanes = (1u32 << group.len()) - 1;
    let ids = eight(group);
    // SAFETY: eight `u32` are 32 bytes.
    let tri = unsafe { _mm256_loadu_si256(ids.as_ptr().cast()) };
    let below = |v: __m256i, len: usize| {
        // Unsigned v < len (len < 2^31): max(v, len) is len.
        let len = _mm256_set1_epi32(len as i32);
        _mm256_movemask_epi8(_mm256_cmpeq_epi32(_mm256_max_epu32(v, len), len)) == -1
    };
    assert!(below(tri, tris.len()), "a triangle id beyond the mesh");
    let times3 = |v: __m256i| _mm256_add_epi32(v, _mm256_add_epi32(v, v));
    let at = times3(tri);
    let gather = |base: *const i32, at: __m256i, k: i32| {
        // SAFETY: the callers check every lane's index: element `3 × index
        // + k` (k < 3) of a slice of 3-element records, under 2^31.
        unsafe { _mm256_i32gather_epi32::<4>(base, _mm256_add_epi32(at, _mm256_set1_epi32(k))) }
    };
    let corner = |k: i32| gather(tris.as_ptr().cast(), at, k);
    let (na, nb, nc) = (corner(0), corner(1), corner(2));
    assert!(
        below(na, nodes.len()) && below(nb, nodes.len()) && below(nc, nodes.len()),
        "a corner beyond the mesh's nodes"
    );
    // Snapped nodes are three 4-byte fields: x, y, z.
    let xyz = |n: __m256i| {
        let at = times3(n);
        let base = nodes.as_ptr().cast();
        (
            gather(base, at, 0),
            gather(base, at, 1),
            gather(base, at, 2),
        )
    };
    let corners = [xyz(na), xyz(nb), xyz(nc)];
    let mut small = 0;
    let mut wide = 0;
    for half in 0..2 {
        let part = |v: __m256i| {
            if half == 0 {
                _mm256_castsi256_si128(v)
            } else {
                _mm256_extracti128_si256::<1>(v)
            }
        };
        let corners = corners.map(|(x, y, z)| {
            (
                _mm256_cvtepi32_epi64(part(x)),
                _mm256_cvtepi32_epi64(part(y)),
                _mm_castsi128_ps(part(z)),
            )
        });
        let (s, w) = set_up_half(
            _mm256_cvtepu32_epi64(part(tri)),
            corners,
            width,
            ys,
            set,
            4 * half,
        );
        let in_group = (lanes >> (4 * half)) & 0xf;
        small |= (s & in_group) << (4 * half);
        wide |= (w & in_group) << (4 * half);
    }
    (small, wide)
}

/// All ones in the `i64` lanes where `a > b` (AVX2 compares `i64` only
/// by `>` and `==`).
#[target_feature(enable = "avx2")]
#[inline]
fn gt(a: __m256i, b: __m256i) -> __m256i {
    _mm256_cmpgt_epi64(a, b)
}

/// Lanes of `a` where `mask` is all ones, else of `b`.
#[target_feature(enable = "avx2")]
#[inline]
fn pick(mask: __m256i, a: __m256i, b: __m256i) -> __m256i {
    _mm256_blendv_epi8(b, a, mask)
}

/// `v.div_euclid(16)` per `i64` lane: an arithmetic shift right by 4,
/// which AVX2 has only for 32-bit lanes (a logical shift, the sign's
/// ones shifted in).
#[target_feature(enable = "avx2")]
#[inline]
fn div16(v: __m256i) -> __m256i {
    let sign = gt(_mm256_setzero_si256(), v);
    _mm256_or_si256(_mm256_srli_epi64::<4>(v), _mm256_slli_epi64::<60>(sign))
}

/// `i64` lanes to `f64`, exactly for values in `-2^51..2^51`: added to the
/// bits of 1.5 × 2^52 they are the bits of 1.5 × 2^52 + v (one unit in the
/// last place per integer there), from which 1.5 × 2^52 is subtracted
/// exactly.
#[target_feature(enable = "avx2")]
#[inline]
fn to_f64(v: __m256i) -> __m256d {
    // 1.5 × 2^52.
    let magic = _mm256_set1_pd(6_755_399_441_055_744.0);
    _mm256_sub_pd(
        _mm256_castsi256_pd(_mm256_add_epi64(v, _mm256_castpd_si256(magic))),
        magic,
    )
}

/// The low 32 bits of each `i64` lane, as four `i32`.
#[target_feature(enable = "avx2")]
#[inline]
fn low_halves(v: __m256i) -> __m128i {
    _mm256_castsi256_si128(_mm256_permutevar8x32_epi32(
        v,
        _mm256_setr_epi32(0, 2, 4, 6, 0, 0, 0, 0),
    ))
}

/// Sets up four triangles `tri` with corners `t` (x, y as `i64`, z) into
/// lanes `at..at + 4` of `set`, as the scalar `set_up`: the masks (bit per
/// lane) of the small ones that draw something and of the large ones that
/// do. A lane's entries are only meaningful where it is small.
#[target_feature(enable = "avx2")]
#[inline]
fn set_up_half(
    tri: __m256i,
    t: [(__m256i, __m256i, __m128); 3],
    width: usize,
    ys: &std::ops::Range<usize>,
    set: &mut Set,
    at: usize,
) -> (u32, u32) {
    let zero = _mm256_setzero_si256();
    let set1 = |v: i64| _mm256_set1_epi64x(v);
    let add = |a, b| _mm256_add_epi64(a, b);
    let sub = |a, b| _mm256_sub_epi64(a, b);
    let min = |a, b| pick(gt(a, b), b, a);
    let max = |a, b| pick(gt(a, b), a, b);
    let [(ax, ay, az), (bx, by, bz), (cx, cy, cz)] = t;
    let (qx, qy) = (sub(bx, ax), sub(by, ay));
    let (rx, ry) = (sub(cx, ax), sub(cy, ay));
    // Differences of snapped coordinates fit 32 bits: the low halves' product.
    let signed = sub(_mm256_mul_epi32(qx, ry), _mm256_mul_epi32(qy, rx));
    let edge_on = _mm256_cmpeq_epi64(signed, zero);
    let back = gt(signed, zero);
    let (ux, uy) = (pick(back, qx, rx), pick(back, qy, ry));
    let (wx, wy) = (pick(back, rx, qx), pick(back, ry, qy));
    let area = pick(back, signed, sub(zero, signed));
    let (lo_x, hi_x) = (min(min(zero, ux), wx), max(max(zero, ux), wx));
    let (lo_y, hi_y) = (min(min(zero, uy), wy), max(max(zero, uy), wy));
    let (y0, y1) = (ys.start as i64, ys.end as i64);
    let centre = |v: __m256i, by: i64| div16(add(v, set1(by)));
    let sx0 = centre(add(ax, lo_x), SUB / 2 - 1);
    let sx1 = min(centre(add(ax, hi_x), -SUB / 2), set1(width as i64 - 1));
    let sy0 = centre(add(ay, lo_y), SUB / 2 - 1);
    let sy1 = min(centre(add(ay, hi_y), -SUB / 2), set1(y1 - 1));
    let (x_first, y_first) = (max(sx0, zero), max(sy0, set1(y0)));
    let empty = _mm256_or_si256(_mm256_or_si256(edge_on, gt(x_first, sx1)), gt(y_first, sy1));
    let large = _mm256_or_si256(
        gt(sub(hi_x, lo_x), set1(SMALL - 1)),
        gt(sub(hi_y, lo_y), set1(SMALL - 1)),
    );
    let drawn = !_mm256_movemask_pd(_mm256_castsi256_pd(empty)) as u32 & 0xf;
    let large = _mm256_movemask_pd(_mm256_castsi256_pd(large)) as u32;

    // The depth plane, as `Plane::new` (a small triangle's values are far
    // below 2^51).
    let inv = _mm256_div_pd(_mm256_set1_pd(1.0), to_f64(area));
    let (x1, y1f, x2, y2) = (to_f64(ux), to_f64(uy), to_f64(wx), to_f64(wy));
    // z1 is zb − a.z, zb the corner b or c as the orientation orders them.
    let (db, dc) = (
        _mm256_cvtps_pd(_mm_sub_ps(bz, az)),
        _mm256_cvtps_pd(_mm_sub_ps(cz, az)),
    );
    let back_pd = _mm256_castsi256_pd(back);
    let (z1, z2) = (
        _mm256_blendv_pd(dc, db, back_pd),
        _mm256_blendv_pd(db, dc, back_pd),
    );
    let gx = _mm256_mul_pd(
        _mm256_sub_pd(_mm256_mul_pd(z1, y2), _mm256_mul_pd(z2, y1f)),
        inv,
    );
    let gy = _mm256_mul_pd(
        _mm256_sub_pd(_mm256_mul_pd(z2, x1), _mm256_mul_pd(z1, x2)),
        inv,
    );
    let corner_centre =
        |s: __m256i, a: __m256i| sub(add(_mm256_slli_epi64::<4>(s), set1(SUB / 2)), a);
    let (r0, r1) = (corner_centre(sx0, ax), corner_centre(sy0, ay));
    let z_ref = _mm256_add_pd(
        _mm256_add_pd(_mm256_cvtps_pd(az), _mm256_mul_pd(gx, to_f64(r0))),
        _mm256_mul_pd(gy, to_f64(r1)),
    );
    let sub_pd = _mm256_set1_pd(SUB as f64);
    let (dzdx, dzdy) = (_mm256_mul_pd(gx, sub_pd), _mm256_mul_pd(gy, sub_pd));

    // The edges, as the scalar set-up packs them. The packing is linear
    // modulo 2^64, so the packed edge value at (px, py) is the packing of
    // the three edge values, each a product of values that fit 32 bits.
    let (dx0, dy0) = (ux, uy);
    let (dx1, dy1) = (sub(wx, ux), sub(wy, uy));
    let (dx2, dy2) = (sub(zero, wx), sub(zero, wy));
    let (px, py) = (corner_centre(x_first, ax), corner_centre(y_first, ay));
    let pack = |a, b, c| {
        add(
            add(a, _mm256_slli_epi64::<{ FIELD as i32 }>(b)),
            _mm256_slli_epi64::<{ 2 * FIELD as i32 }>(c),
        )
    };
    // 1 + (dy·2^32 − dx) >> 63: 1 less the sign bit.
    let not_owned = |dx, dy| {
        sub(
            set1(1),
            _mm256_srli_epi64::<63>(sub(_mm256_slli_epi64::<32>(dy), dx)),
        )
    };
    let edge = |dx, dy| sub(_mm256_mul_epi32(dx, py), _mm256_mul_epi32(dy, px));
    let (dxs, dys) = (pack(dx0, dx1, dx2), pack(dy0, dy1, dy2));
    let owned = pack(
        not_owned(dx0, dy0),
        not_owned(dx1, dy1),
        not_owned(dx2, dy2),
    );
    let e = pack(edge(dx0, dy0), add(edge(dx1, dy1), area), edge(dx2, dy2));
    let outside = sub(add(set1(BIAS), owned), e);
    // 2 × triangle + back side (the mask is −1 there).
    let id = sub(add(tri, tri), back);
    // (y_first − y0) × width: both under 2^32 where the box is drawn.
    let first = add(
        _mm256_mul_epu32(sub(y_first, set1(y0)), set1(width as i64)),
        x_first,
    );

    // SAFETY (every store below): `at` is 0 or 4, so four entries from
    // `at` lie in the eight of each array.
    let keep = |v: __m256i, to: &mut [i64; 8]| unsafe {
        _mm256_storeu_si256(to[at..].as_mut_ptr().cast(), v)
    };
    keep(outside, &mut set.outside);
    keep(_mm256_slli_epi64::<4>(dys), &mut set.sx);
    keep(sub(zero, _mm256_slli_epi64::<4>(dxs)), &mut set.sy);
    keep(first, &mut set.first);
    keep(id, &mut set.id);
    let keep_f32 = |v: __m256d, to: &mut [f32; 8]| unsafe {
        _mm_storeu_ps(to[at..].as_mut_ptr(), _mm256_cvtpd_ps(v))
    };
    keep_f32(z_ref, &mut set.z_ref);
    keep_f32(dzdx, &mut set.dzdx);
    keep_f32(dzdy, &mut set.dzdy);
    let keep_i32 = |v: __m256i, to: &mut [i32; 8]| unsafe {
        _mm_storeu_si128(to[at..].as_mut_ptr().cast(), low_halves(v))
    };
    keep_i32(sub(x_first, sx0), &mut set.off_x);
    keep_i32(sub(y_first, sy0), &mut set.off_y);
    keep_i32(sub(sy1, y_first), &mut set.rows_n);
    keep_i32(sub(sx1, x_first), &mut set.row_len);
    (drawn & !large, drawn & large)
}

impl Set {
    /// Lane `t`'s triangle as the scalar sample loop takes it.
    fn small(&self, t: usize) -> Small {
        Small {
            outside: self.outside[t],
            sx: self.sx[t],
            sy: self.sy[t],
            first: self.first[t] as usize,
            fill: Fill {
                id: self.id[t] as u64,
                plane: Plane {
                    z_ref: self.z_ref[t],
                    dzdx: self.dzdx[t],
                    dzdy: self.dzdy[t],
                    off_x: self.off_x[t],
                    off_y: self.off_y[t],
                },
                rows_n: self.rows_n[t] as u32,
                row_len: self.row_len[t] as u32,
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_rng::TestRng;

    #[test]
    fn small_integers_convert_to_f64_exactly() {
        if !is_x86_feature_detected!("avx2") {
            return;
        }
        let mut rng = TestRng::new(0x51_7cc1_b727_220a);
        let mut values: Vec<i64> = vec![0, 1, -1, (1 << 51) - 1, -(1 << 51), 1 << 40, -12345];
        values.extend((0..400).map(|k| rng.within((1 << (k % 52)) - 1)));
        for four in values.chunks_exact(4) {
            // SAFETY: the processor has AVX2 (checked above).
            let got: [f64; 4] =
                unsafe { std::mem::transmute(to_f64(_mm256_loadu_si256(four.as_ptr().cast()))) };
            let want = [0, 1, 2, 3].map(|k| four[k] as f64);
            assert_eq!(got.map(f64::to_bits), want.map(f64::to_bits), "{four:?}");
        }
    }

    #[test]
    fn division_by_16_rounds_down_as_div_euclid() {
        if !is_x86_feature_detected!("avx2") {
            return;
        }
        let values = [
            0,
            15,
            16,
            17,
            -1,
            -15,
            -16,
            -17,
            i64::MIN,
            i64::MAX,
            -(1 << 40) - 3,
        ];
        for four in values.windows(4) {
            // SAFETY: the processor has AVX2 (checked above).
            let got: [i64; 4] =
                unsafe { std::mem::transmute(div16(_mm256_loadu_si256(four.as_ptr().cast()))) };
            assert_eq!(
                got,
                [0, 1, 2, 3].map(|k| four[k].div_euclid(16)),
                "{four:?}"
            );
        }
    }

    #[test]
    fn groups_of_one_to_eight_ids_fill_all_lanes_from_the_group() {
        assert_eq!(eight(&[5]), [5; 8]);
        assert_eq!(eight(&[1, 2, 3]), [1, 2, 3, 1, 1, 1, 1, 1]);
        let all = [9, 8, 7, 6, 5, 4, 3, 2];
        assert_eq!(eight(&all), all);
    }

    #[test]
    fn meshes_beyond_the_gather_indices_use_other_code() {
        assert!(fits(1000, 3000, 1024));
        assert!(!fits(1 << 30, 3000, 1024));
        assert!(!fits(1000, 1 << 30, 1024));
        assert!(!fits(1000, 3000, 1 << 31));
        assert!(fits((1 << 31) / 3, (1 << 31) / 3, (1 << 31) - 1));
    }
}
