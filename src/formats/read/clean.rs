//! How clean a triangle surface is: open edges (one triangle), non-manifold
//! edges (three or more), edges whose two triangles run the same way
//! (inconsistent orientation), and degenerate triangles (a repeated node or no
//! area). Counted for the whole mesh and per face (group), so `inspect` can
//! say which groups are watertight.

use crate::diag::{Code, Diagnostic};
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
    /// One warning per kind of problem, with its count.
    pub fn warnings(&self) -> Vec<Diagnostic> {
        let c = &self.whole;
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
    let whole = if let [only] = &mesh.faces[..] {
        // One group (STL, most single-object files): no copy of its triangles.
        counts(&mesh.nodes, &only.triangles, scale)
    } else {
        let all: Vec<[u32; 3]> = mesh
            .faces
            .iter()
            .flat_map(|f| f.triangles.iter().copied())
            .collect();
        counts(&mesh.nodes, &all, scale)
    };
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

fn diagonal(mesh: &Mesh) -> f64 {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in &mesh.nodes {
        for ((l, h), &v) in lo.iter_mut().zip(hi.iter_mut()).zip(p) {
            *l = l.min(v);
            *h = h.max(v);
        }
    }
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
/// 4 bytes each), then each node's few entries sorted in place. Linear in
/// the mesh, and the same on any thread count.
pub fn counts(nodes: &[[f64; 3]], triangles: &[[u32; 3]], scale: f64) -> EdgeCounts {
    let mut out = EdgeCounts::default();
    let area_floor = (scale * scale) * 1e-14;
    let n = nodes.len();
    // The half-edges of a triangle as (lower node, higher << 1 | direction);
    // edges of repeated or unknown nodes are skipped.
    let halves = |t: &[u32; 3]| {
        [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])]
            .into_iter()
            .filter(move |&(a, b)| a != b && (a as usize) < n && (b as usize) < n)
            .map(|(a, b)| {
                if a < b {
                    (a, b << 1)
                } else {
                    (b, (a << 1) | 1)
                }
            })
    };
    let mut start = vec![0u32; n + 1];
    for t in triangles {
        if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] || twice_area(nodes, *t) <= area_floor {
            out.degenerate += 1;
        }
        for (lo, _) in halves(t) {
            if let Some(c) = start.get_mut(lo as usize + 1) {
                *c += 1;
            }
        }
    }
    for i in 1..start.len() {
        let before = start.get(i - 1).copied().unwrap_or(0);
        if let Some(c) = start.get_mut(i) {
            *c += before;
        }
    }
    let mut fill = start.clone();
    let mut slots = vec![0u32; start.last().copied().unwrap_or(0) as usize];
    for t in triangles {
        for (lo, entry) in halves(t) {
            if let Some(f) = fill.get_mut(lo as usize)
                && let Some(slot) = slots.get_mut(*f as usize)
            {
                *slot = entry;
                *f += 1;
            }
        }
    }
    drop(fill);
    for w in start.windows(2) {
        let &[from, to] = w else {
            continue;
        };
        let Some(bucket) = slots.get_mut(from as usize..to as usize) else {
            continue;
        };
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
            i = j;
        }
    }
    out
}

fn twice_area(nodes: &[[f64; 3]], [a, b, c]: [u32; 3]) -> f64 {
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
    (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt()
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
}
