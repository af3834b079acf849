//! Edge use counts in a window of live nodes (`formats::node_window`): each
//! node's half-edges (bucketed by their lower node, as in `clean.rs`) are
//! gathered in a small ring of buckets and counted as soon as no later
//! triangle can use the node, instead of bucketing all half-edges at once.
//! The ring stays in the processor's cache, where the counting sort's 28 MB
//! of fresh tables (on 2 million triangles) cost a quarter of the checks'
//! time in page faults alone. Same counts: a bucket
//! holds the same half-edges, only in another order, and `count_bucket`
//! does not depend on the order.

use super::clean::{AreaFloor, EdgeCounts, count_bucket, each_half};

/// Half-edges one ring bucket holds; a node with more goes to the overflow
/// list (a fan's centre). With the length, a bucket is one cache line.
const HELD: usize = 15;

/// Most ring buckets (4 MB): a wider window is left to the counting sort.
const MAX_WINDOW: usize = 1 << 16;

#[derive(Clone, Copy)]
#[repr(C, align(64))]
struct Bucket {
    /// Half-edges given to the bucket, held or not.
    len: u32,
    held: [u32; HELD],
}

/// The counts of `clean::counts_of_parts`, or `None` when the triangles use
/// too wide a range of nodes at once (or a node not below `nodes.len()`).
/// `blocks`: the parts' `node_window::block_ranges` one after another,
/// when known (the plan is then made without a pass over the triangles).
pub(super) fn counts(
    nodes: &[[f64; 3]],
    parts: &[&[[u32; 3]]],
    blocks: Option<&[(u32, u32)]>,
    floor: &AreaFloor,
) -> Option<EdgeCounts> {
    use crate::formats::node_window::{plan, plan_from};
    let n = nodes.len();
    let plan = match blocks {
        Some(ranges) => plan_from(parts, ranges, n, MAX_WINDOW),
        None => plan(parts, n, MAX_WINDOW),
    }?;
    let window = plan.size;
    let mask = window - 1;
    let mut ring = vec![
        Bucket {
            len: 0,
            held: [0; HELD]
        };
        window
    ];
    // Uses of each edge of the bucket being counted, by its higher node.
    let mut uses = vec![0u16; window];
    let mut out = EdgeCounts::default();
    // (lower node << 32 | half-edge) of the nodes with more than `HELD`.
    let mut overflow: Vec<u64> = Vec::new();
    let mut done = 0u32;
    for (b, &start) in plan.blocks.iter().zip(&plan.first) {
        complete(
            &mut ring,
            &mut uses,
            mask,
            done..start,
            &mut out,
            &mut overflow,
        );
        done = done.max(start);
        for t in *b {
            if floor.degenerate(nodes, t) {
                out.degenerate += 1;
            }
            each_half(t, n, |lo, half| {
                if let Some(bucket) = ring.get_mut(lo as usize & mask) {
                    match bucket.held.get_mut(bucket.len as usize) {
                        Some(slot) => *slot = half,
                        None => overflow.push(u64::from(lo) << 32 | u64::from(half)),
                    }
                    bucket.len = bucket.len.saturating_add(1);
                }
            });
        }
    }
    let end = (done as usize + window).min(n) as u32;
    complete(
        &mut ring,
        &mut uses,
        mask,
        done..end,
        &mut out,
        &mut overflow,
    );
    // The overflowing nodes' half-edges, grouped by node.
    overflow.sort_unstable();
    let mut bucket = Vec::new();
    for run in overflow.chunk_by(|a, b| a >> 32 == b >> 32) {
        bucket.clear();
        bucket.extend(run.iter().map(|&h| h as u32));
        count_bucket(&mut bucket, &mut out);
    }
    Some(out)
}

