//! Paper 004's polygonization of {f = 0} on a regular grid, made watertight:
//!
//! 1. The field is sampled block by block (8³ samples); interval arithmetic
//!    proves most blocks entirely inside or outside (their samples get ±1 and
//!    are never evaluated nor stored), and each remaining block gets its own
//!    simplified program (`interval::simplify`) and stores its samples
//!    (`field.rs`).
//! 2. Every grid edge whose end samples differ in sign gets one vertex, placed
//!    by root finding (Illinois false position) on the edge with the owning
//!    block's program (`vertices.rs`). Vertices are numbered plane by plane, so the indexed
//!    mesh is the same for any thread count.
//! 3. In each cell the surface pieces are paper 004's cycles: the crossed
//!    edges are nodes, each cell face joins its crossings in pairs (a face
//!    with four crossings pairs them by the asymptotic decider: the sign of
//!    the bilinear saddle value), and the resulting cycles are triangulated.
//!    A face's pairing depends only on its four values, so the two cells
//!    sharing it agree, and every mesh edge has exactly two triangles.
//!
//! Rules: a sample is inside when f > 0; a value exactly 0 counts as outside
//! (the vertex then sits on that sample, and so do crossings within
//! `weld::SNAP` of a sample; `weld` makes all the vertices on one sample one
//! node and drops the triangles that collapse). When `close_at_box` is set, samples
//! on the box's faces count as at most 0, so a solid leaving the box is capped
//! on the box face. Triangles are oriented with normals pointing out of the
//! solid (towards decreasing f).

use super::cell_table::CellTable;
use super::field::{BS, Block, Field, sample_field};
use super::rows::RowTape;
use super::signs::{self, SignRows};
use super::tape::Ssa;
use super::vertices::{PlaneVertices, plane_vertices, planes_vertices};
use super::weld;
use rayon::prelude::*;
use std::cell::Cell;

/// The sampling grid: `cells` cells per axis over the box.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grid {
    pub min: [f64; 3],
    pub max: [f64; 3],
    pub cells: [usize; 3],
}

impl Grid {
    /// Sample coordinates along one axis (the last is exactly `max`).
    pub fn coords(&self, axis: usize) -> Vec<f64> {
        let n = self.cells[axis];
        (0..=n)
            .map(|i| {
                if i == n {
                    self.max[axis]
                } else {
                    self.min[axis] + (self.max[axis] - self.min[axis]) * (i as f64 / n as f64)
                }
            })
            .collect()
    }
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Options {
    /// Skip blocks interval arithmetic proves inside or outside.
    pub prune: bool,
    /// Root-finding iterations per crossed edge.
    pub iterations: usize,
    /// Cap the solid on the box faces where it leaves the box.
    pub close_at_box: bool,
}

impl Default for Options {
    fn default() -> Options {
        Options {
            prune: true,
            iterations: 6,
            close_at_box: true,
        }
    }
}

/// An indexed triangle mesh of the surface.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Surface {
    pub positions: Vec<[f64; 3]>,
    pub triangles: Vec<[u32; 3]>,
    /// Blocks in the grid and blocks proven inside/outside.
    pub blocks: usize,
    pub pruned_blocks: usize,
}

/// Samples f on every grid point, densely (no pruning), as f32, in parallel
/// over z planes, row by row with the x terms computed once (`RowTape`).
/// Used by the dense-throughput benchmark.
pub fn sample_grid(ssa: &Ssa, grid: &Grid) -> Vec<f32> {
    let mut values = vec![0.0f32; grid.cells.iter().map(|n| n + 1).product()];
    sample_grid_into(ssa, grid, &mut values);
    values
}

/// `sample_grid` into a buffer of the grid's sample count (x fastest), so
/// repeated sampling reuses memory that is already mapped.
pub fn sample_grid_into(ssa: &Ssa, grid: &Grid, values: &mut [f32]) {
    let tape = RowTape::new(ssa);
    let [xs, ys, zs] = [grid.coords(0), grid.coords(1), grid.coords(2)];
    let plane = xs.len() * ys.len();
    assert_eq!(values.len(), plane * zs.len(), "one value per grid sample");
    values.par_chunks_mut(plane).enumerate().for_each_init(
        || tape.workspace(&xs),
        |ws, (k, out)| {
            for (j, row) in out.chunks_mut(xs.len()).enumerate() {
                tape.eval_row(ws, ys[j], zs[k], row);
            }
        },
    );
}

