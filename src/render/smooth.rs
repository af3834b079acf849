//! Smooth-shading normals: for each node of each face, the sum of the
//! area-weighted normals of the face's triangles around it (creases between
//! faces stay sharp). Computed in parallel in a fixed order, so any thread
//! count gives the same sums: triangles are cut into chunks of a fixed size,
//! each chunk sums into a small array over the nodes it touches, and the
//! chunks' partial sums are added in chunk order.

use super::camera::cross;
use rayon::prelude::*;
use std::sync::atomic::{AtomicU32, Ordering};

/// Triangles per chunk of partial sums.
pub const CHUNK: usize = 1 << 14;
/// Widest node range a chunk sums over in an array of its own; a mesh whose
/// chunks reach further (nodes numbered without locality) is summed serially.
const LOCAL_SPAN: usize = 2 * CHUNK;

#[inline]
pub fn tri_normal(p: &[[f64; 3]], t: [u32; 3]) -> [f64; 3] {
    let (a, b, c) = (p[t[0] as usize], p[t[1] as usize], p[t[2] as usize]);
    cross(
        [b[0] - a[0], b[1] - a[1], b[2] - a[2]],
        [c[0] - a[0], c[1] - a[1], c[2] - a[2]],
    )
}

fn add(sum: &mut [f64; 3], n: [f64; 3]) {
    sum[0] += n[0];
    sum[1] += n[1];
    sum[2] += n[2];
}

/// Per triangle corner a slot, and per slot `finish` of the summed normal
/// (the light, for pictures: the sums themselves are never stored). A node's slot
/// is its own index in the first face (lowest index) that uses it; the
/// (face, node) pairs of later faces get slots after the nodes, in sorted order.
/// The slots are `None` when they are the triangles' own nodes (one face).
/// `tri_face` must be non-decreasing (triangles grouped by face in face order).
///
/// Every sum is the plain one, the triangles' normals added in triangle order
/// from zero (the same bits as a serial loop, for any thread count), yet
/// computed in parallel: see [`exact_sums`].
pub fn per_slot<T: Copy + Default + Send + Sync>(
    points: &[[f64; 3]],
    tris: &[[u32; 3]],
    tri_face: &[u32],
    finish: impl Fn([f64; 3]) -> T + Sync,
) -> (Option<Vec<[u32; 3]>>, Vec<T>) {
    let n = points.len();
    let (own_slots, extra) = if tri_face.first() == tri_face.last() {
        (None, Vec::new())
    } else {
        let (slots, extra) = later_face_slots(n, tris, tri_face);
        (Some(slots), extra)
    };
    let corner_slots: &[[u32; 3]] = own_slots.as_deref().unwrap_or(tris);
    let slots = n + extra.len();
    let out = match exact_sums(points, tris, corner_slots, n, slots, &finish) {
        Some(out) => out,
        None => {
            let mut sums = vec![[0.0; 3]; slots];
            for (t, s) in tris.iter().zip(corner_slots) {
                let normal = tri_normal(points, *t);
                for &k in s {
                    add(&mut sums[k as usize], normal);
                }
            }
            sums.par_iter().map(|&v| finish(v)).collect()
        }
    };
    (own_slots, out)
}

/// A triangle whose slots below `n` lie further apart than this is a stray
/// (a ring's closing triangles, say): its corners are summed with the shared
/// slots, so it does not widen its chunk's span.
const STRAY_WIDTH: u32 = LOCAL_SPAN as u32;

