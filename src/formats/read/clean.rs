//! How clean a triangle surface is: open edges (one triangle), non-manifold
//! edges (three or more), edges whose two triangles run the same way
//! (inconsistent orientation), and degenerate triangles (a repeated node or no
//! area). Counted for the whole mesh and per face (group), so `inspect` can
//! say which groups are watertight.

use crate::diag::{Code, Diagnostic};
use crate::formats::MeshFacts;
use crate::mesh::Mesh;

#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct EdgeCounts {
    pub edges: usize,
    pub open: usize,
    pub non_manifold: usize,
    pub inconsistent: usize,
    pub degenerate: usize,
}

impl EdgeCounts {
    /// Closed and 2-manifold with consistent orientation.
    pub fn watertight(&self) -> bool {
        self.edges > 0 && self.open == 0 && self.non_manifold == 0 && self.inconsistent == 0
    }
}

#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct CleanReport {
    pub whole: EdgeCounts,
    /// Per mesh face (group), in face order.
    pub faces: Vec<EdgeCounts>,
}

impl CleanReport {
    /// One warning per kind of problem in the whole mesh, with its count.
    pub fn warnings(&self) -> Vec<Diagnostic> {
        self.whole.warnings()
    }
}

impl EdgeCounts {
    /// One warning per kind of problem, with its count.
    pub fn warnings(&self) -> Vec<Diagnostic> {
        let c = self;
        let mut out = Vec::new();
        let mut push = |code: Code, n: usize, what: &str, help: &str| {
            if n > 0 {
                out.push(Diagnostic::new(code, None, format!("{n} {what}")).with_help(help));
            }
        };
        push(
            Code::OpenEdges,
            c.open,
            "open edges (used by one triangle): the surface has holes or is not closed",
            "`geomc inspect` lists which groups are open; --weld EPS merges nodes that only nearly coincide",
        );
        push(
            Code::NonManifoldEdges,
            c.non_manifold,
            "non-manifold edges (used by three or more triangles)",
            "solvers that need a closed 2-manifold reject these; separate the surfaces that meet there",
        );
        push(
            Code::MeshInconsistentOrientation,
            c.inconsistent,
            "edges whose two triangles are oriented inconsistently",
            "--normals orients every connected surface consistently (outward when closed)",
        );
        push(
            Code::DegenerateTriangles,
            c.degenerate,
            "degenerate triangles (a repeated node or zero area)",
            "--weld EPS removes triangles that collapse when nearby nodes merge",
        );
        out
    }
}

/// The checks of a whole mesh and of each face.
pub fn check(mesh: &Mesh) -> CleanReport {
    let scale = diagonal(mesh);
    let whole = whole_counts(mesh, scale, None);
    let faces = if mesh.faces.len() == 1 {
        vec![whole.clone()]
    } else {
        mesh.faces
            .iter()
            .map(|f| counts(&mesh.nodes, &f.triangles, scale))
            .collect()
    };
    CleanReport { whole, faces }
}

/// The checks of the whole mesh only (what `convert`'s warnings say), without
/// the per-face counts of [`check`].
pub fn check_whole(mesh: &Mesh) -> EdgeCounts {
    whole_counts(mesh, diagonal(mesh), None)
}

/// [`check_whole`] of a mesh as a reader left it: the bounds and the
/// node-window plan's block ranges come from the reader's `facts` instead
/// of passes over the nodes and triangles (facts that do not fit the mesh
/// are not used). The same counts.
pub fn check_whole_known(mesh: &Mesh, facts: &MeshFacts) -> EdgeCounts {
    if !facts.fits(mesh) {
        return check_whole(mesh);
    }
    let scale = facts
        .bounds
        .map_or(0.0, |(lo, hi)| diagonal_of_bounds(lo, hi));
    whole_counts(mesh, scale, Some(&facts.all_blocks()))
}

/// The counts over all faces' triangles together, read in place.
fn whole_counts(mesh: &Mesh, scale: f64, blocks: Option<&[(u32, u32)]>) -> EdgeCounts {
    let parts: Vec<&[[u32; 3]]> = mesh.faces.iter().map(|f| f.triangles.as_slice()).collect();
    counts_of_parts(&mesh.nodes, &parts, scale, blocks)
}

