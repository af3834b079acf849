//! The z-buffer rasteriser. Each sample keeps one `u64`: the depth's bits
//! above the triangle's id (`2 × triangle + back side`), and the smallest value
//! wins. A minimum does not depend on the order triangles arrive in, so bands
//! rasterised in parallel give the same buffer for any thread count.
//! Coordinates are snapped to 1/16 sample so shared edges are exact (no
//! cracks) and the top-left rule decides which triangle owns a sample on one.

use super::scene::{HIDDEN, Scene};
use super::triangle::{self, SUB};
use rayon::prelude::*;

#[cfg(target_arch = "x86_64")]
mod bin_avx2;

pub const EMPTY: u64 = u64::MAX;
/// Sample rows per band (the unit of parallel work).
const BAND: usize = 32;
/// Triangles per binning chunk.
const CHUNK: usize = 1 << 15;

/// A node in sample space: snapped x and y (1/16 sample steps, within
/// ±1.6e7, so `i32` holds them) beside its depth in [0, 1]. Packed in 12
/// bytes so the rasteriser's gather of a corner touches one cache line
/// (separate position and depth arrays of a million-node mesh cost two
/// misses per corner).
/// `repr(C)`: the AVX2 binning gathers x and y as one 8-byte load.
#[derive(Debug, Clone, Copy, Default)]
#[repr(C)]
pub struct Snapped {
    pub x: i32,
    pub y: i32,
    pub z: f32,
}

/// Node positions in sample space: snapped with depths, and unsnapped.
pub struct Projected {
    pub snapped: Vec<Snapped>,
    /// Unsnapped, for interpolation in shading.
    pub xy_f: Vec<[f32; 2]>,
    /// Instead of `xy_f` when each node is its own light slot: unsnapped
    /// with the node's light, one record per node (see `project`).
    pub xy_light: Vec<super::project::XyLight>,
}

#[cfg(test)]
impl Projected {
    /// Unsnapped positions with each node's own light in records, as the
    /// projection makes them when the nodes are their own light slots.
    pub fn records_of(xy_f: &[[f32; 2]], light: &[[f32; 2]]) -> Projected {
        Projected {
            snapped: Vec::new(),
            xy_f: Vec::new(),
            xy_light: (xy_f.iter().zip(light))
                .map(|(&xy, &light)| super::project::XyLight { xy, light })
                .collect(),
        }
    }
}

pub struct ZBuffer {
    pub width: usize,
    pub height: usize,
    pub data: Vec<u64>,
}

pub fn depth_of(value: u64) -> f32 {
    f32::from_bits((value >> 32) as u32)
}

/// The triangle's corners as given, and which side faces the eye (none when
/// it is seen edge-on): what binning needs, without the depths.
#[inline]
fn facing(proj: &Projected, t: [u32; 3]) -> Option<([[i64; 2]; 3], u32)> {
    let v = t.map(|n| {
        let p = proj.snapped[n as usize];
        [p.x as i64, p.y as i64]
    });
    let [a, b, c] = v;
    let area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
    (area != 0).then_some((v, u32::from(area > 0)))
}

#[inline]
fn visible_side(scene: &Scene, tri: usize, back: u32) -> bool {
    scene.side_group(tri, back as usize) != HIDDEN
}

/// First and last sample centre (index) within snapped coordinates `lo..=hi`,
/// clamped to `0..size`.
#[inline]
fn sample_span(lo: i64, hi: i64, size: usize) -> Option<(usize, usize)> {
    // Sample centres sit at (i + 1/2) samples.
    let first = (lo - SUB / 2 + SUB - 1).div_euclid(SUB).max(0);
    let last = (hi - SUB / 2).div_euclid(SUB).min(size as i64 - 1);
    (first <= last).then_some((first as usize, last as usize))
}

