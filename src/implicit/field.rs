//! The polygonizer's sampled field, block-sparse.
//!
//! The grid is cut into blocks of 8³ samples. Interval arithmetic proves
//! most blocks entirely inside or outside (their samples are ±1 and are
//! never evaluated nor stored); each remaining block gets its own simplified
//! program (`interval::simplify`) and its 512 samples are stored together.
//! Why: on the benchmark models 70–91% of the blocks are proven, and a
//! dense 257³ grid (68 MB) cost more in page faults, filling with ±1 and
//! packing signs than the evaluation of the mixed blocks itself. The values
//! are the ones the dense grid held (same programs, same rows, same ±1 and
//! box capping), so the mesh is bit-identical.
//!
//! Given samples (a density volume, `polygonize_samples`) keep the caller's
//! dense buffer.

use super::interval::{self, Interval, Sign};
use super::polygonize::{Grid, Options};
use super::row_blocks::BlockScratch;
use super::rows::RowTape;
use super::signs::SignRows;
use super::tape::{AxisTape, Ssa, Tape};
use rayon::prelude::*;
use std::sync::Arc;

/// Samples per block edge.
pub(super) const BS: usize = 8;
/// Samples per stored block.
const BLOCK_LEN: usize = BS * BS * BS;
/// `slot` of a block whose samples are not stored.
const NOT_STORED: u32 = u32::MAX;

/// What a block's samples need: the f64 tape refines crossings, the row
/// tape samples the grid. Blocks whose simplified programs are equal share
/// one kernel (`id` indexes `Field::kernels`).
pub(super) struct Kernel {
    pub id: u32,
    pub tape: Tape,
    /// The tape split along x, y and z for root finding on grid edges.
    pub along: [AxisTape; 3],
    pub rows: RowTape,
}

impl Kernel {
    fn new(ssa: &Ssa, id: u32) -> Kernel {
        Kernel {
            id,
            tape: Tape::new(ssa),
            along: [0, 1, 2].map(|a| AxisTape::new(ssa, a)),
            rows: RowTape::new(ssa),
        }
    }
}

#[derive(Clone)]
pub(super) enum Block {
    Inside,
    Outside,
    Mixed(Arc<Kernel>),
    /// Given samples without a function: vertices by linear interpolation.
    Sampled,
}

enum Samples {
    /// One value per grid point, x fastest, then y, then z.
    Dense(Vec<f32>),
    /// `BLOCK_LEN` values per stored block (x fastest within the block),
    /// block b's at `slot[b]`; the other blocks' samples are ±1.
    Blocks { slot: Vec<u32>, data: Vec<f32> },
}

pub(super) struct Field {
    pub n1: [usize; 3],
    pub nb: [usize; 3],
    pub blocks: Vec<Block>,
    /// The distinct kernels of the mixed blocks, by `Kernel::id`.
    pub kernels: Vec<Arc<Kernel>>,
    samples: Samples,
}

impl Field {
    /// Given samples (one per grid point), capped at the box when asked.
    pub fn dense(values: Vec<f32>, n1: [usize; 3], options: &Options) -> Field {
        let nb = n1.map(|n| n.div_ceil(BS));
        let mut values = values;
        if options.close_at_box {
            close_dense_at_box(&mut values, n1);
        }
        Field {
            n1,
            nb,
            blocks: vec![Block::Sampled; nb[0] * nb[1] * nb[2]],
            kernels: Vec::new(),
            samples: Samples::Dense(values),
        }
    }

    /// The given samples back (empty for a sampled function's field).
    pub fn into_dense(self) -> Vec<f32> {
        match self.samples {
            Samples::Dense(values) => values,
            Samples::Blocks { .. } => Vec::new(),
        }
    }

    fn block_index(&self, i: usize, j: usize, k: usize) -> usize {
        ((k / BS) * self.nb[1] + j / BS) * self.nb[0] + i / BS
    }

    pub fn block(&self, i: usize, j: usize, k: usize) -> &Block {
        &self.blocks[self.block_index(i, j, k)]
    }

    /// The sample at grid point (i, j, k).
    #[inline]
    pub fn value(&self, i: usize, j: usize, k: usize) -> f32 {
        match &self.samples {
            Samples::Dense(values) => values[(k * self.n1[1] + j) * self.n1[0] + i],
            Samples::Blocks { slot, data } => {
                let b = self.block_index(i, j, k);
                match slot[b] {
                    NOT_STORED => constant(&self.blocks[b]),
                    s => data[s as usize * BLOCK_LEN + local(i, j, k)],
                }
            }
        }
    }