/// Corner c of a cell is at offset (c & 1, c >> 1 & 1, c >> 2 & 1).
pub(super) const EDGES: [(u8, u8); 12] = [
    (0, 1),
    (2, 3),
    (4, 5),
    (6, 7),
    (0, 2),
    (1, 3),
    (4, 6),
    (5, 7),
    (0, 4),
    (1, 5),
    (2, 6),
    (3, 7),
];
/// The six faces, corners counter-clockwise seen from outside the cell.
pub(super) const FACES: [[u8; 4]; 6] = [
    [0, 4, 6, 2],
    [1, 3, 7, 5],
    [0, 1, 5, 4],
    [2, 6, 7, 3],
    [0, 2, 3, 1],
    [4, 5, 7, 6],
];

const fn edge_table() -> [[u8; 8]; 8] {
    let mut t = [[u8::MAX; 8]; 8];
    let mut e = 0;
    while e < 12 {
        let (a, b) = EDGES[e];
        t[a as usize][b as usize] = e as u8;
        t[b as usize][a as usize] = e as u8;
        e += 1;
    }
    t
}
const EDGE_OF: [[u8; 8]; 8] = edge_table();

const fn face_masks() -> [u8; 12] {
    let mut m = [0u8; 12];
    let mut f = 0;
    while f < 6 {
        let mut s = 0;
        while s < 4 {
            let e = EDGE_OF[FACES[f][s] as usize][FACES[f][(s + 1) % 4] as usize];
            m[e as usize] |= 1 << f;
            s += 1;
        }
        f += 1;
    }
    m
}
/// Which faces each cell edge lies on.
pub(super) const FACE_MASK: [u8; 12] = face_masks();

/// The successor of each crossed edge in its cycle (u8::MAX: not crossed):
/// on every face each exit crossing (inside → outside, counter-clockwise
/// seen from outside) is joined to an entry crossing.
pub fn cell_links(v: &[f64; 8]) -> [u8; 12] {
    let inside = std::array::from_fn(|c| v[c] > 0.0);
    // Asymptotic decider: the bilinear interpolant's saddle value
    // (v0 v2 − v1 v3) / (v0 + v2 − v1 − v3) has a positive denominator
    // (p[0] is an inside corner), so the centre is inside when v0 v2 > v1 v3.
    links(inside, |_, p| {
        let val = |c: u8| v[c as usize];
        val(p[0]) * val(p[2]) > val(p[1]) * val(p[3])
    })
}

/// [`cell_links`] from the corner signs, with `centre_inside(face, p)`
/// deciding each face with four crossings (`p`: the face's corners starting
/// at an inside one, counter-clockwise seen from outside).
pub(super) fn links(
    inside: [bool; 8],
    mut centre_inside: impl FnMut(usize, [u8; 4]) -> bool,
) -> [u8; 12] {
    let mut next = [u8::MAX; 12];
    for (f, q) in FACES.into_iter().enumerate() {
        let ins = q.map(|c| inside[c as usize]);
        let crossings = (0..4).filter(|&s| ins[s] != ins[(s + 1) % 4]).count();
        let edge = |a: u8, b: u8| EDGE_OF[a as usize][b as usize];
        if crossings == 2 {
            let exit = (0..4).find(|&s| ins[s] && !ins[(s + 1) % 4]);
            let entry = (0..4).find(|&s| !ins[s] && ins[(s + 1) % 4]);
            if let (Some(x), Some(n)) = (exit, entry) {
                next[edge(q[x], q[(x + 1) % 4]) as usize] = edge(q[n], q[(n + 1) % 4]);
            }
        } else if crossings == 4 {
            let p = saddle_corners(q, ins[0]);
            let (e0, e1, e2, e3) = (
                edge(p[0], p[1]),
                edge(p[1], p[2]),
                edge(p[2], p[3]),
                edge(p[3], p[0]),
            );
            if centre_inside(f, p) {
                next[e0 as usize] = e1;
                next[e2 as usize] = e3;
            } else {
                next[e0 as usize] = e3;
                next[e2 as usize] = e1;
            }
        }
    }
    next
}

/// A face's corners rotated to start at an inside one (faces with four
/// crossings alternate inside and outside).
pub(super) fn saddle_corners(q: [u8; 4], first_inside: bool) -> [u8; 4] {
    let r = if first_inside { 0 } else { 1 };
    [q[r], q[(r + 1) % 4], q[(r + 2) % 4], q[(r + 3) % 4]]
}