/// Sample columns and rows a triangle may cover (`x0..=x1`, `y0..=y1`),
/// clamped to the image; none when its bounding box holds no sample centre
/// of the image.
#[inline]
fn sample_box(
    v: &[[i64; 2]; 3],
    width: usize,
    height: usize,
) -> Option<(usize, usize, usize, usize)> {
    let min_x = v[0][0].min(v[1][0]).min(v[2][0]);
    let max_x = v[0][0].max(v[1][0]).max(v[2][0]);
    let (x0, x1) = sample_span(min_x, max_x, width)?;
    let lo = v[0][1].min(v[1][1]).min(v[2][1]);
    let hi = v[0][1].max(v[1][1]).max(v[2][1]);
    let (y0, y1) = sample_span(lo, hi, height)?;
    Some((x0, x1, y0, y1))
}

/// One chunk's binned triangles: per band, the ids it must draw and the
/// sample columns their boxes reach (`first..=last`; empty when `first >
/// last`), so a band fills and resolves only the columns drawn on.
pub struct ChunkBins {
    pub ids: Vec<Vec<u32>>,
    pub cols: Vec<(u32, u32)>,
}

/// The sample columns the triangles of band `band` reach over every chunk
/// (`first..=last`), or `None` when no triangle reaches the band.
pub fn band_columns(bins: &[ChunkBins], band: usize) -> Option<(usize, usize)> {
    let (first, last) = bins.iter().fold((u32::MAX, 0), |(f, l), chunk| {
        let (cf, cl) = chunk.cols[band];
        (f.min(cf), l.max(cl))
    });
    (first <= last).then_some((first as usize, last as usize))
}

/// For each chunk of triangles, the ids each band of `band_rows` sample rows
/// must draw (front-facing visible sides only, rows clamped to the image).
pub fn bin(
    scene: &Scene,
    proj: &Projected,
    width: usize,
    height: usize,
    band_rows: usize,
) -> Vec<ChunkBins> {
    bin_with(scene, proj, width, height, band_rows, true)
}

/// [`bin`], eight triangles at a time with AVX2 when `vector` and the CPU
/// has it (the same lists either way).
fn bin_with(
    scene: &Scene,
    proj: &Projected,
    width: usize,
    height: usize,
    band_rows: usize,
    vector: bool,
) -> Vec<ChunkBins> {
    let vector = vector && has_avx2();
    let n_bands = height.div_ceil(band_rows);
    // Each sample row's band, looked up: two divisions by a band height
    // that is not always a power of two cost a fifth of binning.
    let band_of: Vec<u32> = (0..height).map(|y| (y / band_rows) as u32).collect();
    // When every face shows the same pair of groups (one face, or faces of
    // one colour), which sides are seen is known once, not per triangle.
    let same_visible = scene.same_sides.map(|sides| sides.map(|g| g != HIDDEN));
    let band_of = &band_of[..];
    (scene.tris.par_chunks(CHUNK))
        .enumerate()
        .map(|(c, chunk)| {
            let mut bins = ChunkBins {
                ids: vec![Vec::new(); n_bands],
                cols: vec![(u32::MAX, 0u32); n_bands],
            };
            let tris = Tris {
                first: c * CHUNK,
                corners: chunk,
            };
            // The loop compiled once per case, so the common one (every
            // face alike) tests a side with no lookup of the scene.
            match same_visible {
                Some(visible) => bin_chunk(
                    proj,
                    tris,
                    width,
                    (band_of, band_rows),
                    &mut bins,
                    vector,
                    same_visible,
                    |_, back| visible[back as usize],
                ),
                None => bin_chunk(
                    proj,
                    tris,
                    width,
                    (band_of, band_rows),
                    &mut bins,
                    vector,
                    None,
                    |tri, back| visible_side(scene, tri, back),
                ),
            }
            bins
        })
        .collect()
}

fn has_avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// Consecutive triangles: their corners, the first one's id `first`.
#[derive(Clone, Copy)]
struct Tris<'a> {
    first: usize,
    corners: &'a [[u32; 3]],
}

