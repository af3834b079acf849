//! The one-face smooth-shading sums in triangle order (the bits of
//! [`serial_sums`](crate::render::normal_sum::serial_sums)) without an array
//! of sums over all nodes: a node's sum is final once no later triangle
//! names it, so it is turned into light there and its place reused. The
//! sums live in a ring of a few thousand nodes that stays in cache, instead
//! of 16 MB zeroed, written and read again for a million triangles.
//!
//! When that is: the chunks' node spans say which nodes later chunks can
//! name. A chunk spanning more than [`LOCAL_SPAN`] (a torus's last rows
//! closing onto its first) would hold every node back, so such "wide"
//! chunks are left out of that reckoning, and the nodes they name are set
//! apart: a wide chunk's corner below the ring goes to a small store of its
//! own (the sum the ring held when the node left it, continued), turned
//! into light at the end.

use super::{CHUNK, LOCAL_SPAN};
use crate::render::normal_sum::{Sum, add_avx2, corner_normal, cross_lanes, load_point};
use std::mem::MaybeUninit;

/// Most nodes in the ring (2 MB of sums); a mesh needing more is summed
/// over an array of all nodes.
const MOST_RING: usize = 1 << 16;
/// Most wide chunks (a torus has one: its last rows closing onto row 0).
const MOST_WIDE: usize = 4;

/// The nodes wide chunks name: a bit per node, and per word of bits the
/// count of set bits before it, so a node's place in the store is a rank.
struct SetApart {
    words: Vec<u64>,
    before: Vec<u32>,
    count: usize,
}

impl SetApart {
    fn new(n: usize, wide: impl Iterator<Item = u32>) -> SetApart {
        let mut words = vec![0u64; n.div_ceil(64)];
        for k in wide {
            words[k as usize >> 6] |= 1 << (k & 63);
        }
        let mut count = 0;
        let before = (words.iter())
            .map(|w| {
                let at = count as u32;
                count += w.count_ones() as usize;
                at
            })
            .collect();
        SetApart {
            words,
            before,
            count,
        }
    }

    /// The place of node `k` (set apart) among the set-apart nodes.
    #[inline]
    fn rank(&self, k: usize) -> usize {
        let below = self.words[k >> 6] & ((1u64 << (k & 63)) - 1);
        self.before[k >> 6] as usize + below.count_ones() as usize
    }

    /// Calls `f(node, rank)` for the set-apart nodes in `from..to`, in order.
    fn each(&self, from: usize, to: usize, mut f: impl FnMut(usize, usize)) {
        if self.count == 0 || from >= to {
            return;
        }
        let mut r = self.rank(from);
        for w in from >> 6..=(to - 1) >> 6 {
            let mut bits = self.words[w];
            while bits != 0 {
                let k = w * 64 + bits.trailing_zeros() as usize;
                bits &= bits - 1;
                if k >= to {
                    return;
                }
                if k >= from {
                    f(k, r);
                    r += 1;
                }
            }
        }
    }
}