/// A cell's cycles, kept on the stack (the polygonizer calls this for every
/// crossed cell): at most 12 crossed edges, so at most 12 cycles.
#[derive(Debug, Clone, Copy)]
pub struct Cycles {
    edges: [u8; 12],
    /// Cycle c is `edges[ends[c]..ends[c + 1]]`.
    ends: [u8; 13],
    count: usize,
}

impl Cycles {
    pub fn len(&self) -> usize {
        self.count
    }
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }
    pub fn iter(&self) -> impl Iterator<Item = &[u8]> {
        (0..self.count).map(|c| &self.edges[self.ends[c] as usize..self.ends[c + 1] as usize])
    }
}

/// The cycles of a cell, each as its cell edges in the order that gives
/// outward-facing triangles.
pub fn cell_cycles(v: &[f64; 8]) -> Cycles {
    cycles_of(&cell_links(v))
}

/// The cycles of a cell's links ([`cell_links`]).
pub(super) fn cycles_of(next: &[u8; 12]) -> Cycles {
    let mut seen = [false; 12];
    let mut cycles = Cycles {
        edges: [0; 12],
        ends: [0; 13],
        count: 0,
    };
    let mut len = 0usize;
    for e in 0..12u8 {
        if next[e as usize] == u8::MAX || seen[e as usize] {
            continue;
        }
        let start = len;
        let mut cur = e;
        while !seen[cur as usize] && next[cur as usize] != u8::MAX {
            seen[cur as usize] = true;
            cycles.edges[len] = cur;
            len += 1;
            cur = next[cur as usize];
        }
        // The links run with the inside on their left seen from outside the
        // cell; reversed, the polygon's normal points out of the solid.
        cycles.edges[start..len].reverse();
        cycles.count += 1;
        cycles.ends[cycles.count] = len as u8;
    }
    cycles
}

/// Marks a vertex id as local to one slab (a cycle centre), renumbered once
/// every slab's count is known.
const CENTRE: u32 = 1 << 31;

/// One slab's triangles and its cycle-centre vertices. A triangle's
/// vertex ids count from the first vertex of the slab's lower plane (its
/// upper plane's follow), or are `CENTRE`-marked indices into the centres.
type SlabOutput = (Vec<[u32; 3]>, Vec<[f64; 3]>);

/// Slab runs per grid (a fixed count, so the split does not depend on the
/// thread count; enough runs to balance the threads' loads).
const RUNS: usize = 32;

thread_local! {
    /// `contour_run`'s edge maps, every entry `u32::MAX` while stored.
    static EDGE_MAPS: Cell<[Vec<u32>; 2]> = const { Cell::new([Vec::new(), Vec::new()]) };
}

/// A run of slabs k0..k1: the vertices of its inner planes k0 + 1..k1 and
/// the slabs' triangles.
struct RunOutput {
    inner: Vec<PlaneVertices>,
    slabs: Vec<SlabOutput>,
}

/// Contours slabs `slabs` (not empty) of the field one after the other,
/// each right after the vertices of its upper plane; `bottom` and `top` are
/// the vertices of planes k0 and k1, made once for the two runs sharing them
/// (root finding on a plane's edges is the costly part of the whole path).
fn contour_run(
    field: &Field,
    signs: &SignRows,
    coords: &[Vec<f64>; 3],
    slabs: std::ops::Range<usize>,
    [bottom, top]: [&PlaneVertices; 2],
    options: &Options,
) -> RunOutput {
    let n1 = field.n1;
    let mut out = Vec::with_capacity(slabs.len());
    // Edge key → vertex index within its plane, for the slab's lower and
    // upper plane; after a slab the lower plane's entries are reset and the
    // maps swap (only the entries set are touched). The maps are kept per
    // thread between runs and calls, all unset (a fresh 0.8 MB map per run
    // cost more in page faults than the contouring of its slabs).
    let mut maps = EDGE_MAPS.with(Cell::take);
    for map in &mut maps {
        if map.len() < n1[0] * n1[1] * 3 {
            map.resize(n1[0] * n1[1] * 3, u32::MAX);
        }
    }
    let fill = |map: &mut [u32], p: &PlaneVertices, on: bool| {
        for (m, &key) in p.keys.iter().enumerate() {
            map[key as usize] = if on { m as u32 } else { u32::MAX };
        }
    };
    fill(&mut maps[0], bottom, true);
    // The inner planes' crossings refined together, kernel by kernel
    // (longer batches for the f64 tape than plane by plane).
    let inner = planes_vertices(field, signs, coords, slabs.start + 1..slabs.end, options);
    for k in slabs.clone() {
        let lower = if k == slabs.start {
            bottom
        } else {
            &inner[k - slabs.start - 1]
        };
        let upper = if k + 1 == slabs.end {
            top
        } else {
            &inner[k - slabs.start]
        };
        fill(&mut maps[1], upper, true);
        let slab = contour_slab(field, signs, k, [lower, upper], &maps, options.close_at_box);
        out.push(slab);
        fill(&mut maps[0], lower, false);
        maps.swap(0, 1);
    }
    fill(&mut maps[0], top, false);
    EDGE_MAPS.with(|m| m.set(maps));
    RunOutput { inner, slabs: out }
}