/// Bins triangles `tris` whose side `back` is `seen` into `bins`, a sample
/// row's band being `band_of[row]` (bands of `band_rows` rows); with AVX2
/// when `vector` (which the caller has checked the CPU has).
/// `same_visible`, when every face shows the same sides, says which are
/// seen (and `seen` repeats it).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn bin_chunk(
    proj: &Projected,
    tris: Tris,
    width: usize,
    (band_of, band_rows): (&[u32], usize),
    bins: &mut ChunkBins,
    vector: bool,
    same_visible: Option<[bool; 2]>,
    seen: impl Fn(usize, u32) -> bool,
) {
    // Neighbouring triangles of a mesh mostly land in the same band, so
    // that band's list is held aside (its length and columns in registers)
    // while the run lasts, instead of being loaded and stored per triangle.
    let mut run = Run::default();
    let mut done = 0;
    #[cfg(target_arch = "x86_64")]
    if vector {
        // SAFETY: `vector` is true only when the CPU has AVX2 (`bin_with`).
        done = unsafe {
            bin_avx2::bin_groups(
                proj,
                tris,
                width,
                band_of,
                bins,
                &mut run,
                band_rows,
                same_visible,
                &seen,
            )
        };
    }
    let _ = (vector, band_rows, same_visible);
    for (tri, &t) in (tris.first + done..).zip(&tris.corners[done..]) {
        bin_one(proj, tri, t, width, band_of, bins, &mut run, &seen);
    }
    run.switch(bins, usize::MAX);
}

/// Bins triangle `tri` (corners `t`) when its side facing the eye is `seen`.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn bin_one(
    proj: &Projected,
    tri: usize,
    t: [u32; 3],
    width: usize,
    band_of: &[u32],
    bins: &mut ChunkBins,
    run: &mut Run,
    seen: &impl Fn(usize, u32) -> bool,
) {
    let Some((v, back)) = facing(proj, t) else {
        return;
    };
    if !seen(tri, back) {
        return;
    }
    if let Some(sample_box) = sample_box(&v, width, band_of.len()) {
        run.place(bins, band_of, tri as u32, sample_box);
    }
}

/// The list of the band the last triangles went to, taken out of the
/// chunk's bins until the next band's turn.
struct Run {
    band: usize,
    ids: Vec<u32>,
    cols: (u32, u32),
}

impl Default for Run {
    fn default() -> Self {
        Run {
            band: usize::MAX,
            ids: Vec::new(),
            cols: (u32::MAX, 0),
        }
    }
}

impl Run {
    /// Lists triangle `tri` in the bands its sample box (columns `x0..=x1`,
    /// rows `first..=last`) reaches.
    #[inline(always)]
    fn place(
        &mut self,
        bins: &mut ChunkBins,
        band_of: &[u32],
        tri: u32,
        (x0, x1, first, last): (usize, usize, usize, usize),
    ) {
        let (from, to) = (band_of[first] as usize, band_of[last] as usize);
        let reach = (x0 as u32, x1 as u32);
        if from == to {
            // Most triangles (a sample or two across) lie in one band.
            if from != self.band {
                self.switch(bins, from);
            }
            self.add(tri, reach);
        } else {
            for band in from..=to {
                if band == self.band {
                    self.add(tri, reach);
                } else {
                    bins.add(band, tri, reach);
                }
            }
        }
    }

    /// Puts the run's list back and takes band `band`'s (none for
    /// `usize::MAX`).
    #[inline(never)]
    fn switch(&mut self, bins: &mut ChunkBins, band: usize) {
        if let Some(ids) = bins.ids.get_mut(self.band) {
            *ids = std::mem::take(&mut self.ids);
            bins.cols[self.band] = self.cols;
        }
        self.band = band;
        if let Some(ids) = bins.ids.get_mut(band) {
            self.ids = std::mem::take(ids);
            self.cols = bins.cols[band];
        }
    }

    #[inline(always)]
    fn add(&mut self, tri: u32, reach: (u32, u32)) {
        self.ids.push(tri);
        self.cols = widen(self.cols, reach);
    }
}

