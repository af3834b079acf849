//! The serial smooth-shading sum: per slot, the normals of the triangles
//! naming it added in triangle order. A slot's sum is four `f64` lanes
//! (x, y, z and a zero) aligned to 32 bytes, so with AVX2 a triangle's normal
//! is one cross product of vectors and each corner one load, add and store
//! (a third of the scalar loop's instructions). The vector code does the same
//! IEEE operations lane by lane (subtract, multiply, subtract, add; nothing
//! fused), so the sums are the scalar loop's bit for bit.

use super::smooth::{NodeSpans, tri_normal};

/// One slot's sum: x, y, z and an unused lane.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
#[repr(C, align(32))]
pub struct Sum(pub [f64; 4]);

impl Sum {
    #[inline]
    pub fn xyz(self) -> [f64; 3] {
        [self.0[0], self.0[1], self.0[2]]
    }
}

/// `len` sums: slot `slots[i][k]` gets the normal of triangle `tris[i]`, in
/// triangle order. Every node of `tris` must be a point and every slot below
/// `len`. `spans`, when they are [`NodeSpans`] of `tris` naming only points,
/// spare the one-face loop its corner checks.
pub fn serial_sums(
    points: &[[f64; 3]],
    tris: &[[u32; 3]],
    slots: &[[u32; 3]],
    len: usize,
    spans: Option<&NodeSpans>,
) -> Vec<Sum> {
    let mut sums = vec![Sum::default(); len];
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx2") {
            let checked = spans.is_some_and(|s| s.all_below(tris, points.len()));
            if checked && std::ptr::eq(tris, slots) && len >= points.len() {
                // SAFETY: the CPU has AVX2 (checked just above), and every
                // corner names a point, so a slot below `len` (the spans
                // of these very triangles say so).
                unsafe { own_sums_unchecked(points, tris, &mut sums) };
            } else {
                // SAFETY: the CPU has AVX2 (checked just above).
                unsafe { sums_avx2(points, tris, slots, &mut sums) };
            }
            return sums;
        }
    }
    sums_scalar(points, tris, slots, &mut sums);
    sums
}