fn diagonal(mesh: &Mesh) -> f64 {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in &mesh.nodes {
        for ((l, h), &v) in lo.iter_mut().zip(hi.iter_mut()).zip(p) {
            *l = l.min(v);
            *h = h.max(v);
        }
    }
    diagonal_of_bounds(lo, hi)
}

/// The length of the bounds' diagonal, 0 when it is not finite (no nodes).
fn diagonal_of_bounds(lo: [f64; 3], hi: [f64; 3]) -> f64 {
    let d: f64 = lo
        .iter()
        .zip(&hi)
        .map(|(l, h)| (h - l).powi(2))
        .sum::<f64>()
        .sqrt();
    if d.is_finite() { d } else { 0.0 }
}

/// Edge use counts: half-edges bucketed by their lower node (a counting
/// sort: two passes over the triangles, `(higher << 1) | direction` in
/// 4 bytes each), then each node's few entries grouped by edge. Linear in
/// the mesh, and the same on any thread count.
pub fn counts(nodes: &[[f64; 3]], triangles: &[[u32; 3]], scale: f64) -> EdgeCounts {
    counts_of_parts(nodes, &[triangles], scale, None)
}

/// [`counts`] of the triangles of several lists together: in a window of
/// live nodes when the triangles allow one (see `window.rs`), else by a
/// counting sort of all half-edges.
fn counts_of_parts(
    nodes: &[[f64; 3]],
    parts: &[&[[u32; 3]]],
    scale: f64,
    blocks: Option<&[(u32, u32)]>,
) -> EdgeCounts {
    let floor = AreaFloor::of(scale);
    if let Some(counts) = super::clean_window::counts(nodes, parts, blocks, &floor) {
        return counts;
    }
    counts_by_sort(nodes, parts, &floor)
}

/// The degenerate-triangle test's floor on twice the area.
pub(super) struct AreaFloor {
    floor: f64,
    /// Above this squared area the square root cannot be at or under the
    /// floor (the margin covers the rounding of the square): most triangles
    /// skip it.
    clearly_above: f64,
}

impl AreaFloor {
    pub(super) fn of(scale: f64) -> AreaFloor {
        let floor = (scale * scale) * 1e-14;
        let floor_squared = floor * floor;
        let clearly_above = if floor_squared.is_normal() {
            floor_squared * (1.0 + 1e-9)
        } else {
            f64::INFINITY
        };
        AreaFloor {
            floor,
            clearly_above,
        }
    }

    /// A repeated node or no area.
    #[inline(always)]
    pub(super) fn degenerate(&self, nodes: &[[f64; 3]], t: &[u32; 3]) -> bool {
        t[0] == t[1]
            || t[1] == t[2]
            || t[0] == t[2]
            || twice_area_at_most(nodes, *t, self.floor, self.clearly_above)
    }
}

/// Edge use counts of all half-edges bucketed at once (any triangle order).
pub(super) fn counts_by_sort(
    nodes: &[[f64; 3]],
    parts: &[&[[u32; 3]]],
    floor: &AreaFloor,
) -> EdgeCounts {
    let mut out = EdgeCounts::default();
    let n = nodes.len();
    // `end[v + 1]` counts node v's half-edges, then (prefix sums) ends its
    // bucket; filling steps each end back, so `end[v + 1]` finally starts
    // bucket v and `end[v + 2]` ends it (one table, no copy for the fill).
    // Counts read before written: zeroed by writing (see `filled_vec`).
    let mut end = crate::allocator::filled_vec(n + 2, 0u32);
    for t in parts.iter().copied().flatten() {
        if floor.degenerate(nodes, t) {
            out.degenerate += 1;
        }
        each_half(t, n, |lo, _| {
            if let Some(c) = end.get_mut(lo as usize + 1) {
                *c += 1;
            }
        });
    }
    for i in 1..end.len() {
        let before = end.get(i - 1).copied().unwrap_or(0);
        if let Some(c) = end.get_mut(i) {
            *c += before;
        }
    }
    let mut slots = vec![0u32; end.last().copied().unwrap_or(0) as usize];
    for t in parts.iter().copied().flatten() {
        each_half(t, n, |lo, entry| {
            if let Some(e) = end.get_mut(lo as usize + 1) {
                *e = e.saturating_sub(1);
                if let Some(slot) = slots.get_mut(*e as usize) {
                    *slot = entry;
                }
            }
        });
    }
    for w in end.get(1..).unwrap_or_default().windows(2) {
        let &[from, to] = w else {
            continue;
        };
        if let Some(bucket) = slots.get_mut(from as usize..to as usize) {
            count_bucket(bucket, &mut out);
        }
    }
    out
}

