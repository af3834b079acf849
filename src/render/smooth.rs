//! Smooth-shading normals: for each node of each face, the sum of the
//! area-weighted normals of the face's triangles around it (creases between
//! faces stay sharp). Computed in parallel in a fixed order, so any thread
//! count gives the same sums: triangles are cut into chunks of a fixed size,
//! each chunk sums into a small array over the nodes it touches, and the
//! chunks' partial sums are added in chunk order.

use super::camera::cross;
use super::normal_sum::{Sum, serial_sums};
use rayon::prelude::*;
use std::mem::MaybeUninit;
use std::sync::atomic::{AtomicU32, Ordering};

#[cfg(target_arch = "x86_64")]
mod windowed;

/// Triangles per chunk of partial sums.
pub const CHUNK: usize = 1 << 14;
/// Nodes per block of the final reduction.
const BLOCK: usize = 1 << 12;
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

fn add_to(sum: &mut Sum, n: [f64; 3]) {
    sum.0[0] += n[0];
    sum.0[1] += n[1];
    sum.0[2] += n[2];
}

/// Per triangle corner a slot, and per slot `finish` of the summed normal
/// (the light, for pictures: the sums themselves are never stored; `finish`
/// maps a run of sums to as many values, so it can take them four at a time). A node's slot
/// is its own index in the first face (lowest index) that uses it; the
/// (face, node) pairs of later faces get slots after the nodes, in sorted order.
/// The slots are `None` when they are the triangles' own nodes (one face).
/// `tri_face` must be non-decreasing (triangles grouped by face in face order).
/// `spans`, when given for a one-face mesh, are [`node_spans`] of `tris`
/// (the caller's validity check made them; they are not made twice).
/// The values are written once, into memory not zeroed first.
///
/// # Safety
/// `finish` writes every element of the slice it is given.
pub unsafe fn per_slot<T: Copy + Send + Sync>(
    points: &[[f64; 3]],
    tris: &[[u32; 3]],
    tri_face: &[u32],
    given: Option<&NodeSpans>,
    finish: impl Fn(&[Sum], &mut [MaybeUninit<T>]) + Sync,
) -> (Option<Vec<[u32; 3]>>, Vec<T>) {
    let n = points.len();
    let (own_slots, extra) = if tri_face.first() == tri_face.last() {
        (None, Vec::new())
    } else {
        let (slots, extra) = later_face_slots(n, tris, tri_face);
        (Some(slots), extra)
    };
    let corner_slots: &[[u32; 3]] = own_slots.as_deref().unwrap_or(tris);
    // Each chunk's node range over the corners of its first faces.
    let made;
    let given = given.filter(|g| own_slots.is_none() && g.all_below(tris, n));
    let spans: &[(usize, usize)] = match given {
        Some(given) => given.spans(),
        _ => {
            made = corner_slots
                .par_chunks(CHUNK)
                .map(|chunk| span(chunk, n))
                .collect::<Vec<_>>();
            &made
        }
    };
    let local = spans
        .iter()
        .all(|&(lo, hi)| hi.saturating_sub(lo) <= LOCAL_SPAN);
    if !local {
        #[cfg(target_arch = "x86_64")]
        if let Some(given) = given
            && std::arch::is_x86_feature_detected!("avx2")
        {
            let mut out = Vec::with_capacity(n);
            let to = &mut out.spare_capacity_mut()[..n];
            // SAFETY: the CPU has AVX2 (checked just above), and every
            // node of `tris` is a point (`given` are their spans, all below).
            if unsafe { windowed::light_in_window(points, tris, given.spans(), to, &finish) } {
                // SAFETY: the window gave `finish` every one of the `n`
                // slots, and `finish` writes every slot it is given (the
                // caller's promise).
                unsafe { out.set_len(n) };
                return (own_slots, out);
            }
        }
        let sums = serial_sums(points, tris, corner_slots, n + extra.len(), given);
        let mut out = Vec::with_capacity(sums.len());
        (out.spare_capacity_mut()[..sums.len()].par_chunks_mut(BLOCK))
            .zip(sums.par_chunks(BLOCK))
            .for_each(|(o, s)| finish(s, o));
        // SAFETY: the chunks cover all `sums.len()` slots, and `finish`
        // writes every slot it is given (the caller's promise).
        unsafe { out.set_len(sums.len()) };
        return (own_slots, out);
    }
    // Partial sums per chunk: an array over its node span, and the corners
    // of later faces in order.
    type Partial = (usize, Vec<[f64; 3]>, Vec<(u32, [f64; 3])>);
    let partials: Vec<Partial> = tris
        .par_chunks(CHUNK)
        .zip(corner_slots.par_chunks(CHUNK))
        .zip(spans)
        .map(|((ts, ss), &(lo, hi))| {
            let mut part = vec![[0.0; 3]; hi.saturating_sub(lo)];
            let mut later = Vec::new();
            for (t, s) in ts.iter().zip(ss) {
                let normal = tri_normal(points, *t);
                for &k in s {
                    if (k as usize) < n {
                        add(&mut part[k as usize - lo], normal);
                    } else {
                        later.push((k, normal));
                    }
                }
            }
            (lo, part, later)
        })
        .collect();
    let len = n + extra.len();
    let mut out = Vec::with_capacity(len);
    let (owned, later) = out.spare_capacity_mut()[..len].split_at_mut(n);
    owned.par_chunks_mut(BLOCK).enumerate().for_each_init(
        Vec::new,
        |sums: &mut Vec<Sum>, (b, block)| {
            let (b0, b1) = (b * BLOCK, b * BLOCK + block.len());
            sums.clear();
            sums.resize(block.len(), Sum::default());
            for (lo, part, _) in &partials {
                let (from, to) = (b0.max(*lo), b1.min(lo + part.len()));
                for node in from..to {
                    add_to(&mut sums[node - b0], part[node - lo]);
                }
            }
            finish(sums, block);
        },
    );
    let mut later_sums = vec![Sum::default(); later.len()];
    for (_, _, extra_corners) in &partials {
        for &(k, normal) in extra_corners {
            add_to(&mut later_sums[k as usize - n], normal);
        }
    }
    finish(&later_sums, later);
    // SAFETY: the blocks cover the first `n` slots and `later` the rest,
    // and `finish` writes every slot it is given (the caller's promise).
    unsafe { out.set_len(len) };
    (own_slots, out)
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
/// over all of them (`hi` is past the largest), kept with the triangles
/// they were taken from: only [`node_spans`] makes them, so they are those
/// triangles' spans (borrowed, the triangles cannot change meanwhile).
pub struct NodeSpans<'t> {
    tris: &'t [[u32; 3]],
    spans: Vec<(usize, usize)>,
}