impl ChunkBins {
    /// Lists triangle `tri` in band `band`, whose columns widen to `reach`.
    #[inline(always)]
    fn add(&mut self, band: usize, tri: u32, reach: (u32, u32)) {
        self.ids[band].push(tri);
        self.cols[band] = widen(self.cols[band], reach);
    }
}

/// Columns `cols` (`first..=last`) widened to `reach`.
#[inline(always)]
fn widen(cols: (u32, u32), reach: (u32, u32)) -> (u32, u32) {
    (cols.0.min(reach.0), cols.1.max(reach.1))
}

/// Draws band `band` (sample rows `ys`, stored from `rows[0]`) from the bins.
pub fn draw_band(
    scene: &Scene,
    proj: &Projected,
    bins: &[ChunkBins],
    band: usize,
    rows: &mut [u64],
    width: usize,
    ys: std::ops::Range<usize>,
) {
    // `triangle::draw_chunks` indexes the band's samples without bounds
    // checks.
    assert!(ys.start <= ys.end && ys.len() * width <= rows.len());
    let chunks = bins.iter().map(|chunk| &chunk.ids[band][..]);
    // SAFETY: `rows` holds the band's samples (asserted above).
    unsafe { triangle::draw_chunks(rows, width, ys, &scene.tris, &proj.snapped, chunks) };
}

pub fn rasterize(scene: &Scene, proj: &Projected, width: usize, height: usize) -> ZBuffer {
    let bins = bin(scene, proj, width, height, BAND);
    let mut data = vec![EMPTY; width * height];
    data.par_chunks_mut(width * BAND)
        .enumerate()
        .for_each(|(band, rows)| {
            let y0 = band * BAND;
            let y1 = (y0 + BAND).min(height);
            draw_band(scene, proj, &bins, band, rows, width, y0..y1);
        });
    ZBuffer {
        width,
        height,
        data,
    }
}

