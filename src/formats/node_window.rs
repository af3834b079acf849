//! A window of live nodes over triangles taken in order. When a mesh uses its
//! nodes in a sliding range (numbered in first-use order, as STL readers and
//! geomc's own MSH number them), a pass that gathers something per node
//! (edge uses, normal sums) can keep only the nodes still in use, in a ring
//! that stays in the processor's cache, and finish each node once no later
//! triangle uses it: no table as large as the mesh, no page faults for it.

/// Triangles per block: the unit in which the window moves.
pub(crate) const BLOCK: usize = 1024;

/// The plan of a pass over some triangles in blocks of [`BLOCK`].
pub(crate) struct NodeWindow<'t> {
    pub blocks: Vec<&'t [[u32; 3]]>,
    /// `first[b]`: the smallest node of blocks `b` and later. Once block `b`
    /// starts, nodes below it are used by no triangle left.
    pub first: Vec<u32>,
    /// A power of two: the nodes in use while block `b` runs lie in
    /// `first[b]..first[b] + size`, so `node & (size - 1)` gives each its
    /// own ring slot.
    pub size: usize,
}

/// The window over `parts` (in order), or `None` when some block uses a
/// node not below `n` or the window would be wider than `max` nodes.
pub(crate) fn plan<'t>(parts: &[&'t [[u32; 3]]], n: usize, max: usize) -> Option<NodeWindow<'t>> {
    let ranges: Vec<(u32, u32)> = parts.iter().flat_map(|p| block_ranges(p)).collect();
    plan_from(parts, &ranges, n, max)
}

/// The smallest and largest node of each block of [`BLOCK`] triangles, in
/// order: what [`plan`] is made from, which a reader can find once for
/// every pass that needs a plan ([`plan_from`]).
pub(crate) fn block_ranges(triangles: &[[u32; 3]]) -> Vec<(u32, u32)> {
    triangles
        .chunks(BLOCK)
        .map(|b| range(b.as_flattened()))
        .collect()
}

/// [`plan`] from the parts' [`block_ranges`] one after another (`None`
/// also when they are not one range per block of the parts).
pub(crate) fn plan_from<'t>(
    parts: &[&'t [[u32; 3]]],
    ranges: &[(u32, u32)],
    n: usize,
    max: usize,
) -> Option<NodeWindow<'t>> {
    let blocks: Vec<&[[u32; 3]]> = parts.iter().flat_map(|p| p.chunks(BLOCK)).collect();
    if blocks.len() != ranges.len() {
        return None;
    }
    let mut first = Vec::with_capacity(blocks.len());
    let mut span = 0usize;
    let mut smallest = u32::MAX;
    for &(least, largest) in ranges.iter().rev() {
        smallest = smallest.min(least);
        first.push(smallest);
        if largest as usize >= n {
            return None;
        }
        span = span.max((largest - smallest) as usize + 1);
    }
    first.reverse();
    let size = span.next_power_of_two().max(64);
    (size <= max).then_some(NodeWindow {
        blocks,
        first,
        size,
    })
}

/// The smallest and largest of some values (`u32::MAX` and 0 for none), in
/// eight lanes compared as signed numbers: baseline x86-64 has no unsigned
/// 32-bit minimum, and the plain fold ran one value at a time (a third of
/// the plan's time).
fn range(values: &[u32]) -> (u32, u32) {
    const FLIP: u32 = 1 << 31;
    let lanes = values.chunks_exact(8);
    let rest = lanes.remainder();
    let mut lo = [i32::MAX; 8];
    let mut hi = [i32::MIN; 8];
    for lane in lanes {
        for k in 0..8 {
            let v = (lane[k] ^ FLIP) as i32;
            lo[k] = lo[k].min(v);
            hi[k] = hi[k].max(v);
        }
    }
    let unflip = |v: i32| v as u32 ^ FLIP;
    let least = lo.iter().fold(u32::MAX, |m, &v| m.min(unflip(v)));
    let largest = hi.iter().fold(0, |m, &v| m.max(unflip(v)));
    rest.iter()
        .fold((least, largest), |(l, h), &v| (l.min(v), h.max(v)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn window_spans_the_nodes_in_use_and_refuses_a_node_used_again_late() {
        // A strip: triangle i uses nodes i, i + 1, i + 2.
        let strip: Vec<[u32; 3]> = (0..5000).map(|i| [i, i + 1, i + 2]).collect();
        let w = plan(&[&strip], 5002, 1 << 16).expect("a window");
        assert_eq!(w.blocks.len(), 5);
        assert_eq!(w.first, vec![0, 1024, 2048, 3072, 4096]);
        // Block 0 uses nodes 0..=1025 from first 0: 1026 nodes, so 2048.
        assert_eq!(w.size, 2048);
        // Node 0 used again at the end: every block starts at 0.
        let mut late = strip.clone();
        late.push([0, 1, 4000]);
        let w = plan(&[&late], 5002, 1 << 16).expect("a window");
        assert!(w.first.iter().all(|&f| f == 0));
        assert_eq!(w.size, 8192);
        assert!(plan(&[&late], 5002, 4096).is_none());
        // A node not below n.
        assert!(plan(&[&strip], 5001, 1 << 16).is_none());
        // Values on both sides of the sign bit, in lanes and in the rest.
        let values = [7, 1 << 31, u32::MAX, 3, 9, 1 << 30, 5, 8, 2, 0x8000_0001, 4];
        assert_eq!(range(&values), (2, u32::MAX));
        assert_eq!(range(&values[..8]), (3, u32::MAX));
        assert_eq!(range(&[]), (u32::MAX, 0));
    }
}