/// `out[k] = finish(sum of node k)` for every node (`finish` is given every
/// slot of `out` once, and the set-apart nodes' slots again from a copy),
/// the sums in triangle order, or `false` (nothing written) when the chunks' spans leave no
/// window small enough. `spans` are the [`CHUNK`] spans of `tris`
/// ([`super::NodeSpans`]), every node of `tris` below `points.len()`, which
/// is `out.len()`; the CPU has AVX2.
///
/// # Safety
/// The CPU has AVX2, and every node of `tris` is below `points.len()`.
#[target_feature(enable = "avx2")]
pub(super) unsafe fn light_in_window<T: Copy>(
    points: &[[f64; 3]],
    tris: &[[u32; 3]],
    spans: &[(usize, usize)],
    out: &mut [MaybeUninit<T>],
    finish: &impl Fn(&[Sum], &mut [MaybeUninit<T>]),
) -> bool {
    let n = points.len();
    assert!(out.len() == n && spans.len() == tris.len().div_ceil(CHUNK));
    let wide = |&(lo, hi): &(usize, usize)| hi - lo > LOCAL_SPAN;
    // Before chunk c, the nodes below `base[c]` are final: no later chunk
    // but a wide one names them.
    let mut base = vec![n; spans.len() + 1];
    for c in (0..spans.len()).rev() {
        base[c] = if wide(&spans[c]) {
            base[c + 1]
        } else {
            base[c + 1].min(spans[c].0)
        };
    }
    // The ring holds nodes base[c].. while chunk c names them.
    let need = (spans.iter().zip(&base))
        .map(|(&(_, hi), &b)| hi.saturating_sub(b))
        .max()
        .unwrap_or(0);
    let size = need.next_power_of_two().max(64);
    // Few wide chunks, few nodes set apart: else the store would be the
    // array of all nodes again.
    if size > MOST_RING || spans.iter().filter(|s| wide(s)).count() > MOST_WIDE {
        return false;
    }
    let wide_tris = (tris.chunks(CHUNK).zip(spans))
        .filter(|(_, s)| wide(s))
        .flat_map(|(t, _)| t.as_flattened().iter().copied());
    let apart = SetApart::new(n, wide_tris);
    if apart.count > MOST_RING {
        return false;
    }
    let mut store = vec![Sum::default(); apart.count];
    let mut ring = vec![Sum::default(); size];
    let mask = size - 1;
    // Turns nodes from..to into light and empties their places.
    let mut advance = |ring: &mut [Sum], store: &mut [Sum], from: usize, to: usize| {
        let mut k = from;
        while k < to {
            let at = k & mask;
            let len = (to - k).min(size - at);
            finish(&ring[at..at + len], &mut out[k..k + len]);
            apart.each(k, k + len, |node, r| store[r] = ring[node & mask]);
            ring[at..at + len].fill(Sum::default());
            k += len;
        }
    };
    let mut done = 0;
    for ((chunk, span), &b) in tris.chunks(CHUNK).zip(spans).zip(&base) {
        advance(&mut ring, &mut store, done, b);
        done = b;
        if wide(span) {
            for t in chunk {
                // SAFETY: every node is below `n` (the caller's promise);
                // one below `done` is set apart (only wide chunks name
                // such nodes), so it has a rank in the store; any other is
                // below `hi ≤ done + size` (`need`), so its place in the
                // ring is its own.
                unsafe {
                    let nrm = corner_normal(
                        points.get_unchecked(t[0] as usize),
                        points.get_unchecked(t[1] as usize),
                        points.get_unchecked(t[2] as usize),
                    );
                    for &k in t {
                        let k = k as usize;
                        let sum = if k < done {
                            store.get_unchecked_mut(apart.rank(k))
                        } else {
                            ring.get_unchecked_mut(k & mask)
                        };
                        add_avx2(sum, nrm);
                    }
                }
            }
        } else {
            // SAFETY: every node is below `n` (the caller's promise), and
            // within `lo..hi` of this chunk, `done ≤ lo` and
            // `hi ≤ done + size`: its place in the ring is its own.
            unsafe { local_chunk(points, chunk, &mut ring) };
        }
    }
    advance(&mut ring, &mut store, done, n);
    let mut light = vec![MaybeUninit::uninit(); store.len()];
    finish(&store, &mut light);
    apart.each(0, n, |node, r| out[node] = light[r]);
    true
}

/// The normal of triangle `t`.
///
/// # Safety
/// The CPU has AVX2; every node of `t` is below `points.len()`.
#[target_feature(enable = "avx2")]
#[inline]
unsafe fn normal(points: &[[f64; 3]], t: [u32; 3]) -> std::arch::x86_64::__m256d {
    // SAFETY: every node of `t` is a point (the caller's promise).
    unsafe {
        corner_normal(
            points.get_unchecked(t[0] as usize),
            points.get_unchecked(t[1] as usize),
            points.get_unchecked(t[2] as usize),
        )
    }
}

/// `sum += a`, then `sum += b`, the sum kept in a register between.
#[target_feature(enable = "avx2")]
#[inline]
fn add_two(sum: &mut Sum, a: std::arch::x86_64::__m256d, b: std::arch::x86_64::__m256d) {
    use std::arch::x86_64::*;
    // SAFETY: `sum` is four f64s aligned to 32 bytes (`Sum`).
    unsafe {
        let old = _mm256_load_pd(sum.0.as_ptr());
        let once = _mm256_add_pd(old, a);
        _mm256_store_pd(sum.0.as_mut_ptr(), _mm256_add_pd(once, b));
    }
}