/// The triangles of slab k (cells k..k + 1 in z); `planes` are the vertices
/// of planes k and k + 1 and `maps` their edge key → index maps.
fn contour_slab(
    field: &Field,
    signs: &SignRows,
    k: usize,
    planes: [&PlaneVertices; 2],
    maps: &[Vec<u32>; 2],
    close_at_box: bool,
) -> SlabOutput {
    let n1 = field.n1;
    let cells = [n1[0] - 1, n1[1] - 1];
    let base = [0, planes[0].keys.len() as u32];
    let position = |id: u32| {
        let dz = usize::from(id >= base[1]);
        planes[dz].positions[(id - base[dz]) as usize]
    };
    let touches_box = |i: usize, j: usize, k: usize| {
        let b = [i / BS, j / BS, k / BS];
        (0..3).any(|a| b[a] == 0 || (b[a] * BS + BS) >= n1[a] - 1)
    };
    let table = CellTable::get();
    // About two triangles per crossed edge (growing the vector by doubling
    // cost copies and page faults).
    let crossed = planes[0].keys.len() + planes[1].keys.len();
    let mut tris = Vec::with_capacity(crossed + crossed / 4);
    let mut centres = Vec::new();
    let mut ids = Vec::with_capacity(12);
    for j in 0..cells[1] {
        let rows = [(j, k), (j + 1, k), (j, k + 1), (j + 1, k + 1)].map(|(j, k)| signs.row(j, k));
        // Cells whose eight corners do not all share one sign: some corner
        // inside (OR) and not all inside (AND).
        let mixed = (0..signs.words).map(|w| {
            let (mut all, mut any) = (u64::MAX, 0u64);
            for r in rows {
                let (a, b) = (r[w], signs::shifted(r, w));
                all &= a & b;
                any |= a | b;
            }
            (any & !all & signs::low_bits(cells[0], w), w)
        });
        for i in mixed.flat_map(|(m, w)| signs::bits(m, w)) {
            match field.block(i, j, k) {
                Block::Outside => continue,
                Block::Inside if !(close_at_box && touches_box(i, j, k)) => continue,
                _ => {}
            }
            // Corner c's sign is bit i + (c & 1) of row c >> 1 (the rows'
            // order above); the same `> 0` as the samples' (`signs::pack`).
            let mut sign_case = 0usize;
            for (r, row) in rows.iter().enumerate() {
                let pair = (row[i / 64] >> (i % 64)) & 1
                    | ((row[(i + 1) / 64] >> ((i + 1) % 64)) & 1) << 1;
                sign_case |= (pair as usize) << (2 * r);
            }
            let cycles = table.lookup_case(sign_case, |c| {
                let c = c as usize;
                field.value(i + (c & 1), j + (c >> 1 & 1), k + (c >> 2 & 1)) as f64
            });
            for c in 0..cycles.count as usize {
                let (cycle, valid_starts) = cycles.cycle(c);
                ids.clear();
                for &e in cycle {
                    let (a, b) = EDGES[e as usize];
                    let axis = (a ^ b).trailing_zeros() as usize;
                    let (a, dz) = (a as usize, (a as usize >> 2) & 1);
                    let key = ((j + (a >> 1 & 1)) * n1[0] + i + (a & 1)) * 3 + axis;
                    let m = maps[dz][key];
                    ids.push(if m == u32::MAX { m } else { base[dz] + m });
                }
                if ids.contains(&u32::MAX) {
                    continue;
                }
                triangulate(valid_starts, &ids, position, &mut tris, &mut centres);
            }
        }
    }
    (tris, centres)
}