/// The parallel sums of [`per_slot`], or `None` when the mesh is numbered
/// without locality (a chunk's span too wide, or too many stray corners).
///
/// Triangles are cut into chunks of [`CHUNK`]. A slot that only one chunk
/// uses, inside that chunk's *own* range (its span with every other chunk's
/// span and every stray triangle's slots taken out), gets its whole sum from
/// that chunk, summed in triangle order in a small array. Every other
/// contribution (slots near chunk borders, slots of later faces, stray
/// triangles) is listed by its chunk in triangle order and the lists are
/// added in chunk order, so each sum adds its normals in triangle order from
/// zero, as the serial loop does: no partial sums are added together.
fn exact_sums<T: Copy + Default + Send + Sync>(
    points: &[[f64; 3]],
    tris: &[[u32; 3]],
    corner_slots: &[[u32; 3]],
    n: usize,
    slots: usize,
    finish: &(impl Fn([f64; 3]) -> T + Sync),
) -> Option<Vec<T>> {
    let below = |k: u32| (k as usize) < n;
    let is_stray = |s: &[u32; 3]| {
        let (lo, hi) = s
            .iter()
            .filter(|&&k| below(k))
            .fold((u32::MAX, 0), |(l, h), &k| (l.min(k), h.max(k)));
        lo != u32::MAX && hi - lo > STRAY_WIDTH
    };
    // Per chunk: the span of its other triangles' slots below `n`, and its
    // strays' slots below `n`.
    let scans: Vec<((usize, usize), Vec<u32>)> = corner_slots
        .par_chunks(CHUNK)
        .map(|chunk| {
            let mut strays = Vec::new();
            let (mut lo, mut hi) = (usize::MAX, 0);
            for s in chunk {
                if is_stray(s) {
                    strays.extend(s.iter().copied().filter(|&k| below(k)));
                    continue;
                }
                for &k in s.iter().filter(|&&k| below(k)) {
                    lo = lo.min(k as usize);
                    hi = hi.max(k as usize + 1);
                }
            }
            ((lo, hi), strays)
        })
        .collect();
    let mut strays: Vec<u32> = scans.iter().flat_map(|(_, s)| s.iter().copied()).collect();
    if scans
        .iter()
        .any(|&((lo, hi), _)| hi.saturating_sub(lo) > LOCAL_SPAN)
        || strays.len() > tris.len() / 8
    {
        return None;
    }
    strays.sort_unstable();
    strays.dedup();
    let spans: Vec<(usize, usize)> = scans.iter().map(|&(span, _)| span).collect();
    let own: Vec<(usize, usize)> = (0..spans.len())
        .map(|c| own_range(&spans, c, &strays))
        .collect();
    let layout = Layout::new(&own, slots);
    // Each chunk finishes its own range straight into its piece of `out`
    // (own ranges are disjoint), summing in one buffer per thread, and lists
    // its other contributions as (shared index, normal) in triangle order.
    let mut out = vec![T::default(); slots];
    let mut pieces: Vec<&mut [T]> = (0..own.len()).map(|_| Default::default()).collect();
    let (mut rest, mut at): (&mut [T], usize) = (&mut out, 0);
    for &(lo, hi, c) in &layout.owned {
        let (piece, after) = std::mem::take(&mut rest)[lo - at..].split_at_mut(hi - lo);
        pieces[c] = piece;
        (rest, at) = (after, hi);
    }
    let listed: Vec<Vec<(u32, [f64; 3])>> = tris
        .par_chunks(CHUNK)
        .zip(corner_slots.par_chunks(CHUNK))
        .zip(&own)
        .zip(pieces)
        .map_init(
            Vec::new,
            |sums: &mut Vec<[f64; 3]>, (((ts, ss), &(lo, hi)), piece)| {
                sums.clear();
                sums.resize(hi - lo, [0.0; 3]);
                let mut listed = Vec::new();
                for (t, s) in ts.iter().zip(ss) {
                    let normal = tri_normal(points, *t);
                    for &k in s {
                        let k = k as usize;
                        if (lo..hi).contains(&k) {
                            add(&mut sums[k - lo], normal);
                        } else {
                            listed.push((layout.shared_index(k) as u32, normal));
                        }
                    }
                }
                for (o, &v) in piece.iter_mut().zip(sums.iter()) {
                    *o = finish(v);
                }
                listed
            },
        )
        .collect();
    let mut shared = vec![[0.0; 3]; layout.shared];
    for &(i, normal) in listed.iter().flatten() {
        add(&mut shared[i as usize], normal);
    }
    // The shared slots: the runs before, between and after the own ranges.
    let mut shared_sums = shared.iter();
    let mut from = 0;
    let ends = layout.owned.iter().map(|&(lo, hi, _)| (lo, hi));
    for (lo, hi) in ends.chain([(slots, slots)]) {
        for (o, &v) in out[from..lo].iter_mut().zip(&mut shared_sums) {
            *o = finish(v);
        }
        from = hi;
    }
    Some(out)
}