/// Adds a chunk's normals into the ring. Two triangles that are a quad cut
/// along its diagonal, (a, b, c) then (a, c, d) (a grid's and a torus's
/// order), share the points a and c and the edge c − a: four points are
/// read instead of six, and a and c get both normals in a register (one
/// load and store instead of two). Each normal is the same operations on
/// the same values as one triangle at a time, and per node the adds keep
/// triangle order, so the bits are those of one triangle at a time; other
/// triangles are added so.
///
/// # Safety
/// The CPU has AVX2; every node of `tris` is below `points.len()`, and its
/// place `node & (ring.len() − 1)` is in the ring (a power of two long).
#[target_feature(enable = "avx2")]
unsafe fn local_chunk(points: &[[f64; 3]], tris: &[[u32; 3]], ring: &mut [Sum]) {
    use std::arch::x86_64::_mm256_sub_pd;
    let mask = ring.len() - 1;
    let (pairs, rest) = tris.as_chunks::<2>();
    // SAFETY (all blocks below): every node is a point, and its place in
    // the ring is below `ring.len()` (`& mask`), the caller's promise; each
    // place is borrowed for one add only, so never twice at once.
    let places = ring.as_mut_ptr();
    let at = |k: u32| unsafe { &mut *places.add(k as usize & mask) };
    let point = |k: u32| load_point(unsafe { points.get_unchecked(k as usize) });
    let one = |t: [u32; 3]| {
        let nt = unsafe { normal(points, t) };
        for k in t {
            add_avx2(at(k), nt);
        }
    };
    for &[t, u] in pairs {
        // With a ≠ b and a ≠ c every node gets the first normal before the
        // second (b = c or d = any corner included).
        if t[0] == u[0] && t[2] == u[1] && t[0] != t[1] && t[0] != t[2] {
            let [a, b, c] = t.map(point);
            let ca = _mm256_sub_pd(c, a);
            let nt = cross_lanes(_mm256_sub_pd(b, a), ca);
            let nu = cross_lanes(ca, _mm256_sub_pd(point(u[2]), a));
            add_two(at(t[0]), nt, nu);
            add_avx2(at(t[1]), nt);
            add_two(at(t[2]), nt, nu);
            add_avx2(at(u[2]), nu);
        } else {
            one(t);
            one(u);
        }
    }
    for &t in rest {
        one(t);
    }
}

#[cfg(test)]
mod tests {
    use super::super::node_spans;
    use super::*;
    use crate::render::normal_sum::serial_sums;