/// Calls `f(lower node, higher << 1 | direction)` for each half-edge of a
/// triangle, skipping edges of a repeated node or of a node not below `n`.
/// Three plain calls: the iterator chain this replaced (an array, a filter,
/// a map) kept its state on the stack in the two hottest loops.
#[inline(always)]
pub(super) fn each_half(&[a, b, c]: &[u32; 3], n: usize, mut f: impl FnMut(u32, u32)) {
    let mut half = |x: u32, y: u32| {
        if x != y && (x as usize) < n && (y as usize) < n {
            // Chosen without a branch: which way an edge runs is a coin
            // toss on a consistently oriented surface, so a branch on it
            // was mispredicted half the time.
            let (lo, hi) = if x < y { (x, y) } else { (y, x) };
            f(lo, (hi << 1) | u32::from(x > y));
        }
    };
    half(a, b);
    half(b, c);
    half(c, a);
}

/// Adds the edges of one node's bucket to the counts. A bucket holds a few
/// entries (about six on a closed surface): up to 32 are grouped by a
/// pairwise scan with a bit mask of those already counted, larger ones sorted.
pub(super) fn count_bucket(bucket: &mut [u32], out: &mut EdgeCounts) {
    if bucket.len() > 32 {
        bucket.sort_unstable();
        let mut i = 0;
        while let Some(&first) = bucket.get(i) {
            let key = first >> 1;
            let mut j = i;
            let (mut forward, mut backward) = (0usize, 0usize);
            while let Some(&h) = bucket.get(j).filter(|&&h| h >> 1 == key) {
                if h & 1 == 0 {
                    forward += 1;
                } else {
                    backward += 1;
                }
                j += 1;
            }
            tally(forward, backward, out);
            i = j;
        }
        return;
    }
    let mut counted = 0u32;
    for (i, &h) in bucket.iter().enumerate() {
        if counted & (1 << i) != 0 {
            continue;
        }
        let key = h >> 1;
        let (mut forward, mut backward) = (0usize, 0usize);
        for (j, &g) in bucket.iter().enumerate().skip(i) {
            if g >> 1 == key {
                counted |= 1 << j;
                if g & 1 == 0 {
                    forward += 1;
                } else {
                    backward += 1;
                }
            }
        }
        tally(forward, backward, out);
    }
}

/// One edge used `forward` times in its direction and `backward` against it.
fn tally(forward: usize, backward: usize, out: &mut EdgeCounts) {
    out.edges += 1;
    match forward + backward {
        1 => out.open += 1,
        2 => {
            if forward != 1 {
                out.inconsistent += 1;
            }
        }
        _ => out.non_manifold += 1,
    }
}

/// `twice_area(..) <= floor`, without the square root when the squared
/// area is clearly above `floor²` (`clearly_above`).
fn twice_area_at_most(nodes: &[[f64; 3]], t: [u32; 3], floor: f64, clearly_above: f64) -> bool {
    let squared = twice_area_squared(nodes, t);
    if squared > clearly_above {
        return false;
    }
    squared.sqrt() <= floor
}