/// Triangulates one cycle of vertex ids as a fan whose diagonals never join
/// two crossings on one cell face (the neighbour cell might join the same
/// pair); for quads the shorter valid diagonal. When no such fan exists (a
/// face whose two segments both belong to this cycle) the cycle is fanned
/// around a new vertex at its centroid.
/// `valid_starts`: bit s set when the fan from vertex s is such a fan
/// (`cell_table::CaseCycles::valid`).
fn triangulate(
    valid_starts: u16,
    ids: &[u32],
    position: impl Fn(u32) -> [f64; 3],
    out: &mut Vec<[u32; 3]>,
    centres: &mut Vec<[f64; 3]>,
) {
    let n = ids.len();
    if n < 3 {
        return;
    }
    let valid = |s: usize| valid_starts >> s & 1 == 1;
    let start = if n == 4 {
        let len = |a: usize, b: usize| {
            let (p, q) = (position(ids[a]), position(ids[b]));
            (0..3).map(|k| (p[k] - q[k]).powi(2)).sum::<f64>()
        };
        match (valid(0), valid(1)) {
            (true, true) if len(1, 3) < len(0, 2) => Some(1),
            (true, _) => Some(0),
            (false, true) => Some(1),
            (false, false) => None,
        }
    } else {
        (0..n).find(|&s| valid(s))
    };
    match start {
        Some(start) => {
            for d in 1..n - 1 {
                out.push([ids[start], ids[(start + d) % n], ids[(start + d + 1) % n]]);
            }
        }
        None => {
            let mut c = [0.0; 3];
            for &id in ids {
                let p = position(id);
                for (k, ck) in c.iter_mut().enumerate() {
                    *ck += p[k] / n as f64;
                }
            }
            let centre = CENTRE | centres.len() as u32;
            centres.push(c);
            for m in 0..n {
                out.push([centre, ids[m], ids[(m + 1) % n]]);
            }
        }
    }
}

/// The parts one after the other, each item mapped by `map(part, item)`,
/// copied in parallel: the order is the parts' order for any thread count.
/// `spare` more items fit without growing the vector.
fn concat<T: Copy + Sync, U: Send>(
    parts: &[&[T]],
    spare: usize,
    map: impl Fn(usize, T) -> U + Sync,
) -> Vec<U> {
    let total = parts.iter().map(|p| p.len()).sum();
    let mut out: Vec<U> = Vec::with_capacity(total + spare);
    let mut rest = &mut out.spare_capacity_mut()[..total];
    let mut slots = Vec::with_capacity(parts.len());
    for part in parts {
        let (here, after) = rest.split_at_mut(part.len());
        slots.push(here);
        rest = after;
    }
    slots
        .into_par_iter()
        .zip(parts.par_iter())
        .enumerate()
        .for_each(|(i, (slot, part))| {
            for (d, &x) in slot.iter_mut().zip(part.iter()) {
                d.write(map(i, x));
            }
        });
    // SAFETY: the slots cover the first `total` elements and every one of
    // them was written above.
    unsafe { out.set_len(total) };
    out
}

/// Polygonizes {f = 0} of `ssa` over the grid.
pub fn polygonize(ssa: &Ssa, grid: &Grid, options: &Options) -> Surface {
    let field = sample_field(ssa, grid, options);
    mesh_field(&field, grid, options)
}

/// Polygonizes {v = 0} of given samples (x fastest, then y, then z; one per
/// grid point), vertices by linear interpolation along the edges.
///
/// # Panics
/// If `values` does not hold one value per grid point (a caller bug).
pub fn polygonize_samples(values: Vec<f64>, grid: &Grid, options: &Options) -> Surface {
    let n1 = grid.cells.map(|n| n + 1);
    assert_eq!(
        values.len(),
        n1[0] * n1[1] * n1[2],
        "one sample per grid point"
    );
    // To f32 keeping each sign (a tiny positive value must not round to 0).
    let values = values
        .iter()
        .map(|&v| match v as f32 {
            0.0 if v > 0.0 => f32::MIN_POSITIVE,
            w => w,
        })
        .collect();
    polygonize_samples_f32(values, grid, options)
}

/// [`polygonize_samples`] on f32 samples (as a CT volume or
/// [`sample_grid`] gives them), without the conversion.
///
/// # Panics
/// If `values` does not hold one value per grid point (a caller bug).
pub fn polygonize_samples_f32(values: Vec<f32>, grid: &Grid, options: &Options) -> Surface {
    polygonize_samples_f32_returning(values, grid, options).0
}