fn sums_scalar(points: &[[f64; 3]], tris: &[[u32; 3]], slots: &[[u32; 3]], sums: &mut [Sum]) {
    for (t, s) in tris.iter().zip(slots) {
        let n = tri_normal(points, *t);
        for &k in s {
            let sum = &mut sums[k as usize].0;
            sum[0] += n[0];
            sum[1] += n[1];
            sum[2] += n[2];
        }
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn sums_avx2(points: &[[f64; 3]], tris: &[[u32; 3]], slots: &[[u32; 3]], sums: &mut [Sum]) {
    if std::ptr::eq(tris, slots) {
        // The slots are the triangles' own nodes (one face): each corner is
        // read once, and with the points and sums cut to one length a
        // node's bounds check serves both its point and its sum.
        let m = points.len().min(sums.len());
        let (points, sums) = (&points[..m], &mut sums[..m]);
        for t in tris {
            let n = normal_avx2(points, *t);
            for &k in t {
                add_avx2(&mut sums[k as usize], n);
            }
        }
        return;
    }
    for (t, s) in tris.iter().zip(slots) {
        let n = normal_avx2(points, *t);
        for &k in s {
            add_avx2(&mut sums[k as usize], n);
        }
    }
}

/// The triangle's normal (`tri_normal`) in the x, y, z lanes.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
fn normal_avx2(points: &[[f64; 3]], t: [u32; 3]) -> std::arch::x86_64::__m256d {
    let [a, b, c] = t.map(|k| &points[k as usize]);
    corner_normal(a, b, c)
}

/// The normal of the triangle with corners `a`, `b`, `c`, as [`normal_avx2`].
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
pub(in crate::render) fn corner_normal(
    a: &[f64; 3],
    b: &[f64; 3],
    c: &[f64; 3],
) -> std::arch::x86_64::__m256d {
    use std::arch::x86_64::*;
    let (a, b, c) = (load_point(a), load_point(b), load_point(c));
    cross_lanes(_mm256_sub_pd(b, a), _mm256_sub_pd(c, a))
}

/// `u × v` in the x, y, z lanes of `u` and `v`: [`cross`]'s products and
/// differences, lane by lane.
///
/// [`cross`]: crate::render::camera::cross
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
pub(in crate::render) fn cross_lanes(
    u: std::arch::x86_64::__m256d,
    v: std::arch::x86_64::__m256d,
) -> std::arch::x86_64::__m256d {
    use std::arch::x86_64::*;
    // u × v = (u · v.yzx − u.yzx · v).yzx: lane y of the difference is
    // u.y·v.z − u.z·v.y, the x of `cross` (the same products in the same
    // order), and so on round, with three permutations instead of four.
    // The spare lane stays 0·0 − 0·0.
    const YZX: i32 = 0b11_00_10_01;
    let w = _mm256_sub_pd(
        _mm256_mul_pd(u, _mm256_permute4x64_pd::<YZX>(v)),
        _mm256_mul_pd(_mm256_permute4x64_pd::<YZX>(u), v),
    );
    _mm256_permute4x64_pd::<YZX>(w)
}

/// The one-face loop of [`sums_avx2`] without corner checks: about six
/// million of them for a million triangles.
///
/// # Safety
/// The CPU has AVX2, and every node of `tris` is below `points.len()`,
/// which is at most `sums.len()`.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn own_sums_unchecked(points: &[[f64; 3]], tris: &[[u32; 3]], sums: &mut [Sum]) {
    for t in tris {
        // SAFETY: every node of `t` is below `points.len()` ≤ `sums.len()`
        // (the caller's promise).
        unsafe {
            let [a, b, c] = t.map(|k| points.get_unchecked(k as usize));
            let n = corner_normal(a, b, c);
            for &k in t {
                add_avx2(sums.get_unchecked_mut(k as usize), n);
            }
        }
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
pub(in crate::render) fn add_avx2(sum: &mut Sum, n: std::arch::x86_64::__m256d) {
    use std::arch::x86_64::*;
    // SAFETY: `sum` is four f64s aligned to 32 bytes (`Sum`).
    unsafe {
        let old = _mm256_load_pd(sum.0.as_ptr());
        _mm256_store_pd(sum.0.as_mut_ptr(), _mm256_add_pd(old, n));
    }
}

/// A point's x, y, z and a zero lane.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
pub(in crate::render) fn load_point(p: &[f64; 3]) -> std::arch::x86_64::__m256d {
    use std::arch::x86_64::*;
    // SAFETY: `p` holds three f64s: 16 bytes at its start, 8 at its third.
    unsafe {
        let xy = _mm_loadu_pd(p.as_ptr());
        let z = _mm_load_sd(p.as_ptr().add(2));
        _mm256_insertf128_pd::<1>(_mm256_castpd128_pd256(xy), z)
    }
}

#[cfg(test)]
mod tests {
    use super::super::smooth::node_spans;
    use super::*;

    /// Points whose differences and products round: any change in the
    /// order or fusing of operations would show in the bits.
    fn scattered(n: usize) -> Vec<[f64; 3]> {
        (0..n)
            .map(|i| {
                let t = i as f64 * 0.618_033_988_749_895;
                [
                    t.sin() * 1.3e3,
                    (t * 1.7).cos() * 0.37,
                    t.fract() * 1e-3 + 7.0,
                ]
            })
            .collect()
    }

    #[test]
    fn vector_sums_are_the_scalar_sums_bit_for_bit() {
        let points = scattered(997);
        let n = points.len() as u32;
        let tris: Vec<[u32; 3]> = (0..5000u32)
            .map(|i| [i % n, (i * 7 + 3) % n, (i * 13 + 5) % n])
            .collect();
        // Slots past the points too (a later face's pairs), in another order.
        let slots: Vec<[u32; 3]> = tris.iter().map(|t| t.map(|k| (k * 3) % 1200)).collect();
        let mut want = vec![Sum::default(); 1200];
        sums_scalar(&points, &tris, &slots, &mut want);
        let got = serial_sums(&points, &tris, &slots, 1200, None);
        assert_eq!(got.len(), 1200);
        for (g, w) in got.iter().zip(&want) {
            assert_eq!(g.xyz().map(f64::to_bits), w.xyz().map(f64::to_bits));
        }
        // Slots that are the triangles themselves (one face) take the
        // one-read loop: the same bits.
        let mut own = vec![Sum::default(); points.len()];
        sums_scalar(&points, &tris, &tris, &mut own);
        let got_own = serial_sums(&points, &tris, &tris, points.len(), None);
        for (g, w) in got_own.iter().zip(&own) {
            assert_eq!(g.xyz().map(f64::to_bits), w.xyz().map(f64::to_bits));
        }
        // With the triangles' spans, the loop without corner checks: the
        // same bits again.
        let spans = node_spans(&tris);
        assert!(spans.all_below(&tris, points.len()));
        let unchecked = serial_sums(&points, &tris, &tris, points.len(), Some(&spans));
        for (g, w) in unchecked.iter().zip(&own) {
            assert_eq!(g.xyz().map(f64::to_bits), w.xyz().map(f64::to_bits));
        }
        assert!(own.iter().filter(|s| s.xyz() != [0.0; 3]).count() > 900);
        // And the scalar loop is the plain per-slot sum of `tri_normal`s.
        let k = slots[17][1] as usize;
        let mut plain = [0.0f64; 3];
        for (t, s) in tris.iter().zip(&slots) {
            for &slot in s {
                if slot as usize == k {
                    let nrm = tri_normal(&points, *t);
                    for c in 0..3 {
                        plain[c] += nrm[c];
                    }
                }
            }
        }
        assert_eq!(want[k].xyz().map(f64::to_bits), plain.map(f64::to_bits));
        assert_ne!(plain, [0.0; 3]);
    }

    #[test]
    fn unchecked_sums_are_the_scalar_sums_bit_for_bit_on_random_meshes() {
        let points = scattered(600);
        let n = points.len() as u32;
        // Random meshes, the same on every run.
        let mut rng = crate::test_rng::TestRng::new(0x9e37_79b9_7f4a_7c15);
        let mut tris: Vec<[u32; 3]> = Vec::new();
        // Random runs of strips (each triangle shares two corners with the
        // last, in turning positions), fans (one corner shared by all),
        // triangles sharing one or no corner, and degenerate ones naming a
        // corner twice or thrice, also as the very first triangle: nodes
        // first named in order, skipping some, and named again later.
        tris.push([5, 5, 9]);
        while tris.len() < 20_000 {
            let r = rng.next_u64();
            let at = (r >> 8) as u32 % n;
            let len = 1 + (r >> 40) as usize % 40;
            match r % 6 {
                0 | 1 => {
                    // A strip: (a, b, c), (a, c, d) rotated as the torus does.
                    let w = 1 + (r >> 20) as u32 % 7;
                    for j in 0..len as u32 {
                        let p = |i: u32, k: u32| (at + i * w + k) % n;
                        tris.push([p(0, j), p(1, j), p(1, j + 1)]);
                        tris.push([p(0, j), p(1, j + 1), p(0, j + 1)]);
                    }
                }
                2 => {
                    for j in 0..len as u32 {
                        tris.push([at, (at + j + 1) % n, (at + j + 2) % n]);
                    }
                }
                3 => {
                    let last = *tris.last().unwrap_or(&[0, 1, 2]);
                    tris.push([last[(r >> 30) as usize % 3], at, (at + 11) % n]);
                }
                4 => {
                    let k = (rng.next_u64() % u64::from(n)) as u32;
                    let shapes = [[at, at, k], [at, k, at], [k, at, at], [at, at, at]];
                    tris.push(shapes[(r >> 30) as usize % 4]);
                    let last = tris[tris.len() - 1];
                    tris.push([last[0], last[2], (at + 3) % n]);
                }
                _ => {
                    for _ in 0..len {
                        let v = rng.next_u64();
                        tris.push([0, 21, 42].map(|s| ((v >> s) % u64::from(n)) as u32));
                    }
                }
            }
        }
        // Nodes 590.. are never named; slots past the points (a later
        // face's) are asked for too: both stay zero.
        for t in &mut tris {
            *t = t.map(|m| m % 590);
        }
        let len = points.len() + 50;
        let mut want = vec![Sum::default(); len];
        sums_scalar(&points, &tris, &tris, &mut want);
        let spans = node_spans(&tris);
        assert!(spans.all_below(&tris, points.len()));
        let got = serial_sums(&points, &tris, &tris, len, Some(&spans));
        assert_eq!(got.len(), len);
        for (node, (g, w)) in got.iter().zip(&want).enumerate() {
            assert_eq!(g.0.map(f64::to_bits), w.0.map(f64::to_bits), "node {node}");
        }
        assert!(got[590..].iter().all(|s| s.0.map(f64::to_bits) == [0; 4]));
        // Triangles naming nodes in their order of first use, and the
        // empty list.
        let strip: Vec<[u32; 3]> = (0..500u32)
            .map(|j| {
                if j % 2 == 0 {
                    [j, j + 1, j + 2]
                } else {
                    [j, j + 2, j + 1]
                }
            })
            .collect();
        let spans = node_spans(&strip);
        let mut want_strip = vec![Sum::default(); points.len()];
        sums_scalar(&points, &strip, &strip, &mut want_strip);
        let got_strip = serial_sums(&points, &strip, &strip, points.len(), Some(&spans));
        for (g, w) in got_strip.iter().zip(&want_strip) {
            assert_eq!(g.0.map(f64::to_bits), w.0.map(f64::to_bits));
        }
        let none: Vec<[u32; 3]> = Vec::new();
        let spans = node_spans(&none);
        let empty = serial_sums(&points, &none, &none, points.len() + 3, Some(&spans));
        assert_eq!(empty, vec![Sum::default(); points.len() + 3]);
        // The runs above did share corners and repeat them.
        let shares_two = tris
            .windows(2)
            .filter(|w| w[1].iter().filter(|c| w[0].contains(c)).count() == 2);
        assert!(shares_two.count() > 5_000);
        let repeats = tris
            .iter()
            .filter(|t| t[0] == t[1] || t[1] == t[2] || t[0] == t[2]);
        assert!(repeats.count() > 100);
        assert!(got.iter().filter(|s| s.xyz() != [0.0; 3]).count() > 480);
    }
}