fn twice_area_squared(nodes: &[[f64; 3]], [a, b, c]: [u32; 3]) -> f64 {
    let (Some(p), Some(q), Some(r)) = (
        nodes.get(a as usize),
        nodes.get(b as usize),
        nodes.get(c as usize),
    ) else {
        return 0.0;
    };
    let u = [q[0] - p[0], q[1] - p[1], q[2] - p[2]];
    let v = [r[0] - p[0], r[1] - p[1], r[2] - p[2]];
    let n = [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ];
    n[0] * n[0] + n[1] * n[1] + n[2] * n[2]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tetrahedron_is_watertight_and_a_flipped_face_is_not_consistent() {
        let nodes = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ];
        let mut tris = vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]];
        let c = counts(&nodes, &tris, 1.7);
        assert_eq!((c.edges, c.open, c.inconsistent), (6, 0, 0));
        assert!(c.watertight());
        tris[0] = [0, 1, 2];
        let c = counts(&nodes, &tris, 1.7);
        assert_eq!(c.inconsistent, 3);
        let c = counts(&nodes, &tris[..3], 1.7);
        assert_eq!(c.open, 3);
        let c = counts(&nodes, &[[0, 1, 1], [0, 1, 2]], 1.7);
        assert_eq!(c.degenerate, 1);
    }

    /// A double cone of 40 segments: the apex's bucket holds 80 half-edges
    /// (the sorting path), the rim nodes' a few (the scanning path).
    #[test]
    fn double_cone_counts_edges_through_both_bucket_paths() {
        let segments = 40u32;
        let mut nodes = vec![[0.0, 0.0, 1.0]];
        for i in 0..segments {
            let a = std::f64::consts::TAU * f64::from(i) / f64::from(segments);
            nodes.push([a.cos(), a.sin(), 0.0]);
        }
        nodes.push([0.0, 0.0, -1.0]);
        let rim = |i: u32| 1 + i % segments;
        let mut tris = Vec::new();
        for i in 0..segments {
            tris.push([0, rim(i), rim(i + 1)]);
            tris.push([segments + 1, rim(i + 1), rim(i)]);
        }
        let c = counts(&nodes, &tris, 2.8);
        assert_eq!(
            (c.edges, c.open, c.non_manifold, c.inconsistent),
            (120, 0, 0, 0)
        );
        assert!(c.watertight());
        // One apex triangle reversed: its three edges run like their neighbours'.
        tris[0] = [0, rim(1), rim(0)];
        let c = counts(&nodes, &tris, 2.8);
        assert_eq!((c.edges, c.inconsistent), (120, 3));
        tris[0] = [0, rim(0), rim(1)];
        // A triangle given twice: its edges are used three times.
        tris.push([0, rim(5), rim(6)]);
        let c = counts(&nodes, &tris, 2.8);
        assert_eq!((c.edges, c.non_manifold, c.open), (120, 3, 0));
        // Without the duplicate and the bottom: the 40 rim edges are open.
        tris.pop();
        let top: Vec<[u32; 3]> = tris.iter().step_by(2).copied().collect();
        let c = counts(&nodes, &top, 2.8);
        assert_eq!((c.edges, c.open, c.non_manifold), (80, 40, 0));
    }

    #[test]
    fn degenerate_test_without_the_root_agrees_near_the_floor() {
        // Twice the area of this right triangle is exactly 2 * 2^-40 = 2^-39.
        let h = 2f64.powi(-20);
        let nodes = [[0.0, 0.0, 0.0], [2.0 * h, 0.0, 0.0], [0.0, h, 0.0]];
        let tri = [[0, 1, 2]];
        let floor = |scale: f64| scale * scale * 1e-14;
        // Scale with the floor exactly at the area, just below and just above.
        let at = (2f64.powi(-39) / 1e-14).sqrt();
        for (scale, degenerate) in [(at * 1.001, 1), (at * 0.999, 0), (at * 0.9999999999, 0)] {
            let c = counts(&nodes, &tri, scale);
            let expected = usize::from(2f64.powi(-39) <= floor(scale));
            assert_eq!(c.degenerate, expected, "scale {scale}");
            assert_eq!(c.degenerate, degenerate, "scale {scale}");
        }
    }
}
