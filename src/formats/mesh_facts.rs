//! What a reader learns about the mesh it has just built, for the passes
//! after it: the nodes' bounds (and that every coordinate is finite), and
//! per face its largest node, whether it uses its nodes in first-use order
//! (`groups::FirstUse`) and each block's node range (`node_window`).
//!
//! The reader has to scan the nodes and triangles anyway (no index out of
//! range, no coordinate that is not finite reaches a writer); it finds
//! these on the same passes, while both threads are reading. Without them
//! `convert`'s GLB writer scanned all nodes and triangles again on its own
//! thread (the conversion's critical path), and the checks' thread made its
//! own node-window plan and bounds from the same data.

use super::groups::{Bounds, FirstUse, nodes_scan};
use super::node_window::{BLOCK, block_ranges};
use crate::mesh::Mesh;
use rayon::prelude::*;

/// Facts of one mesh as read. They hold while the mesh is not changed:
/// whoever changes it drops them ([`MeshFacts::fits`] is only a guard
/// against facts of another mesh, not against changed values).
#[derive(Debug, Clone, PartialEq)]
pub struct MeshFacts {
    nodes: usize,
    /// `None` without nodes.
    pub(crate) bounds: Option<Bounds>,
    /// Per face, in the mesh's face order.
    pub(crate) faces: Vec<FaceFacts>,
}

/// One face's triangles, summed up.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct FaceFacts {
    triangles: usize,
    pub(crate) order: FirstUse,
    /// [`block_ranges`] of its triangles.
    pub(crate) blocks: Vec<(u32, u32)>,
}

/// Blocks per parallel piece of [`FaceFacts::of`] (49,152 indices: a
/// piece is summed up twice while it is in the processor's cache).
pub(crate) const PIECE_BLOCKS: usize = 16;

/// Triangles per piece of [`FaceFacts::piece`].
pub(crate) const PIECE_TRIANGLES: usize = BLOCK * PIECE_BLOCKS;

/// One piece of a face's triangles summed up: its first-use summary and
/// its blocks' node ranges.
pub(crate) type FacePiece = (FirstUse, Vec<(u32, u32)>);

impl FaceFacts {
    pub(crate) fn of(triangles: &[[u32; 3]]) -> FaceFacts {
        let pieces: Vec<FacePiece> = triangles
            .par_chunks(PIECE_TRIANGLES)
            .map(FaceFacts::piece)
            .collect();
        FaceFacts::from_pieces(triangles.len(), pieces)
    }

    /// A piece of [`PIECE_TRIANGLES`] triangles (the last one may be
    /// shorter), summed up.
    pub(crate) fn piece(triangles: &[[u32; 3]]) -> FacePiece {
        (
            FirstUse::piece(triangles.as_flattened()),
            block_ranges(triangles),
        )
    }

    /// The facts of `triangles` triangles from their [`FaceFacts::piece`]s,
    /// in order from the first triangle on.
    pub(crate) fn from_pieces(triangles: usize, pieces: Vec<FacePiece>) -> FaceFacts {
        let mut order = FirstUse::default();
        let mut blocks = Vec::with_capacity(triangles.div_ceil(BLOCK));
        for (summary, ranges) in pieces {
            order = order.then(summary);
            blocks.extend(ranges);
        }
        FaceFacts {
            triangles,
            order,
            blocks,
        }
    }

    /// Whether these are facts of as many triangles as `triangles` holds.
    pub(crate) fn counts(&self, triangles: &[[u32; 3]]) -> bool {
        self.triangles == triangles.len()
    }

    /// The largest node index (0 without triangles).
    pub(crate) fn largest(&self) -> u32 {
        self.order.largest()
    }
}

impl MeshFacts {
    /// The facts of `nodes` and of faces with these [`FaceFacts`], or the
    /// index of the first node with a coordinate that is not finite.
    pub(crate) fn of(nodes: &[[f64; 3]], faces: Vec<FaceFacts>) -> Result<MeshFacts, usize> {
        let (bad, bounds) = nodes_scan(nodes);
        if let Some(i) = bad {
            return Err(i);
        }
        Ok(MeshFacts {
            nodes: nodes.len(),
            bounds,
            faces,
        })
    }

    /// The facts of `nodes` nodes whose coordinates are known to be finite,
    /// with these bounds (`None` without nodes).
    pub(crate) fn of_finite(
        nodes: usize,
        bounds: Option<Bounds>,
        faces: Vec<FaceFacts>,
    ) -> MeshFacts {
        MeshFacts {
            nodes,
            bounds,
            faces,
        }
    }