    /// The inside/outside bits of every sample.
    pub fn signs(&self) -> SignRows {
        let (slot, data) = match &self.samples {
            Samples::Dense(values) => return SignRows::new(values, self.n1),
            Samples::Blocks { slot, data } => (slot, data),
        };
        let (n1, nb) = (self.n1, self.nb);
        SignRows::from_rows(n1, |j, k, row| {
            let first = ((k / BS) * nb[1] + j / BS) * nb[0];
            let at = local(0, j, k);
            for bi in 0..nb[0] {
                let len = (n1[0] - bi * BS).min(BS);
                let b = first + bi;
                let byte = match slot[b] {
                    NOT_STORED => match self.blocks[b] {
                        Block::Inside => u64::MAX,
                        _ => 0,
                    },
                    s => {
                        let eight = &data[s as usize * BLOCK_LEN + at..][..BS];
                        eight
                            .iter()
                            .enumerate()
                            .fold(0u64, |m, (c, &v)| m | (u64::from(v > 0.0) << c))
                    }
                };
                // Bits past the row stay 0.
                let byte = byte & ((1u64 << len) - 1);
                row[bi * BS / 64] |= byte << (bi * BS % 64);
            }
        })
    }
}

/// The value of every sample of a block not stored.
fn constant(block: &Block) -> f32 {
    match block {
        Block::Inside => 1.0,
        _ => -1.0,
    }
}

/// The index of grid point (i, j, k) within its block's samples.
#[inline]
fn local(i: usize, j: usize, k: usize) -> usize {
    ((k % BS) * BS + j % BS) * BS + i % BS
}

/// A block range [lo, hi) per axis of the block grid.
type Region = ([usize; 3], [usize; 3]);

/// A classified block: proven (`Inside`/`Outside`), or mixed with its
/// simplified program (the kernels are built once per distinct program).
enum Leaf {
    Proven(Block),
    Mixed(Ssa),
}

/// Classifies the blocks of `region` by interval arithmetic, recursively
/// halving the region and simplifying the program on the way down, so a
/// leaf block sees only the few union branches active near it (M3's
/// 1,000-ball chain shrinks to a handful). Returns (block index, leaf).
fn classify_region(
    ssa: &Ssa,
    region: Region,
    coords: &[Vec<f64>; 3],
    nb: [usize; 3],
    out: &mut Vec<(usize, Leaf)>,
) {
    let (lo, hi) = region;
    let n1 = [coords[0].len(), coords[1].len(), coords[2].len()];
    let bounds = [0, 1, 2].map(|a| {
        let top = (hi[a] * BS).min(n1[a] - 1);
        Interval::new(coords[a][lo[a] * BS], coords[a][top])
    });
    let sign = interval::sign_only(ssa);
    let iv = interval::eval(ssa, &sign, bounds);
    let fill = |block: Block, out: &mut Vec<(usize, Leaf)>| {
        for k in lo[2]..hi[2] {
            for j in lo[1]..hi[1] {
                for i in lo[0]..hi[0] {
                    out.push(((k * nb[1] + j) * nb[0] + i, Leaf::Proven(block.clone())));
                }
            }
        }
    };
    match interval::classify(iv[ssa.root()]) {
        Sign::Inside => return fill(Block::Inside, out),
        Sign::Outside => return fill(Block::Outside, out),
        Sign::Ambiguous => {}
    }
    let simpler = interval::simplify(ssa, &sign, &iv);
    let extent = [0, 1, 2].map(|a| hi[a] - lo[a]);
    let axis = (0..3).max_by_key(|&a| (extent[a], a)).unwrap_or(0);
    if extent[axis] <= 1 {
        let at = (lo[2] * nb[1] + lo[1]) * nb[0] + lo[0];
        return out.push((at, Leaf::Mixed(simpler)));
    }
    let mid = lo[axis] + extent[axis] / 2;
    let (mut a_hi, mut b_lo) = (hi, lo);
    a_hi[axis] = mid;
    b_lo[axis] = mid;
    if extent.iter().product::<usize>() >= 64 {
        let (mut left, mut right) = (Vec::new(), Vec::new());
        rayon::join(
            || classify_region(&simpler, (lo, a_hi), coords, nb, &mut left),
            || classify_region(&simpler, (b_lo, hi), coords, nb, &mut right),
        );
        out.extend(left);
        out.extend(right);
    } else {
        classify_region(&simpler, (lo, a_hi), coords, nb, out);
        classify_region(&simpler, (b_lo, hi), coords, nb, out);
    }
}