/// Marks the samples of visible edge segments (sample-space endpoints with
/// depths): a line about `half_width` samples to each side, drawn where it is
/// not behind the surface by more than `tolerance` of the depth range.
/// A section cap hides every edge but the section's own outline (`on_plane`).
pub fn mark_edges(
    zbuf: &ZBuffer,
    segments: &[([[f32; 3]; 2], bool)],
    half_width: f32,
    tolerance: f32,
    is_cap: impl Fn(u64) -> bool,
    mask: &mut [bool],
) {
    let (w, h) = (zbuf.width as i64, zbuf.height as i64);
    for &([a, b], on_plane) in segments {
        let len = (b[0] - a[0]).abs().max((b[1] - a[1]).abs());
        let steps = (len * 2.0).ceil().max(1.0) as usize;
        let r = half_width.ceil() as i64;
        for i in 0..=steps {
            let u = i as f32 / steps as f32;
            let (x, y, z) = (
                a[0] + u * (b[0] - a[0]),
                a[1] + u * (b[1] - a[1]),
                a[2] + u * (b[2] - a[2]),
            );
            let (cx, cy) = (x.floor() as i64, y.floor() as i64);
            for sy in (cy - r).max(0)..=(cy + r).min(h - 1) {
                for sx in (cx - r).max(0)..=(cx + r).min(w - 1) {
                    let (dx, dy) = (sx as f32 + 0.5 - x, sy as f32 + 0.5 - y);
                    if dx * dx + dy * dy > half_width * half_width {
                        continue;
                    }
                    let index = (sy * w + sx) as usize;
                    let value = zbuf.data[index];
                    if value == EMPTY
                        || (z <= depth_of(value) + tolerance && (on_plane || !is_cap(value)))
                    {
                        mask[index] = true;
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn chunk(cols: &[(u32, u32)]) -> ChunkBins {
        ChunkBins {
            ids: vec![Vec::new(); cols.len()],
            cols: cols.to_vec(),
        }
    }

    #[test]
    fn band_columns_join_the_chunks_reach() {
        let none = (u32::MAX, 0);
        let bins = [
            chunk(&[none, (10, 20), (7, 9)]),
            chunk(&[none, (4, 12), none]),
        ];
        assert_eq!(band_columns(&bins, 0), None);
        assert_eq!(band_columns(&bins, 1), Some((4, 20)));
        assert_eq!(band_columns(&bins, 2), Some((7, 9)));
    }

    #[test]
    fn bands_list_the_seen_triangles_reaching_them_in_order() {
        // 70,000 random triangles (two chunks and a part), of three faces,
        // the second showing no back and the third nothing: each band
        // lists, ascending, exactly the triangles whose seen side faces the
        // eye and whose sample box reaches its rows, and its columns are
        // those boxes' reach.
        let mut rng = crate::test_rng::TestRng::new(0x6a09_e667_f3bc_c908);
        let (width, height, band_rows) = (90usize, 77usize, 10usize);
        let n = 2 * CHUNK + 4_465;
        let snapped: Vec<Snapped> = (0..3 * n)
            .map(|k| {
                let reach = [30, 120, 900][k / 3 % 3];
                Snapped {
                    x: (rng.within(reach) + 700) as i32,
                    y: (rng.within(reach) + 600) as i32,
                    z: 0.5,
                }
            })
            .collect();
        let tris: Vec<[u32; 3]> = (0..n as u32)
            .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
            .collect();
        let tri_face: Vec<u32> = (0..n as u32).map(|t| t % 3).collect();
        let scene = Scene {
            points: Vec::new().into(),
            tris: tris.into(),
            tri_face,
            one_face: None,
            face_sides: vec![[0, 1], [0, HIDDEN], [HIDDEN, HIDDEN]],
            same_sides: None,
            corner_slots: Vec::new().into(),
            light: Vec::new(),
            groups: Vec::new(),
        };
        let proj = Projected {
            snapped,
            xy_f: Vec::new(),
            xy_light: Vec::new(),
        };
        let bins = bin(&scene, &proj, width, height, band_rows);
        assert_eq!(bins.len(), 3);
        let n_bands = height.div_ceil(band_rows);
        let mut listed = 0;
        for band in 0..n_bands {
            let rows = band * band_rows..((band + 1) * band_rows).min(height);
            let (mut expected, mut reach) = (Vec::new(), (u32::MAX, 0));
            for (tri, t) in scene.tris.iter().enumerate() {
                let v = t.map(|k| {
                    let p = proj.snapped[k as usize];
                    [i64::from(p.x), i64::from(p.y)]
                });
                let area = (v[1][0] - v[0][0]) * (v[2][1] - v[0][1])
                    - (v[1][1] - v[0][1]) * (v[2][0] - v[0][0]);
                let side = usize::from(area > 0);
                if area == 0 || scene.face_sides[tri % 3][side] == HIDDEN {
                    continue;
                }
                if let Some((x0, x1, y0, y1)) = sample_box(&v, width, height)
                    && y0 < rows.end
                    && rows.start <= y1
                {
                    expected.push(tri as u32);
                    reach = (reach.0.min(x0 as u32), reach.1.max(x1 as u32));
                }
            }
            let got: Vec<u32> = bins.iter().flat_map(|c| c.ids[band].clone()).collect();
            assert_eq!(got, expected, "band {band}");
            let columns = (reach.0 <= reach.1).then_some((reach.0 as usize, reach.1 as usize));
            assert_eq!(band_columns(&bins, band), columns, "band {band}");
            listed += got.len();
        }
        assert!(listed > 20_000, "{listed} listed");
    }

    #[test]
    fn vector_binning_lists_what_scalar_binning_lists() {
        // Random triangles of every kind (tiny, a band or more high, huge,
        // off the picture, edge-on, beyond the vector lanes' ±2^30 reach,
        // in blocks of close neighbours),
        // two chunks and a part (so groups of eight and a tail), binned
        // eight at a time with AVX2 and one at a time: the same lists in
        // the same order and the same columns, for one pair of sides for
        // every face (each side seen or hidden) and sides per face.
        if !has_avx2() {
            eprintln!("no AVX2: only the scalar binning runs here");
            return;
        }
        let mut rng = crate::test_rng::TestRng::new(0xbb67_ae85_84ca_a73b);
        let (width, height, band_rows) = (93usize, 130usize, 16usize);
        let n = 2 * CHUNK + 4_467;
        let mut snapped = Vec::with_capacity(3 * n);
        let (mut local, mut block_centre) = (false, [0, 0]);
        for t in 0..n {
            // Half the blocks of 32 like a mesh's: small neighbours, so
            // that whole groups of eight join the band of the ones before.
            if t % 32 == 0 {
                local = rng.below(2) == 0;
                block_centre = [rng.below(16 * width) as i64, rng.below(16 * height) as i64];
            }
            let kind = if local { 8 } else { rng.below(8) };
            let (reach, centre) = match kind {
                8 => (24, block_centre),
                0..=2 => (30, [800, 1000]),
                3 => (500, [700, 900]),
                4 => (3000, [600, 1100]),
                5 => (1 << 28, [0, 0]),
                // Small, but about the lanes' reach (the scalar code's).
                6 => (1000, [1 << 30, -(1 << 30)]),
                _ => (40, [-700, 2200]),
            };
            let edge_on = rng.below(16);
            let mut corner = || Snapped {
                x: (centre[0] + rng.within(reach)) as i32,
                y: (centre[1] + rng.within(reach)) as i32,
                z: 0.5,
            };
            let (a, b) = (corner(), corner());
            // One in eight edge-on: its third corner repeats one or lies
            // on the line through both (not for the far kinds: doubling a
            // corner near 2^30 leaves `i32`).
            let c = match edge_on {
                0 => a,
                1 if kind != 5 && kind != 6 => Snapped {
                    x: 2 * b.x - a.x,
                    y: 2 * b.y - a.y,
                    z: 0.5,
                },
                _ => corner(),
            };
            snapped.extend([a, b, c]);
        }
        let tris: Vec<[u32; 3]> = (0..n as u32)
            .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
            .collect();
        let proj = Projected {
            snapped,
            xy_f: Vec::new(),
            xy_light: Vec::new(),
        };
        let mut scene = Scene {
            points: Vec::new().into(),
            tris: tris.into(),
            tri_face: (0..n as u32).map(|t| t % 3).collect(),
            one_face: None,
            face_sides: vec![[0, 1], [0, HIDDEN], [HIDDEN, 2]],
            same_sides: None,
            corner_slots: Vec::new().into(),
            light: Vec::new(),
            groups: Vec::new(),
        };
        let sides = [None, Some([0, 1]), Some([0, HIDDEN]), Some([HIDDEN, 1])];
        for same_sides in sides {
            scene.same_sides = same_sides;
            let scalar = bin_with(&scene, &proj, width, height, band_rows, false);
            let vector = bin_with(&scene, &proj, width, height, band_rows, true);
            let listed: usize = scalar.iter().flat_map(|c| &c.ids).map(Vec::len).sum();
            assert!(listed > 5_000, "{same_sides:?}: {listed} listed");
            assert_eq!(scalar.len(), vector.len());
            for (s, v) in scalar.iter().zip(&vector) {
                assert_eq!(s.ids, v.ids, "{same_sides:?}");
                assert_eq!(s.cols, v.cols, "{same_sides:?}");
            }
        }
    }

    #[test]
    fn sample_box_holds_the_covered_sample_centres() {
        // Corners in 1/16 sample steps: x 20..70 holds the centres of
        // samples 1..=3 (24, 40, 56), y 0..30 those of rows 0..=1 (8, 24).
        let v = [[20, 0], [70, 10], [30, 30]];
        assert_eq!(sample_box(&v, 100, 100), Some((1, 3, 0, 1)));
        // Clamped to a picture of 3 columns and 1 row.
        assert_eq!(sample_box(&v, 3, 1), Some((1, 2, 0, 0)));
        // Between two sample centres: nothing to draw.
        assert_eq!(sample_box(&[[9, 9], [20, 9], [9, 20]], 100, 100), None);
    }
}