impl NodeSpans<'_> {
    pub fn spans(&self) -> &[(usize, usize)] {
        &self.spans
    }

    /// Whether these are the spans of `tris` (the same slice) and every
    /// corner names a node below `n`: a triangle names a node past `n`
    /// exactly when some chunk's `hi > n`.
    pub fn all_below(&self, tris: &[[u32; 3]], n: usize) -> bool {
        std::ptr::eq(self.tris, tris) && self.spans.iter().all(|&(_, hi)| hi <= n)
    }
}

/// The [`NodeSpans`] of `tris`. For triangles that name no node past the
/// points, these are the spans [`per_slot`] sums one face over.
pub fn node_spans(tris: &[[u32; 3]]) -> NodeSpans<'_> {
    let spans = tris
        .par_chunks(CHUNK)
        .map(|chunk| {
            let (lo, hi) = id_range(chunk.as_flattened());
            (lo as usize, hi as usize + 1)
        })
        .collect();
    NodeSpans { tris, spans }
}

/// The least and greatest id (`u32::MAX` and 0 for none): a plain minimum
/// and maximum (no filter: every id counts), which the compiler turns into
/// vector code; with AVX2, eight ids an instruction (`vpminud`), where the
/// SSE2 of every x86-64 has no unsigned 32-bit minimum to use.
fn id_range(ids: &[u32]) -> (u32, u32) {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has AVX2 (checked just above).
            return unsafe { id_range_avx2(ids) };
        }
    }
    plain_id_range(ids)
}