/// Samples `ssa` on the grid: blocks classified by interval arithmetic
/// (`classify_region`), the samples of the mixed blocks evaluated on their
/// own programs, all of a block's rows together (`RowTape::eval_block`), and of the proven-inside blocks on the box faces
/// (which `close_at_box` caps) stored as 1 capped; nothing else is stored.
pub(super) fn sample_field(ssa: &Ssa, grid: &Grid, options: &Options) -> Field {
    let coords = [grid.coords(0), grid.coords(1), grid.coords(2)];
    let n1 = [coords[0].len(), coords[1].len(), coords[2].len()];
    let nb = [n1[0].div_ceil(BS), n1[1].div_ceil(BS), n1[2].div_ceil(BS)];
    let mut blocks = vec![Block::Outside; nb[0] * nb[1] * nb[2]];
    let kernels = if options.prune {
        let mut found = Vec::with_capacity(blocks.len());
        classify_region(ssa, ([0; 3], nb), &coords, nb, &mut found);
        share_kernels(&found, &mut blocks)
    } else {
        let kernel = Arc::new(Kernel::new(ssa, 0));
        blocks.fill(Block::Mixed(kernel.clone()));
        vec![kernel]
    };
    let on_box = |b: usize| {
        let at = [b % nb[0], b / nb[0] % nb[1], b / (nb[0] * nb[1])];
        (0..3).any(|a| at[a] == 0 || at[a] == nb[a] - 1)
    };
    let stored: Vec<usize> = (0..blocks.len())
        .filter(|&b| match blocks[b] {
            Block::Mixed(_) => true,
            Block::Inside => options.close_at_box && on_box(b),
            _ => false,
        })
        .collect();
    let mut slot = vec![NOT_STORED; blocks.len()];
    for (s, &b) in stored.iter().enumerate() {
        slot[b] = s as u32;
    }
    let mut data = vec![0.0f32; stored.len() * BLOCK_LEN];
    data.par_chunks_mut(BLOCK_LEN)
        .zip(stored.par_iter())
        .for_each_init(BlockScratch::default, |scratch, (out, &b)| {
            let at = [b % nb[0], b / nb[0] % nb[1], b / (nb[0] * nb[1])];
            let lo = at.map(|a| a * BS);
            let owned = [0, 1, 2].map(|a| (lo[a] + BS).min(n1[a]));
            let len = owned[0] - lo[0];
            match &blocks[b] {
                Block::Mixed(kernel) => {
                    let mut ws = kernel.rows.workspace(&coords[0][lo[0]..owned[0]]);
                    // All the block's rows at once (`row_blocks.rs`).
                    let [ys, zs] = [1, 2].map(|a| &coords[a][lo[a]..owned[a]]);
                    kernel.rows.eval_block(&mut ws, scratch, ys, zs, len, out);
                }
                _ => out.fill(1.0),
            }
            if options.close_at_box {
                // Samples on the box faces count as at most 0.
                for k in lo[2]..owned[2] {
                    for j in lo[1]..owned[1] {
                        let face = k == 0 || k == n1[2] - 1 || j == 0 || j == n1[1] - 1;
                        for i in lo[0]..owned[0] {
                            if face || i == 0 || i == n1[0] - 1 {
                                let v = &mut out[local(i, j, k)];
                                *v = v.min(0.0);
                            }
                        }
                    }
                }
            }
        });
    Field {
        n1,
        nb,
        blocks,
        kernels,
        samples: Samples::Blocks { slot, data },
    }
}

/// Sets the classified blocks; mixed blocks with equal programs share one
/// kernel, numbered in the order of `found` (deterministic). Why: M3's
/// neighbouring blocks around one ball, and M2's inner blocks (all the
/// gyroid alone), have the same program: building it once per block cost
/// allocations and time, and one kernel per program lets root finding run
/// their edges in one batch (`vertices::refine_by_kernel`).
fn share_kernels(found: &[(usize, Leaf)], blocks: &mut [Block]) -> Vec<Arc<Kernel>> {
    let mut ids: std::collections::HashMap<&Ssa, u32> = std::collections::HashMap::new();
    let mut programs: Vec<&Ssa> = Vec::new();
    let mut mixed: Vec<(usize, u32)> = Vec::new();
    for (at, leaf) in found {
        match leaf {
            Leaf::Proven(block) => blocks[*at] = block.clone(),
            Leaf::Mixed(ssa) => {
                let id = *ids.entry(ssa).or_insert_with(|| {
                    programs.push(ssa);
                    (programs.len() - 1) as u32
                });
                mixed.push((*at, id));
            }
        }
    }
    let kernels: Vec<Arc<Kernel>> = programs
        .par_iter()
        .enumerate()
        .map(|(id, ssa)| Arc::new(Kernel::new(ssa, id as u32)))
        .collect();
    for (at, id) in mixed {
        blocks[at] = Block::Mixed(kernels[id as usize].clone());
    }
    kernels
}