/// [`polygonize_samples_f32`] that hands the sample buffer back (its values
/// outside the box closed), so the caller decides when its memory is freed:
/// the implicit bench times contouring as VTK's is timed, without freeing the
/// input.
///
/// # Panics
/// If `values` does not hold one value per grid point (a caller bug).
pub fn polygonize_samples_f32_returning(
    values: Vec<f32>,
    grid: &Grid,
    options: &Options,
) -> (Surface, Vec<f32>) {
    let n1 = grid.cells.map(|n| n + 1);
    assert_eq!(
        values.len(),
        n1[0] * n1[1] * n1[2],
        "one sample per grid point"
    );
    let field = Field::dense(values, n1, options);
    let surface = mesh_field(&field, grid, options);
    (surface, field.into_dense())
}

fn mesh_field(field: &Field, grid: &Grid, options: &Options) -> Surface {
    let coords = [grid.coords(0), grid.coords(1), grid.coords(2)];
    let signs = field.signs();
    // Runs of consecutive slabs, each contoured by one thread right after
    // its planes' vertices, so the samples of planes k and k + 1 are still
    // in cache when slab k reads them (two passes over all planes read the
    // 68 MB grid twice from memory). The runs only split the work: every
    // plane and slab gives the same result in any run, so the output is the
    // same for any thread count.
    let nz = grid.cells[2];
    let run = nz.div_ceil(RUNS).max(1);
    // The planes where runs meet (and the bottom and top), made first.
    let cuts: Vec<usize> = (0..nz).step_by(run).chain([nz]).collect();
    let shared: Vec<PlaneVertices> = cuts
        .par_iter()
        .map(|&k| plane_vertices(field, &signs, &coords, k, options))
        .collect();
    let runs: Vec<RunOutput> = (0..cuts.len() - 1)
        .into_par_iter()
        .map(|r| {
            let ends = [&shared[r], &shared[r + 1]];
            contour_run(field, &signs, &coords, cuts[r]..cuts[r + 1], ends, options)
        })
        .collect();
    // Planes in order: each run's first plane, its inner planes, and last
    // the top plane.
    let planes: Vec<&PlaneVertices> = runs
        .iter()
        .zip(&shared)
        .flat_map(|(r, first)| std::iter::once(first).chain(&r.inner))
        .chain(shared.last())
        .collect();
    let slabs: Vec<&SlabOutput> = runs.iter().flat_map(|r| &r.slabs).collect();
    let mut offsets = Vec::with_capacity(planes.len());
    let mut total = 0u32;
    for p in &planes {
        offsets.push(total);
        total += p.keys.len() as u32;
    }
    // Empty when no vertex sits on a sample (then `weld` has nothing to do).
    let at_sample: Vec<u64> = if planes.iter().all(|p| p.at_sample.is_empty()) {
        Vec::new()
    } else {
        let none: Vec<Vec<u64>> = planes
            .iter()
            .map(|p| match p.at_sample.is_empty() {
                true => vec![weld::NONE; p.keys.len()],
                false => Vec::new(),
            })
            .collect();
        let parts: Vec<&[u64]> = planes
            .iter()
            .zip(&none)
            .map(|(p, n)| {
                if p.at_sample.is_empty() {
                    &n[..]
                } else {
                    &p.at_sample[..]
                }
            })
            .collect();
        concat(&parts, 0, |_, s| s)
    };
    // The cycle centres are appended below: room for them from the start
    // (growing a vector of 700k vertices copies it).
    let centres: usize = slabs.iter().map(|s| s.1.len()).sum();
    let mut positions: Vec<[f64; 3]> = concat(
        &planes.iter().map(|p| &p.positions[..]).collect::<Vec<_>>(),
        centres,
        |_, p| p,
    );
    // Each slab's centres follow the edge vertices, slab after slab.
    let mut bases = Vec::with_capacity(slabs.len());
    for (_, centres) in &slabs {
        bases.push(positions.len() as u32);
        positions.extend_from_slice(centres);
    }
    let triangles = concat(
        &slabs.iter().map(|s| &s.0[..]).collect::<Vec<_>>(),
        0,
        |slab, t| {
            t.map(|id| {
                if id & CENTRE != 0 {
                    bases[slab] + (id & !CENTRE)
                } else {
                    // Slab k's vertices are planes k and k + 1's, which
                    // follow each other in the global numbering.
                    offsets[slab] + id
                }
            })
        },
    );
    let pruned_blocks = field
        .blocks
        .iter()
        .filter(|b| matches!(b, Block::Inside | Block::Outside))
        .count();
    let mut surface = Surface {
        positions,
        triangles,
        blocks: field.blocks.len(),
        pruned_blocks,
    };
    weld::weld_at_samples(&mut surface, &at_sample);
    surface
}