#[inline(always)]
fn plain_id_range(ids: &[u32]) -> (u32, u32) {
    (ids.iter()).fold((u32::MAX, 0), |(lo, hi), &s| (lo.min(s), hi.max(s)))
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn id_range_avx2(ids: &[u32]) -> (u32, u32) {
    plain_id_range(ids)
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
        let xyz = |s: &[Sum], o: &mut [MaybeUninit<[f64; 3]>]| {
            assert_eq!(o.len(), s.len());
            for (o, s) in o.iter_mut().zip(s) {
                o.write(s.xyz());
            }
        };
        // SAFETY: `xyz` writes every slot it is given.
        let (slots, sums) = unsafe { per_slot(points, tris, tri_face, None, xyz) };
        let one_face = tri_face.iter().all(|&f| f == 0);
        assert_eq!(slots.is_none(), one_face);
        let slots = slots.unwrap_or_else(|| tris.to_vec());
        let want = serial(points, tris, tri_face);
        assert_eq!(slots.len(), tris.len());
        for (s, w) in slots.iter().zip(&want) {
            for k in 0..3 {
                let got = sums[s[k] as usize];
                for c in 0..3 {
                    assert!((got[c] - w[k][c]).abs() < 1e-12, "{got:?} vs {:?}", w[k]);
                }
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
    fn id_ranges_are_the_least_and_greatest_id() {
        let mut rng = crate::test_rng::TestRng::new(0x853c_49e6_748f_ea9b);
        for len in [0, 1, 7, 8, 9, 31, 32, 33, 1000, 4099] {
            let ids: Vec<u32> = (0..len)
                .map(|_| {
                    let state = rng.next_u64();
                    // Ids on both sides of 2^31, where a signed minimum differs.
                    (state >> 20) as u32 ^ if state & 1 == 0 { 0x8000_0000 } else { 0 }
                })
                .collect();
            let want = (
                ids.iter().copied().min().unwrap_or(u32::MAX),
                ids.iter().copied().max().unwrap_or(0),
            );
            assert_eq!(id_range(&ids), want, "{len}");
            assert_eq!(plain_id_range(&ids), want);
        }
        assert_eq!(
            id_range(&[5, 0x8000_0001, 3, 0xffff_fffe]),
            (3, 0xffff_fffe)
        );
    }

    #[test]
    fn node_spans_are_each_chunks_id_range() {
        let (_, mut tris, _) = field(300, 100);
        // A stray id far out in the second chunk, and the last chunk short.
        tris[CHUNK + 5][1] = 4_000_000_000;
        tris.truncate(2 * CHUNK + 7);
        let made = node_spans(&tris);
        let spans = made.spans();
        assert_eq!(spans.len(), 3);
        // The stray id is past the nodes; the spans are only these triangles'.
        assert!(!made.all_below(&tris, 4_000_000_000));
        assert!(made.all_below(&tris, 4_000_000_001));
        assert!(!made.all_below(&tris.clone(), 4_000_000_001));
        for (chunk, &got) in tris.chunks(CHUNK).zip(spans) {
            let ids = chunk.iter().flatten().map(|&i| i as usize);
            let want = (ids.clone().min().unwrap_or(0), ids.max().unwrap_or(0) + 1);
            assert_eq!(got, want);
            assert_eq!(got, span(chunk, usize::MAX));
        }
        assert_eq!(spans[1].1, 4_000_000_001);
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