/// Caps given samples on the box faces at 0 (only the six faces are visited).
fn close_dense_at_box(values: &mut [f32], n1: [usize; 3]) {
    for k in 0..n1[2] {
        let k_face = k == 0 || k == n1[2] - 1;
        for j in 0..n1[1] {
            let start = (k * n1[1] + j) * n1[0];
            let row = &mut values[start..start + n1[0]];
            if k_face || j == 0 || j == n1[1] - 1 {
                for v in row.iter_mut() {
                    *v = v.min(0.0);
                }
            } else {
                row[0] = row[0].min(0.0);
                row[n1[0] - 1] = row[n1[0] - 1].min(0.0);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::implicit::ir::Ctx;

    /// A ball of radius 1.2 in the box [-1, 1]³: it leaves the box through
    /// the six faces, so proven-inside blocks lie on the box.
    fn big_ball() -> Ssa {
        let mut ctx = Ctx::new();
        let f = crate::implicit::vertices::tests::ball(&mut ctx, 1.2, [0.05, 0.0, -0.03]);
        Ssa::from_ctx(&ctx, f)
    }

    /// Two balls apart, joined by max: the blocks around each ball simplify
    /// to that ball alone, so many mixed blocks share few kernels, each
    /// numbered by its place in `kernels`.
    #[test]
    fn mixed_blocks_with_equal_programs_share_one_kernel() {
        let mut ctx = Ctx::new();
        let a = crate::implicit::vertices::tests::ball(&mut ctx, 0.3, [-0.5, 0.0, 0.0]);
        let b = crate::implicit::vertices::tests::ball(&mut ctx, 0.3, [0.5, 0.1, 0.0]);
        let f = ctx.binary(crate::implicit::ir::Binary::Max, a, b);
        let grid = Grid {
            min: [-1.0; 3],
            max: [1.0; 3],
            cells: [64, 64, 64],
        };
        let field = sample_field(&Ssa::from_ctx(&ctx, f), &grid, &Options::default());
        let ids: Vec<u32> = field
            .blocks
            .iter()
            .filter_map(|b| match b {
                Block::Mixed(k) => Some(k.id),
                _ => None,
            })
            .collect();
        assert_eq!(field.kernels.len(), 2, "one kernel per ball");
        assert!(ids.len() > 20, "{} mixed blocks", ids.len());
        for (id, kernel) in field.kernels.iter().enumerate() {
            assert_eq!(kernel.id as usize, id);
            assert!(ids.iter().filter(|&&i| i as usize == id).count() > 8);
        }
    }

    #[test]
    fn the_sparse_field_stores_only_mixed_and_capped_blocks_and_packs_their_signs() {
        let grid = Grid {
            min: [-1.0; 3],
            max: [1.0; 3],
            cells: [37, 30, 45],
        };
        let n1 = grid.cells.map(|n| n + 1);
        let field = sample_field(&big_ball(), &grid, &Options::default());
        let Samples::Blocks { slot, data } = &field.samples else {
            panic!("a sampled function's field is block-sparse");
        };
        let stored = slot.iter().filter(|&&s| s != NOT_STORED).count();
        let mixed = field
            .blocks
            .iter()
            .filter(|b| matches!(b, Block::Mixed(_)))
            .count();
        let inside = field
            .blocks
            .iter()
            .filter(|b| matches!(b, Block::Inside))
            .count();
        assert!(mixed > 0 && inside > 0, "{mixed} mixed, {inside} inside");
        assert!(
            stored > mixed && stored < field.blocks.len(),
            "{stored} stored"
        );
        assert_eq!(data.len(), stored * BLOCK_LEN);
        // Every sample as a dense grid: its sign bits are the field's.
        let mut dense = Vec::with_capacity(n1.iter().product());
        for k in 0..n1[2] {
            for j in 0..n1[1] {
                for i in 0..n1[0] {
                    let v = field.value(i, j, k);
                    let on_box = [i, j, k].iter().zip(n1).any(|(&c, n)| c == 0 || c == n - 1);
                    assert!(!on_box || v <= 0.0, "({i}, {j}, {k}) on the box is {v}");
                    dense.push(v);
                }
            }
        }
        let (a, b) = (field.signs(), SignRows::new(&dense, n1));
        for k in 0..n1[2] {
            for j in 0..n1[1] {
                assert_eq!(a.row(j, k), b.row(j, k), "row ({j}, {k})");
            }
        }
        // The centre is inside, a corner outside.
        assert!(field.value(18, 15, 22) > 0.0);
        assert!(field.value(0, 0, 0) < 0.0);
    }
}