/// The largest part of chunk `c`'s span that no other chunk's span and no
/// stray slot reaches (empty when there is none).
fn own_range(spans: &[(usize, usize)], c: usize, strays: &[u32]) -> (usize, usize) {
    let (lo, hi) = spans[c];
    if lo >= hi {
        return (0, 0);
    }
    let mut taken: Vec<(usize, usize)> = (spans.iter().enumerate())
        .filter(|&(d, &(l, h))| d != c && l < hi && lo < h)
        .map(|(_, &span)| span)
        .collect();
    let from = strays.partition_point(|&k| (k as usize) < lo);
    let to = strays.partition_point(|&k| (k as usize) < hi);
    taken.extend(
        strays[from..to]
            .iter()
            .map(|&k| (k as usize, k as usize + 1)),
    );
    taken.sort_unstable();
    let mut best = (0, 0);
    let mut at = lo;
    for (l, h) in taken.into_iter().chain([(hi, hi)]) {
        if l > at && l.min(hi) - at > best.1 - best.0 {
            best = (at, l.min(hi));
        }
        at = at.max(h);
    }
    best
}

/// Where each slot's sum lives: in one chunk's own range, or at an index of
/// the shared sums (the slots outside every own range, in order).
struct Layout {
    /// Non-empty own ranges as (start, end, chunk), sorted.
    owned: Vec<(usize, usize, usize)>,
    /// Per entry of `owned` (and one past the last): the owned slots before it.
    owned_before: Vec<usize>,
    /// Slots outside every own range.
    shared: usize,
}

impl Layout {
    fn new(own: &[(usize, usize)], slots: usize) -> Layout {
        let mut owned: Vec<(usize, usize, usize)> = (own.iter().enumerate())
            .filter(|(_, r)| r.0 < r.1)
            .map(|(c, &(lo, hi))| (lo, hi, c))
            .collect();
        owned.sort_unstable();
        let mut owned_before = vec![0];
        for &(lo, hi, _) in &owned {
            owned_before.push(owned_before[owned_before.len() - 1] + hi - lo);
        }
        let shared = slots - owned_before[owned.len()];
        Layout {
            owned,
            owned_before,
            shared,
        }
    }

    /// The shared index of slot `k`, which no own range holds (a chunk lists
    /// only slots outside its own range, and a slot in another chunk's own
    /// range is in neither its span nor its strays).
    #[inline]
    fn shared_index(&self, k: usize) -> usize {
        let e = self.owned.partition_point(|&(lo, _, _)| lo <= k);
        k - self.owned_before[e]
    }
}

/// The node range `lo..hi` of the slots below `n` in one chunk of corners.
#[inline]
fn span(chunk: &[[u32; 3]], n: usize) -> (usize, usize) {
    let owned = chunk.iter().flatten().filter(|&&s| (s as usize) < n);
    owned.fold((usize::MAX, 0), |(lo, hi), &s| {
        (lo.min(s as usize), hi.max(s as usize + 1))
    })
}

/// Per [`CHUNK`] of triangles, the range of the nodes its corners name,
/// over all of them (`hi` is past the largest): a triangle names a node
/// past `n` exactly when some chunk's `hi > n`.
pub fn node_spans(tris: &[[u32; 3]]) -> Vec<(usize, usize)> {
    tris.par_chunks(CHUNK)
        .map(|chunk| span(chunk, usize::MAX))
        .collect()
}