    /// Whether these could be `mesh`'s facts: as many nodes, and the same
    /// faces with as many triangles each.
    pub(crate) fn fits(&self, mesh: &Mesh) -> bool {
        self.nodes == mesh.nodes.len()
            && self.faces.len() == mesh.faces.len()
            && self
                .faces
                .iter()
                .zip(&mesh.faces)
                .all(|(f, face)| f.triangles == face.triangles.len())
    }

    /// Every face's block ranges one after another (the faces' triangles
    /// taken in order as one list of parts).
    pub(crate) fn all_blocks(&self) -> Vec<(u32, u32)> {
        self.faces
            .iter()
            .flat_map(|f| f.blocks.iter().copied())
            .collect()
    }
}

/// The bounds of `nodes` when every coordinate is finite and there are
/// nodes; `None` otherwise.
pub(crate) fn finite_bounds(nodes: &[[f64; 3]]) -> Option<Bounds> {
    let (bad, lo, hi) = nodes.iter().fold(
        (false, [f64::INFINITY; 3], [f64::NEG_INFINITY; 3]),
        |(bad, lo, hi), p| {
            (
                bad | !(p[0].is_finite() & p[1].is_finite() & p[2].is_finite()),
                std::array::from_fn(|k| lo[k].min(p[k])),
                std::array::from_fn(|k| hi[k].max(p[k])),
            )
        },
    );
    (!bad && !nodes.is_empty()).then_some((lo, hi))
}

/// The bounds of two sets of nodes together.
pub(crate) fn merge_bounds(a: Option<Bounds>, b: Option<Bounds>) -> Option<Bounds> {
    match (a, b) {
        (Some((lo, hi)), Some((l, h))) => Some((
            std::array::from_fn(|k| lo[k].min(l[k])),
            std::array::from_fn(|k| hi[k].max(h[k])),
        )),
        (a, b) => a.or(b),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::MeshFace;

    #[test]
    fn a_faces_facts_are_its_largest_node_order_and_block_ranges() {
        // A strip over 40,000 triangles: nodes 0..40,002 in first-use order,
        // three pieces of 16 blocks (the last one short).
        let strip: Vec<[u32; 3]> = (0..40_000).map(|i| [i, i + 1, i + 2]).collect();
        let f = FaceFacts::of(&strip);
        assert_eq!(f.largest(), 40_001);
        assert_eq!(f.order.identity(), Some(40_002));
        assert_eq!(f.blocks.len(), 40);
        assert_eq!(f.blocks[0], (0, 1025));
        assert_eq!(f.blocks[39], (39_936, 40_001));
        assert_eq!(f.blocks, block_ranges(&strip));
        // A node ahead of its turn in the third piece: no first-use order.
        let mut ahead = strip.clone();
        ahead[33_000] = [33_000, 39_000, 33_001];
        let f = FaceFacts::of(&ahead);
        assert_eq!(f.order.identity(), None);
        assert_eq!(f.largest(), 40_001);
        assert_eq!(f.blocks[32], (32_768, 39_000));
        let none = FaceFacts::of(&[]);
        assert_eq!((none.largest(), none.order.identity()), (0, Some(0)));
        assert!(none.blocks.is_empty());
    }

    #[test]
    fn mesh_facts_give_bounds_or_the_first_bad_node_and_fit_their_mesh_only() {
        let nodes = vec![[0.0, -2.0, 1.0], [3.0, 0.5, -1.0], [1.0, 1.0, 4.0]];
        let face = MeshFace {
            name: "s".into(),
            triangles: vec![[0, 1, 2]],
            boundary: Vec::new(),
        };
        let facts =
            MeshFacts::of(&nodes, vec![FaceFacts::of(&face.triangles)]).expect("finite nodes");
        assert_eq!(facts.bounds, Some(([0.0, -2.0, -1.0], [3.0, 1.0, 4.0])));
        let mut mesh = Mesh {
            dimension: 3,
            nodes: nodes.clone(),
            faces: vec![face],
            ..Mesh::default()
        };
        assert!(facts.fits(&mesh));
        mesh.faces[0].triangles.push([2, 1, 0]);
        assert!(!facts.fits(&mesh));
        mesh.faces[0].triangles.pop();
        mesh.nodes.push([0.0; 3]);
        assert!(!facts.fits(&mesh));
        let mut bad = nodes;
        bad[2][1] = f64::NAN;
        assert_eq!(MeshFacts::of(&bad, Vec::new()), Err(2));
    }
}