    /// A torus of `nu` rows of `nv` nodes, rows in order: the last row's
    /// triangles close onto row 0, so the last chunk is wide.
    fn torus(nu: u32, nv: u32) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        let mut points = Vec::new();
        for i in 0..nu {
            let u = f64::from(i) / f64::from(nu) * std::f64::consts::TAU;
            for j in 0..nv {
                let v = f64::from(j) / f64::from(nv) * std::f64::consts::TAU;
                let ring = 1.0 + 0.35 * v.cos();
                points.push([ring * u.cos(), ring * u.sin(), 0.35 * v.sin()]);
            }
        }
        let id = |i: u32, j: u32| (i % nu) * nv + j % nv;
        let mut tris = Vec::new();
        for i in 0..nu {
            for j in 0..nv {
                tris.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                tris.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        (points, tris)
    }

    /// The windowed sums, or `None` when the window is too wide.
    fn windowed(points: &[[f64; 3]], tris: &[[u32; 3]]) -> Option<Vec<Sum>> {
        let spans = node_spans(tris);
        assert!(spans.all_below(tris, points.len()));
        let mut out = vec![MaybeUninit::new(Sum([7.0; 4])); points.len()];
        let copy = |s: &[Sum], o: &mut [MaybeUninit<Sum>]| {
            for (o, s) in o.iter_mut().zip(s) {
                o.write(*s);
            }
        };
        // SAFETY: the CPU has AVX2 (the callers check), every node is a point.
        let done = unsafe { light_in_window(points, tris, spans.spans(), &mut out, &copy) };
        // SAFETY: every slot was initialised above (and perhaps written again).
        let out: Vec<Sum> = out
            .into_iter()
            .map(|s| unsafe { s.assume_init() })
            .collect();
        if !done {
            assert!(out.iter().all(|s| *s == Sum([7.0; 4])), "nothing written");
        }
        done.then_some(out)
    }

    fn assert_serial_bits(points: &[[f64; 3]], tris: &[[u32; 3]]) {
        let got = windowed(points, tris).expect("a window fits");
        let want = serial_sums(points, tris, tris, points.len(), None);
        for (node, (g, w)) in got.iter().zip(&want).enumerate() {
            assert_eq!(g.0.map(f64::to_bits), w.0.map(f64::to_bits), "node {node}");
        }
    }

    #[test]
    fn windowed_sums_are_the_serial_sums_bit_for_bit() {
        if !std::arch::is_x86_feature_detected!("avx2") {
            return;
        }
        // 80,000 triangles over 40,000 nodes: five chunks, the last wide.
        let (points, tris) = torus(400, 100);
        let spans = node_spans(&tris);
        let wide = spans.spans().iter().filter(|(lo, hi)| hi - lo > LOCAL_SPAN);
        assert_eq!(wide.count(), 1);
        assert!(spans.spans()[4].0 == 0 && spans.spans()[4].1 == points.len());
        assert_serial_bits(&points, &tris);
        // The wide chunk in the middle, first, and the order reversed.
        let mut turned = tris.clone();
        turned.rotate_left(2 * CHUNK + 555);
        assert_serial_bits(&points, &turned);
        turned.rotate_left(tris.len() - CHUNK);
        assert_serial_bits(&points, &turned);
        turned.reverse();
        assert_serial_bits(&points, &turned);
        // Short meshes: one partial chunk, and none.
        assert_serial_bits(&points, &tris[..1000]);
        assert_serial_bits(&points, &[]);
        // Degenerate triangles, corners named twice, nodes never named.
        let mut odd = tris[..3 * CHUNK].to_vec();
        for (i, t) in odd.iter_mut().enumerate().step_by(7) {
            t[i % 3] = t[(i + 1) % 3];
        }
        odd.push([39_999, 0, 39_999]);
        odd.push([5, 5, 5]);
        assert_serial_bits(&points, &odd);
    }

    #[test]
    fn quads_with_repeated_corners_keep_the_serial_bits() {
        if !std::arch::is_x86_feature_detected!("avx2") {
            return;
        }
        let (points, tris) = torus(400, 100);
        assert!(
            tris.chunks(2)
                .all(|q| q[0][0] == q[1][0] && q[0][2] == q[1][1])
        );
        // Quads (a, b, c), (a, c, d) with corners named twice: d = a, b or
        // c and b = c share the points; a = b and a = c are added one
        // triangle at a time.
        let mut odd = tris.clone();
        for (q, pair) in odd.chunks_exact_mut(2).enumerate() {
            let [a, b, c] = pair[0];
            match q % 7 {
                0 => pair[1][2] = a,
                1 => pair[1][2] = b,
                2 => pair[1][2] = c,
                3 => (pair[0][2], pair[1][1]) = (b, b),
                4 => pair[0][1] = a,
                5 => (pair[0][2], pair[1][1]) = (a, a),
                _ => {}
            }
        }
        assert_serial_bits(&points, &odd);
        // Pairs across quads (an odd start) and single triangles.
        assert_serial_bits(&points, &odd[1..]);
        assert_serial_bits(&points, &tris[3..CHUNK + 8]);
    }

    #[test]
    fn nodes_numbered_without_locality_take_no_window() {
        if !std::arch::is_x86_feature_detected!("avx2") {
            return;
        }
        let (points, tris) = torus(400, 200);
        let n = points.len() as u32;
        let to = |i: u32| ((u64::from(i) * 7919) % u64::from(n)) as u32;
        let shuffled: Vec<[u32; 3]> = tris.iter().map(|t| t.map(to)).collect();
        assert!(windowed(&points, &shuffled).is_none());
        assert!(windowed(&points, &tris).is_some());
    }

    #[test]
    fn set_apart_nodes_are_ranked_in_order() {
        let apart = SetApart::new(300, [299, 3, 64, 3, 0, 127, 128].into_iter());
        assert_eq!(apart.count, 6);
        let mut seen = Vec::new();
        apart.each(0, 300, |k, r| seen.push((k, r)));
        assert_eq!(
            seen,
            [(0, 0), (3, 1), (64, 2), (127, 3), (128, 4), (299, 5)]
        );
        for &(k, r) in &seen {
            assert_eq!(apart.rank(k), r);
        }
        seen.clear();
        apart.each(4, 128, |k, r| seen.push((k, r)));
        assert_eq!(seen, [(64, 2), (127, 3)]);
        apart.each(128, 128, |_, _| panic!("empty range"));
    }
}