/// The slots of a mesh of several faces, and the (face, node) pairs of the
/// nodes used by a face after their first, sorted.
fn later_face_slots(
    n: usize,
    tris: &[[u32; 3]],
    tri_face: &[u32],
) -> (Vec<[u32; 3]>, Vec<(u32, u32)>) {
    let owner: Vec<AtomicU32> = (0..n).map(|_| AtomicU32::new(u32::MAX)).collect();
    tris.par_iter().zip(tri_face).for_each(|(t, &f)| {
        for &node in t {
            owner[node as usize].fetch_min(f, Ordering::Relaxed);
        }
    });
    let owner: Vec<u32> = owner.into_iter().map(AtomicU32::into_inner).collect();
    let owner = &owner;
    let mut extra: Vec<(u32, u32)> = tris
        .par_iter()
        .zip(tri_face)
        .flat_map_iter(|(t, &f)| {
            t.iter()
                .filter(move |&&node| owner[node as usize] != f)
                .map(move |&node| (f, node))
        })
        .collect();
    extra.par_sort_unstable();
    extra.dedup();
    let slot = |node: u32, f: u32| -> u32 {
        if owner[node as usize] == f {
            node
        } else {
            // Always found: every pair of a later face was collected.
            (n + extra.binary_search(&(f, node)).unwrap_or_else(|i| i)) as u32
        }
    };
    let slots = tris
        .par_iter()
        .zip(tri_face)
        .map(|(t, &f)| t.map(|node| slot(node, f)))
        .collect();
    (slots, extra)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A bumpy height field of `nx × ny` quads (two triangles each), nodes
    /// numbered row by row, split into two faces at column `nx / 2`.
    fn field(nx: u32, ny: u32) -> (Vec<[f64; 3]>, Vec<[u32; 3]>, Vec<u32>) {
        let mut points = Vec::new();
        for j in 0..=ny {
            for i in 0..=nx {
                let (x, y) = (i as f64 * 0.1, j as f64 * 0.1);
                points.push([x, y, (3.0 * x).sin() * (2.0 * y).cos()]);
            }
        }
        let id = |i: u32, j: u32| j * (nx + 1) + i;
        let mut faces: [Vec<[u32; 3]>; 2] = [Vec::new(), Vec::new()];
        for j in 0..ny {
            for i in 0..nx {
                let f = &mut faces[usize::from(i >= nx / 2)];
                f.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                f.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        let tri_face: Vec<u32> = (0..2)
            .flat_map(|f| std::iter::repeat_n(f as u32, faces[f].len()))
            .collect();
        let tris = faces.concat();
        (points, tris, tri_face)
    }

    /// The plain serial sums: per (face, node), in triangle order.
    fn serial(p: &[[f64; 3]], tris: &[[u32; 3]], tri_face: &[u32]) -> Vec<[[f64; 3]; 3]> {
        let mut sum = std::collections::HashMap::<(u32, u32), [f64; 3]>::new();
        for (t, &f) in tris.iter().zip(tri_face) {
            for &node in t {
                add(sum.entry((f, node)).or_default(), tri_normal(p, *t));
            }
        }
        (tris.iter().zip(tri_face))
            .map(|(t, &f)| t.map(|node| sum[&(f, node)]))
            .collect()
    }

    fn check(points: &[[f64; 3]], tris: &[[u32; 3]], tri_face: &[u32], (nx, ny): (usize, usize)) {
        let (slots, sums) = per_slot(points, tris, tri_face, |v| v);
        let one_face = tri_face.iter().all(|&f| f == 0);
        assert_eq!(slots.is_none(), one_face);
        let slots = slots.unwrap_or_else(|| tris.to_vec());
        let want = serial(points, tris, tri_face);
        assert_eq!(slots.len(), tris.len());
        for (s, w) in slots.iter().zip(&want) {
            for k in 0..3 {
                let got = sums[s[k] as usize];
                // The same bits: added in triangle order, as the serial loop.
                assert_eq!(got.map(f64::to_bits), w[k].map(f64::to_bits));
            }
        }
        // A node on the crease between the faces has one slot per face.
        let distinct: std::collections::HashSet<(u32, u32)> = (tris.iter().zip(&slots))
            .flat_map(|(t, s)| (0..3).map(move |k| (t[k], s[k])))
            .collect();
        let nodes: std::collections::HashSet<u32> = tris.iter().flatten().copied().collect();
        let crease = if one_face { 0 } else { ny + 1 };
        assert_eq!(distinct.len(), nodes.len() + crease);
        assert_eq!(nodes.len(), (nx + 1) * (ny + 1));
    }

    #[test]
    fn chunked_sums_match_serial_sums_per_face() {
        // 60,000 triangles: several chunks, nodes numbered with locality.
        let (points, tris, tri_face) = field(300, 100);
        assert!(tris.len() > 3 * CHUNK);
        check(&points, &tris, &tri_face, (300, 100));
        // As one face: the triangles are their own slots, no crease.
        check(&points, &tris, &vec![0; tris.len()], (300, 100));
    }

    #[test]
    fn a_closing_ring_of_strays_is_summed_in_parallel_in_triangle_order() {
        // Rows wrap around: the last row's triangles name the first row's
        // nodes, so the last chunk would span every node.
        let (points, _, _) = field(400, 100);
        let (nx, ny) = (400u32, 100u32);
        let id = |i: u32, j: u32| j * (nx + 1) + i;
        // The triangles row by row (one face's order), then the closing row.
        let mut tris: Vec<[u32; 3]> = (0..ny)
            .flat_map(|j| (0..nx).map(move |i| (i, j)))
            .flat_map(|(i, j)| {
                [
                    [id(i, j), id(i + 1, j), id(i + 1, j + 1)],
                    [id(i, j), id(i + 1, j + 1), id(i, j + 1)],
                ]
            })
            .collect();
        // Two faces: the first half of the rows, then the rest.
        let half = tris.len() / 2;
        let tri_face: Vec<u32> = (0..tris.len()).map(|t| u32::from(t >= half)).collect();
        // So far apart that the closing triangles are strays.
        assert!(id(0, ny) - id(0, 0) > STRAY_WIDTH);
        let closing: Vec<[u32; 3]> = (0..nx)
            .flat_map(|i| {
                [
                    [id(i, ny), id(i + 1, ny), id(i + 1, 0)],
                    [id(i, ny), id(i + 1, 0), id(i, 0)],
                ]
            })
            .collect();
        tris.extend(&closing);
        let one = vec![0; tris.len()];
        let corner_slots = tris.clone();
        let n = points.len();
        let sums = exact_sums(&points, &tris, &corner_slots, n, n, &|v| v).expect("parallel");
        let mut serial = vec![[0.0; 3]; n];
        for t in &tris {
            for &k in t {
                add(&mut serial[k as usize], tri_normal(&points, *t));
            }
        }
        assert_eq!(sums.len(), n);
        for (got, want) in sums.iter().zip(&serial) {
            assert_eq!(got.map(f64::to_bits), want.map(f64::to_bits));
        }
        // The first row's nodes are summed from two ends of the mesh.
        assert!(serial[id(5, 0) as usize] != [0.0; 3]);
        check_sums(&points, &tris, &one);
        // As two faces: the crease's later-face slots are listed too.
        let two: Vec<u32> = tri_face
            .iter()
            .copied()
            .chain(closing.iter().map(|_| 1))
            .collect();
        check_sums(&points, &tris, &two);
    }

    /// `per_slot`'s sums against the serial ones, bit for bit.
    fn check_sums(points: &[[f64; 3]], tris: &[[u32; 3]], tri_face: &[u32]) {
        let (slots, sums) = per_slot(points, tris, tri_face, |v| v);
        let slots = slots.unwrap_or_else(|| tris.to_vec());
        let want = serial(points, tris, tri_face);
        for (s, w) in slots.iter().zip(&want) {
            for k in 0..3 {
                assert_eq!(
                    sums[s[k] as usize].map(f64::to_bits),
                    w[k].map(f64::to_bits)
                );
            }
        }
    }

    #[test]
    fn nodes_numbered_without_locality_are_summed_serially_alike() {
        let (points, tris, tri_face) = field(400, 100);
        assert!(points.len() > LOCAL_SPAN);
        // Renumber the nodes by a stride coprime to their count.
        let n = points.len() as u64;
        let to = |i: u32| ((i as u64 * 7919) % n) as u32;
        let mut shuffled = vec![[0.0; 3]; points.len()];
        for (i, p) in points.iter().enumerate() {
            shuffled[to(i as u32) as usize] = *p;
        }
        let tris: Vec<[u32; 3]> = tris.iter().map(|t| t.map(to)).collect();
        check(&shuffled, &tris, &tri_face, (400, 100));
    }
}