/// Counts the buckets of `nodes` and empties them; a node that overflowed
/// joins its held half-edges to the overflow list.
fn complete(
    ring: &mut [Bucket],
    uses: &mut [u16],
    mask: usize,
    nodes: std::ops::Range<u32>,
    out: &mut EdgeCounts,
    overflow: &mut Vec<u64>,
) {
    for v in nodes {
        let Some(bucket) = ring.get_mut(v as usize & mask) else {
            continue;
        };
        let len = bucket.len as usize;
        if len > HELD {
            overflow.extend(
                bucket
                    .held
                    .iter()
                    .map(|&h| u64::from(v) << 32 | u64::from(h)),
            );
        } else if let Some(held) = bucket.held.get(..len) {
            count_held(held, uses, mask, out);
        }
        bucket.len = 0;
    }
}

/// Adds the edges of one held bucket to the counts, as `count_bucket`
/// would, by tallying each edge's uses in `uses` at its higher node (within
/// the window, so `& mask` keeps the bucket's edges apart): two passes of
/// one table step per half-edge, where the pairwise scan compared every
/// pair (40% of the counting). A bucket of clean edges (each used once
/// each way, as on a closed surface) takes no branch on its values; any
/// other is counted again by `count_bucket`. `uses` is zero before and after.
fn count_held(held: &[u32], uses: &mut [u16], mask: usize, out: &mut EdgeCounts) {
    // Forward uses in the low byte, backward in the high (at most `HELD`).
    for &h in held {
        if let Some(u) = uses.get_mut((h >> 1) as usize & mask) {
            *u += 1 << ((h & 1) * 8);
        }
    }
    let mut edges = 0usize;
    // Non-zero when some edge was not used once each way.
    let mut unclean = 0u32;
    for &h in held {
        if let Some(u) = uses.get_mut((h >> 1) as usize & mask) {
            // An edge's first half-edge takes its tally, the others find zero.
            let n = u32::from(std::mem::take(u));
            edges += usize::from(n != 0);
            unclean |= n * (n ^ 0x0101);
        }
    }
    if unclean == 0 {
        out.edges += edges;
    } else {
        let mut copy = [0u32; HELD];
        if let Some(copy) = copy.get_mut(..held.len()) {
            copy.copy_from_slice(held);
            count_bucket(copy, out);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::clean::counts_by_sort;
    use super::*;
    use crate::formats::node_window::block_ranges;

    /// Held buckets of repeated edges in both directions (clean pairs,
    /// open edges, same-way pairs, edges used three to five times) counted
    /// by the tallies and by `count_bucket` give the same counts, and the
    /// tallies are left zero.
    #[test]
    fn held_bucket_tallies_equal_the_pairwise_scan() {
        let mask = 4095usize;
        let mut uses = vec![0u16; mask + 1];
        let mut state = 12345u64;
        let mut next = |m: u64| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 33) % m
        };
        let mut total = (EdgeCounts::default(), EdgeCounts::default());
        for round in 0..2000u32 {
            // Node v's bucket: higher nodes within the window above v.
            let v = 100_000 + round * 7;
            let len = 1 + next(HELD as u64) as usize;
            let keys: Vec<u32> = (0..3)
                .map(|_| v + 1 + next(mask as u64 - 1) as u32)
                .collect();
            let held: Vec<u32> = (0..len)
                .map(|_| keys[next(3) as usize] << 1 | next(2) as u32)
                .collect();
            count_held(&held, &mut uses, mask, &mut total.0);
            count_bucket(&mut held.clone(), &mut total.1);
            assert!(uses.iter().all(|&u| u == 0));
        }
        assert_eq!(total.0, total.1);
        let c = &total.0;
        assert!(c.open > 0 && c.non_manifold > 0 && c.inconsistent > 0 && c.edges > 2000);
        // A clean pair, an open edge and a same-way pair: three edges.
        let mut one = EdgeCounts::default();
        count_held(
            &[10 << 1, 12 << 1, 10 << 1 | 1, 11 << 1, 11 << 1],
            &mut uses,
            mask,
            &mut one,
        );
        assert_eq!(
            (one.edges, one.open, one.inconsistent, one.non_manifold),
            (3, 1, 1, 0)
        );
    }

    /// A strip of quads along x, numbered in first-use order, closed into a
    /// tube and capped by fans (each fan's centre overflows its bucket):
    /// window and counting sort give the same counts, with a flipped
    /// triangle and a duplicated one too.
    #[test]
    fn window_counts_equal_the_counting_sort() {
        let ring = 40u32;
        let rows = 300u32;
        let mut nodes = Vec::new();
        for r in 0..rows {
            for k in 0..ring {
                let a = std::f64::consts::TAU * f64::from(k) / f64::from(ring);
                nodes.push([a.cos(), a.sin(), f64::from(r) * 0.1]);
            }
        }
        let id = |r: u32, k: u32| r * ring + k % ring;
        let mut tris = Vec::new();
        for r in 0..rows - 1 {
            for k in 0..ring {
                tris.push([id(r, k), id(r, k + 1), id(r + 1, k + 1)]);
                tris.push([id(r, k), id(r + 1, k + 1), id(r + 1, k)]);
            }
        }
        let top = nodes.len() as u32;
        nodes.push([0.0, 0.0, f64::from(rows) * 0.1]);
        for k in 0..ring {
            tris.push([id(rows - 1, k), id(rows - 1, k + 1), top]);
        }
        let floor = AreaFloor::of(30.0);
        let by_window =
            |tris: &[[u32; 3]]| counts(&nodes, &[tris], None, &floor).expect("a window");
        let by_sort = |tris: &[[u32; 3]]| counts_by_sort(&nodes, &[tris], &floor);
        let whole = by_window(&tris);
        assert_eq!(whole, by_sort(&tris));
        // The bottom rim is open (40 edges), the rest closed and consistent.
        assert_eq!(
            (
                whole.edges,
                whole.open,
                whole.non_manifold,
                whole.inconsistent
            ),
            (3 * 40 * 299 + 40 + 40, 40, 0, 0)
        );
        let mut changed = tris.clone();
        changed[100] = [changed[100][0], changed[100][2], changed[100][1]];
        changed.insert(5000, changed[5000]);
        changed.push([top, top, 3]);
        let c = by_window(&changed);
        assert_eq!(c, by_sort(&changed));
        assert_eq!((c.inconsistent, c.non_manifold, c.degenerate), (3, 3, 1));
        // Split into parts: the same counts as together.
        let (a, b) = changed.split_at(7777);
        assert_eq!(counts(&nodes, &[a, b], None, &floor), Some(c.clone()));
        // With the parts' block ranges known: the same counts.
        let known = [block_ranges(a), block_ranges(b)].concat();
        assert_eq!(counts(&nodes, &[a, b], Some(&known), &floor), Some(c));
        // A node used again far later needs a window wider than allowed.
        let far = nodes.len();
        nodes.extend((0..MAX_WINDOW as u32 + 10).map(|i| [f64::from(i), 1.0, 2.0]));
        let mut wide = vec![[0, 1, 2]];
        wide.extend((far..far + MAX_WINDOW).map(|i| [i as u32, i as u32 + 1, i as u32 + 2]));
        wide.push([0, 2, 3]);
        assert_eq!(counts(&nodes, &[&wide], None, &floor), None);
        // Without the first and last triangles the window is narrow again.
        let strip = &wide[1..wide.len() - 1];
        let narrow = counts(&nodes, &[strip], None, &floor).expect("a window");
        assert_eq!(narrow, counts_by_sort(&nodes, &[strip], &floor));
        // Edges (i, i + 1) and (i, i + 2); neighbours run the same way along
        // the first kind, the second kind and both ends are open.
        let m = MAX_WINDOW;
        assert_eq!(
            (narrow.edges, narrow.open, narrow.inconsistent),
            (2 * m + 1, m + 2, m - 1)
        );
    }
}
