//! One triangle drawn into a band of the z-buffer: its sample box, its depth
//! plane and its three edge functions, then the samples of the box inside it.
//!
//! A million-triangle mesh gives triangles of a few samples each, so the
//! set-up per triangle, not the sample loop, is most of the drawing; the
//! set-up keeps few values live (corners relative to the first one) and a
//! triangle under `SMALL` snapped units across steps its three edges as
//! fields of one integer: one add per sample and one test of three sign
//! bits, instead of three adds and three tests. Where the processor has
//! AVX-512, `lanes` does the same eight triangles at a time.

use super::raster::Snapped;
use crate::cache_hint::prefetch_at;

#[cfg(target_arch = "x86_64")]
mod lanes;

/// Sub-sample steps per sample of the snapped coordinates.
pub const SUB: i64 = 16;

/// Triangles ahead whose corners are fetched while one is set up: a corner
/// is two dependent loads (the triangle, then its node), scattered over the
/// mesh.
const AHEAD: usize = 8;

/// Draws triangles `ids` of each chunk of `chunks` (corners `tris`, nodes
/// `nodes`) into rows `ys` of the z-buffer (stored from `rows[0]`, rows
/// `width` samples long): each sample inside a triangle keeps the smaller
/// of its value and the triangle's depth bits above `2 × triangle + back
/// side`. Edge-on triangles draw nothing.
///
/// # Safety
/// `ys.start <= ys.end` and `rows` holds at least `ys.len() × width`
/// samples: the sample loops index without bounds checks.
pub unsafe fn draw_chunks<'a>(
    rows: &mut [u64],
    width: usize,
    ys: std::ops::Range<usize>,
    tris: &[[u32; 3]],
    nodes: &[Snapped],
    chunks: impl Iterator<Item = &'a [u32]>,
) {
    #[cfg(target_arch = "x86_64")]
    let lanes = lanes::available();
    #[cfg(not(target_arch = "x86_64"))]
    let lanes = false;
    // SAFETY: the caller's promise.
    unsafe { draw_chunks_by(lanes, rows, width, ys, tris, nodes, chunks) }
}

/// [`draw_chunks`], eight triangles at a time in vector lanes when `lanes`
/// (the processor has AVX-512), else one after another (set up, then
/// filled: a batch of set-ups before their sample loops was slower).
///
/// # Safety
/// As [`draw_chunks`]; `lanes` only when [`lanes::available`].
unsafe fn draw_chunks_by<'a>(
    lanes: bool,
    rows: &mut [u64],
    width: usize,
    ys: std::ops::Range<usize>,
    tris: &[[u32; 3]],
    nodes: &[Snapped],
    chunks: impl Iterator<Item = &'a [u32]>,
) {
    #[cfg(target_arch = "x86_64")]
    if lanes {
        for ids in chunks {
            // SAFETY: the caller's promise; the processor has the
            // instructions.
            unsafe { lanes::draw_ids(rows, width, &ys, tris, nodes, ids) };
        }
        return;
    }
    for ids in chunks {
        for (i, &tri) in ids.iter().enumerate() {
            // Ahead: the triangle 16 places on, the corners of the one 8 on
            // (its triangle fetched 8 places ago), so the dependent loads
            // overlap. A band's ids in a chunk ascend, but by jumps (a ring
            // of the mesh to the next) the hardware does not follow.
            if let Some(&far) = ids.get(i + 2 * AHEAD) {
                prefetch_at(tris.as_ptr().wrapping_add(far as usize));
            }
            if let Some(near) = ids.get(i + AHEAD).and_then(|&t| tris.get(t as usize)) {
                for &c in near {
                    // A hint needs no bounds check: it reads nothing.
                    prefetch_at(nodes.as_ptr().wrapping_add(c as usize));
                }
            }
            let [a, b, c] = tris[tri as usize];
            let corners = [nodes[a as usize], nodes[b as usize], nodes[c as usize]];
            let mut small = Small::default();
            // SAFETY: the caller's promise; `set_up` places a small
            // triangle's box in the band.
            unsafe {
                if set_up(rows, width, &ys, corners, tri, &mut small) {
                    small.fill(rows.as_mut_ptr(), width);
                }
            }
        }
    }
}

/// A small triangle set up for its sample loop: its packed edges at the
/// box's first sample and their steps, the box's first sample in the band,
/// and what else the loop needs.
#[derive(Clone, Copy, Default)]
struct Small {
    outside: i64,
    sx: i64,
    sy: i64,
    first: usize,
    fill: Fill,
}

impl Small {
    /// # Safety
    /// The box from `rows.add(self.first)` lies in the band.
    #[inline(always)]
    unsafe fn fill(&self, rows: *mut u64, width: usize) {
        // A copy in registers: the stores to the band could alias `self`.
        let small = *self;
        // SAFETY: the caller's promise.
        unsafe {
            small.fill.packed(
                rows.add(small.first),
                width,
                small.outside,
                small.sx,
                small.sy,
            )
        }
    }
}

/// Sets up triangle `tri` with corners `t` for rows `ys` of the band:
/// a small one into `small` (true), a large one drawn at once; false when
/// it draws nothing or is drawn.
///
/// # Safety
/// `ys.start <= ys.end` and `rows` holds at least `ys.len() × width`
/// samples.
#[inline(always)]
unsafe fn set_up(
    rows: &mut [u64],
    width: usize,
    ys: &std::ops::Range<usize>,
    t: [Snapped; 3],
    tri: u32,
    small: &mut Small,
) -> bool {
    let (y0, y1) = (ys.start, ys.end);
    let [p, q, r] = t;
    let (ax, ay) = (p.x as i64, p.y as i64);
    // Corners b and c relative to a: the values the set-up keeps are small.
    let (qx, qy) = (q.x as i64 - ax, q.y as i64 - ay);
    let (rx, ry) = (r.x as i64 - ax, r.y as i64 - ay);
    let signed = qx * ry - qy * rx;
    if signed == 0 {
        return false;
    }
    // Image y points down, so a triangle counter-clockwise from the eye has
    // a negative area here: that is its front. b and c are ordered so that
    // the area is positive.
    let back = signed > 0;
    let (ux, uy, wx, wy, zb, zc) = if back {
        (qx, qy, rx, ry, q.z, r.z)
    } else {
        (rx, ry, qx, qy, r.z, q.z)
    };
    let area = signed.abs();
    let (lo_x, hi_x) = (0.min(ux).min(wx), 0.max(ux).max(wx));
    let (lo_y, hi_y) = (0.min(uy).min(wy), 0.max(uy).max(wy));
    // The sample centres (at i + 1/2 samples) within the bounding box,
    // clamped to the band and the picture.
    let sx0 = (ax + lo_x + SUB / 2 - 1).div_euclid(SUB);
    let sx1 = (ax + hi_x - SUB / 2).div_euclid(SUB).min(width as i64 - 1);
    let sy0 = (ay + lo_y + SUB / 2 - 1).div_euclid(SUB);
    let sy1 = (ay + hi_y - SUB / 2).div_euclid(SUB).min(y1 as i64 - 1);
    let (x_first, y_first) = (sx0.max(0), sy0.max(y0 as i64));
    if x_first > sx1 || y_first > sy1 {
        return false;
    }
    let plane = Plane::new(
        [p.z, zb, zc],
        [ux, uy, wx, wy],
        area,
        [sx0 * SUB + SUB / 2 - ax, sy0 * SUB + SUB / 2 - ay],
        [x_first - sx0, y_first - sy0],
    );
    let id = u64::from(tri) * 2 + u64::from(back);
    let (rows_n, row_len) = (sy1 - y_first, sx1 - x_first);
    let first = (y_first as usize - y0) * width + x_first as usize;
    // Edges a→b, b→c, c→a: E(p) = (end − start) × (p − start) is positive
    // inside. With p' = p − a: E_ab = u × p', E_bc = (w − u) × p' + area,
    // E_ca = −w × p', where d × p' = dx·p'y − dy·p'x.
    let (dx0, dy0) = (ux, uy);
    let (dx1, dy1) = (wx - ux, wy - uy);
    let (dx2, dy2) = (-wx, -wy);
    let px = x_first * SUB + SUB / 2 - ax;
    let py = y_first * SUB + SUB / 2 - ay;
    // A box within the band and the picture: under 2^32 samples each way.
    let (rows_n, row_len) = (rows_n as u32, row_len as u32);
    if hi_x - lo_x < SMALL && hi_y - lo_y < SMALL {
        let (dxs, dys) = (pack(dx0, dx1, dx2), pack(dy0, dy1, dy2));
        let owned = pack(
            not_owned(dx0, dy0),
            not_owned(dx1, dy1),
            not_owned(dx2, dy2),
        );
        let e = dxs
            .wrapping_mul(py)
            .wrapping_sub(dys.wrapping_mul(px))
            .wrapping_add(area << FIELD);
        // Field by field: a record built aside and copied in is read back
        // wider than it was written, which stalls the store forwarding.
        small.outside = BIAS.wrapping_add(owned).wrapping_sub(e);
        small.sx = dys.wrapping_mul(SUB);
        small.sy = dxs.wrapping_mul(-SUB);
        // The box's samples lie in rows y_first..=sy1 ⊂ y0..y1 and columns
        // x_first..=sx1 ⊂ 0..width, so every index from `first` is below
        // (y1 - y0) × width <= rows.len().
        small.first = first;
        small.fill.id = id;
        small.fill.plane = plane;
        small.fill.rows_n = rows_n;
        small.fill.row_len = row_len;
        true
    } else {
        let e = [
            dx0 * py - dy0 * px - not_owned(dx0, dy0),
            dx1 * py - dy1 * px + area - not_owned(dx1, dy1),
            dx2 * py - dy2 * px - not_owned(dx2, dy2),
        ];
        // SAFETY: as for the small triangle's box above.
        let fill = Fill {
            id,
            plane,
            rows_n,
            row_len,
        };
        unsafe {
            fill.wide(
                rows.as_mut_ptr().add(first),
                width,
                e,
                [-dy0 * SUB, -dy1 * SUB, -dy2 * SUB],
                [dx0 * SUB, dx1 * SUB, dx2 * SUB],
            )
        };
        false
    }
}

/// Triangles narrower and lower than this (snapped units, 32 samples) keep
/// every edge value of their box within ±2^19, so three fit one `i64`.
const SMALL: i64 = 1 << 9;
/// Bits per edge field of the packed edges.
const FIELD: u32 = 21;
/// Each field holds `2^20 − 1 − E` (E the edge value less its top-left
/// bias), in `0..2^21` for a small triangle's box: its bit 20 is set exactly
/// when the sample is outside that edge.
const BIAS: i64 = ((1 << 20) - 1) * (1 + (1 << FIELD) + (1 << (2 * FIELD)));
/// Bit 20 of each field.
const OUTSIDE: i64 = (1 << 20) * (1 + (1 << FIELD) + (1 << (2 * FIELD)));

/// Three edge values as fields of one integer (wrapping: a field may be
/// negative, the sum is exact modulo 2^64).
#[inline(always)]
fn pack(a: i64, b: i64, c: i64) -> i64 {
    a.wrapping_add(b << FIELD).wrapping_add(c << (2 * FIELD))
}

/// Top-left rule (y down): an edge going up, or horizontal going right,
/// owns the sample centres exactly on it, so of two triangles sharing an
/// edge exactly one draws them. It owns them when
/// `dy < 0 || (dy == 0 && dx > 0)`, that is when `dy·2^32 − dx < 0`
/// (|dx|, |dy| < 2^26): one sign instead of branches. 1 when the edge does
/// not own them.
#[inline(always)]
fn not_owned(dx: i64, dy: i64) -> i64 {
    1 + (((dy << 32) - dx) >> 63)
}

/// The depth over the box: `z_ref` at its first sample (the unclamped box
/// corner, so bands agree exactly), `dzdx`, `dzdy` per sample, and the
/// first drawn sample's offset from that corner.
#[derive(Clone, Copy, Default)]
struct Plane {
    z_ref: f32,
    dzdx: f32,
    dzdy: f32,
    off_x: i32,
    off_y: i32,
}

impl Plane {
    /// From the corners' depths `z`, b and c relative to a (`uw`, the
    /// triangle's positive orientation), twice its area, the box corner's
    /// sample centre relative to a (`r`) and the first drawn sample's
    /// offset from it (`off`).
    #[inline(always)]
    fn new(z: [f32; 3], uw: [i64; 4], area: i64, r: [i64; 2], off: [i64; 2]) -> Plane {
        let inv = 1.0 / area as f64;
        let (x1, y1, x2, y2) = (uw[0] as f64, uw[1] as f64, uw[2] as f64, uw[3] as f64);
        let (z1, z2) = ((z[1] - z[0]) as f64, (z[2] - z[0]) as f64);
        // dz per snapped unit, then per sample.
        let gx = (z1 * y2 - z2 * y1) * inv;
        let gy = (z2 * x1 - z1 * x2) * inv;
        let z_ref = z[0] as f64 + gx * r[0] as f64 + gy * r[1] as f64;
        Plane {
            z_ref: z_ref as f32,
            dzdx: (gx * SUB as f64) as f32,
            dzdy: (gy * SUB as f64) as f32,
            // Within the box: under 2^31 samples.
            off_x: off[0] as i32,
            off_y: off[1] as i32,
        }
    }
}

/// What the sample loops need of a triangle besides its edges: the box
/// (`rows_n + 1` rows of `row_len + 1` samples), the depth plane and the id.
#[derive(Clone, Copy, Default)]
struct Fill {
    id: u64,
    plane: Plane,
    rows_n: u32,
    row_len: u32,
}

impl Fill {
    /// The value of the sample `k` places along a row whose depth at its
    /// first drawn sample is `zy`, stored where it is nearer.
    ///
    /// # Safety
    /// `row.add(k)` is a sample of the band.
    #[inline(always)]
    unsafe fn store(&self, row: *mut u64, k: i64, zy: f32) {
        let depth = (zy + self.plane.dzdx * (k + i64::from(self.plane.off_x)) as f32).max(0.0);
        let value = (u64::from(depth.to_bits()) << 32) | self.id;
        // SAFETY: the caller's promise.
        let slot = unsafe { &mut *row.add(k as usize) };
        if value < *slot {
            *slot = value;
        }
    }

    /// The depth at the first drawn sample of box row `j`.
    #[inline(always)]
    fn row_depth(&self, j: i64) -> f32 {
        self.plane.z_ref + self.plane.dzdy * (j + i64::from(self.plane.off_y)) as f32
    }

    /// The sample loop over packed edges (`outside` at the first sample,
    /// `sx` and `sy` its steps per sample and per row; rows `width` apart).
    ///
    /// # Safety
    /// Every sample of the box from `row` lies in the band.
    #[inline(always)]
    unsafe fn packed(&self, mut row: *mut u64, width: usize, mut outside: i64, sx: i64, sy: i64) {
        let mut j = 0;
        loop {
            let zy = self.row_depth(j);
            let mut f = outside;
            let mut k = 0;
            loop {
                if f & OUTSIDE == 0 {
                    // SAFETY: k <= row_len, in the box.
                    unsafe { self.store(row, k, zy) };
                }
                if k == i64::from(self.row_len) {
                    break;
                }
                k += 1;
                f = f.wrapping_add(sx);
            }
            if j == i64::from(self.rows_n) {
                break;
            }
            j += 1;
            // SAFETY: j <= rows_n: the next row of the box.
            row = unsafe { row.add(width) };
            outside = outside.wrapping_add(sy);
        }
    }

    /// The sample loop over three `i64` edge values (`e` at the first
    /// sample, `sx` and `sy` their steps per sample and per row; rows
    /// `width` apart). Rare (large triangles), so not inlined into the
    /// set-up.
    ///
    /// # Safety
    /// Every sample of the box from `row` lies in the band.
    #[inline(never)]
    unsafe fn wide(
        &self,
        mut row: *mut u64,
        width: usize,
        mut e: [i64; 3],
        sx: [i64; 3],
        sy: [i64; 3],
    ) {
        let mut j = 0;
        loop {
            let zy = self.row_depth(j);
            let mut f = e;
            let mut k = 0;
            loop {
                if (f[0] | f[1] | f[2]) >= 0 {
                    // SAFETY: k <= row_len, in the box.
                    unsafe { self.store(row, k, zy) };
                }
                if k == i64::from(self.row_len) {
                    break;
                }
                k += 1;
                f = [f[0] + sx[0], f[1] + sx[1], f[2] + sx[2]];
            }
            if j == i64::from(self.rows_n) {
                break;
            }
            j += 1;
            // SAFETY: j <= rows_n: the next row of the box.
            row = unsafe { row.add(width) };
            e = [e[0] + sy[0], e[1] + sy[1], e[2] + sy[2]];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::raster::{EMPTY, depth_of};
    use crate::test_rng::TestRng;

    /// The samples of a `w`×`h` picture that `draw_chunks` fills with
    /// triangle `v`
    /// (snapped units, either orientation), corner depths `z`, id 7.
    fn drawn(v: [[i64; 2]; 3], z: [f32; 3], w: usize, h: usize) -> Vec<u64> {
        let mut rows = vec![EMPTY; w * h];
        let nodes = [0, 1, 2].map(|k| Snapped {
            x: v[k][0] as i32,
            y: v[k][1] as i32,
            z: z[k],
        });
        // Triangle 7 of a mesh whose others are edge-on.
        let mut tris = vec![[0, 0, 0]; 8];
        tris[7] = [0, 1, 2];
        // SAFETY: `rows` holds h × w samples.
        unsafe { draw_chunks(&mut rows, w, 0..h, &tris, &nodes, [&[7u32][..]].into_iter()) };
        rows
    }

    fn signed_area(v: [[i64; 2]; 3]) -> i64 {
        (v[1][0] - v[0][0]) * (v[2][1] - v[0][1]) - (v[1][1] - v[0][1]) * (v[2][0] - v[0][0])
    }

    /// Sample centre `(px, py)` (snapped units) inside `v` (positive area),
    /// an edge owning the centres on it when it goes up, or right when
    /// horizontal: the plain statement of the top-left rule.
    fn inside(v: [[i64; 2]; 3], px: i64, py: i64) -> bool {
        (0..3).all(|k| {
            let (a, b) = (v[k], v[(k + 1) % 3]);
            let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
            let e = dx * (py - a[1]) - dy * (px - a[0]);
            if dy < 0 || (dy == 0 && dx > 0) {
                e >= 0
            } else {
                e > 0
            }
        })
    }

    #[test]
    fn draw_fills_the_sample_centres_inside_by_the_top_left_rule() {
        let (w, h) = (40usize, 24usize);
        // A fixed pseudo-random sequence of triangles: small ones (the
        // packed edges, some close to `SMALL` across) and ones reaching far
        // outside the picture (the wide edges), in both orientations.
        let mut rng = TestRng::new(0x2545_f491_4f6c_dd1d);
        let (mut filled, mut wide, mut near_limit) = (0, 0, 0);
        for round in 0..600 {
            let reach = [120, 255, 1 << 20][round % 3];
            let c = [rng.within(300) + 320, rng.within(200) + 190];
            let v = [0, 1, 2].map(|_| [c[0] + rng.within(reach), c[1] + rng.within(reach)]);
            let area = signed_area(v);
            if area == 0 {
                continue;
            }
            let span = |d: usize| {
                let (lo, hi) = (v.iter().map(|p| p[d]).min(), v.iter().map(|p| p[d]).max());
                hi.unwrap_or(0) - lo.unwrap_or(0)
            };
            let extent = span(0).max(span(1));
            wide += usize::from(extent >= SMALL);
            near_limit += usize::from((400..SMALL).contains(&extent));
            let positive = if area < 0 { [v[0], v[2], v[1]] } else { v };
            let rows = drawn(v, [0.25; 3], w, h);
            for (i, &value) in rows.iter().enumerate() {
                let (px, py) = (
                    (i % w) as i64 * SUB + SUB / 2,
                    (i / w) as i64 * SUB + SUB / 2,
                );
                let expected = inside(positive, px, py);
                assert_eq!(value != EMPTY, expected, "triangle {v:?}, sample {i}");
                if expected {
                    filled += 1;
                    let id = 7 * 2 + u64::from(area > 0);
                    assert_eq!((depth_of(value), value & 0xffff_ffff), (0.25, id));
                }
            }
        }
        assert!(
            wide > 150 && near_limit > 30 && filled > 50_000,
            "{wide} wide, {near_limit} near the packed limit, {filled} filled"
        );
    }

    #[test]
    fn two_triangles_sharing_an_edge_fill_each_sample_once() {
        // Squares split along a diagonal through sample centres, small
        // (packed edges) and large (wide edges): every sample of the square
        // is filled by exactly one half.
        for (size, w) in [(64i64, 8usize), (20_000, 1300)] {
            let (a, b, c, d) = ([0, 0], [size, 0], [size, size], [0, size]);
            for halves in [[[a, b, c], [a, c, d]], [[b, c, d], [b, d, a]]] {
                let [one, two] = halves.map(|t| drawn(t, [0.5; 3], w, 8));
                let n = (size / SUB) as usize;
                for y in 0..8.min(n) {
                    for x in 0..n.min(w) {
                        let i = y * w + x;
                        let count = usize::from(one[i] != EMPTY) + usize::from(two[i] != EMPTY);
                        assert_eq!(count, 1, "size {size}, sample ({x}, {y})");
                    }
                }
            }
        }
    }

    #[test]
    fn depths_follow_the_plane_through_the_corners() {
        // Depth 0.1 at x = 0 rising by 0.5 per 1000 samples in x and 0.25
        // in y, on a small and a large triangle: each drawn sample's depth
        // is the plane's at its centre within f32 rounding.
        let depth = |x: f64, y: f64| 0.1 + (0.5 * x + 0.25 * y) / (1000.0 * SUB as f64);
        for v in [
            [[8, 8], [300, 40], [60, 250]],
            [[-5000, -900], [90_000, 300], [2_000, 70_000]],
        ] {
            let z = v.map(|p| depth(p[0] as f64, p[1] as f64) as f32);
            let rows = drawn(v, z, 30, 20);
            let mut checked = 0;
            for (i, &value) in rows.iter().enumerate().filter(|(_, v)| **v != EMPTY) {
                let (px, py) = ((i % 30) as f64 * 16.0 + 8.0, (i / 30) as f64 * 16.0 + 8.0);
                let expected = depth(px, py);
                assert!(
                    (f64::from(depth_of(value)) - expected).abs() < 1e-6,
                    "{v:?}, sample {i}: {} against {expected}",
                    depth_of(value)
                );
                checked += 1;
            }
            assert!(checked > 80, "{v:?}: {checked} samples");
        }
    }

    #[test]
    fn lanes_draw_every_list_length_as_the_scalar_code() {
        // Band lists of every length from 0 to 41 (no group, one partial
        // group, whole groups and a partial last one), ids in random order
        // with repeats, on a picture whose rows and end are not at
        // multiples of eight samples (the lanes' blocks straddle rows, and
        // the last one passes the end): the lanes fill what the scalar code
        // fills.
        let mut rng = TestRng::new(0x1405_7b7e_f767_814f);
        let (w, h) = (45usize, 41usize);
        let (mut nodes, mut tris) = (Vec::new(), Vec::new());
        for t in 0..300u32 {
            // Mostly small triangles, some up to 30 samples across (box
            // rows of several blocks), every seventh a large one.
            let c = [rng.within(380) + 360, rng.within(340) + 328];
            let reach = match t % 7 {
                0 => 3000,
                1 | 4 => 230,
                _ => 50,
            };
            for _ in 0..3 {
                nodes.push(Snapped {
                    x: (c[0] + rng.within(reach)) as i32,
                    y: (c[1] + rng.within(reach)) as i32,
                    z: rng.within(1000) as f32 / 1000.0,
                });
            }
            tris.push([3 * t, 3 * t + 1, 3 * t + 2]);
        }
        let ids: Vec<u32> = (0..41).map(|_| (rng.within(149) + 149) as u32).collect();
        let mut drawn_samples = 0;
        for len in 0..=ids.len() {
            let draw = |lanes: bool| {
                let mut picture = vec![EMPTY; w * h];
                // SAFETY: `picture` holds the band's samples; `lanes` only
                // where the processor has them.
                unsafe {
                    draw_chunks_by(
                        lanes,
                        &mut picture,
                        w,
                        0..h,
                        &tris,
                        &nodes,
                        [&ids[..len]].into_iter(),
                    )
                };
                picture
            };
            let scalar = draw(false);
            drawn_samples += scalar.iter().filter(|&&v| v != EMPTY).count();
            #[cfg(target_arch = "x86_64")]
            if lanes::available() {
                assert!(draw(true) == scalar, "{len} ids: the pictures differ");
            }
        }
        assert!(drawn_samples > 4000, "{drawn_samples} samples drawn");
    }

    #[test]
    fn lanes_draw_the_bits_the_scalar_code_draws() {
        // Many triangles over several bands: small ones (some sharing
        // corners, some near the packed limit), large ones, both
        // orientations, depths below 0 (stored as 0) and above 1. Batches
        // of eight and the partial last one, boxes wider than eight samples
        // and clipped at every side of the picture and the band.
        let mut rng = TestRng::new(0x9e37_79b9_7f4a_7c15);
        let (w, h, band) = (75usize, 61usize, 16usize);
        let mut nodes = Vec::new();
        let mut tris = Vec::new();
        for t in 0..3001u32 {
            let c = [rng.within(700) + 600, rng.within(600) + 490];
            let reach = [40, 200, 500, 3000][t as usize % 4];
            for _ in 0..3 {
                nodes.push(Snapped {
                    x: (c[0] + rng.within(reach)) as i32,
                    y: (c[1] + rng.within(reach)) as i32,
                    z: rng.within(1200) as f32 / 1000.0,
                });
            }
            let n = 3 * t;
            tris.push(if t % 5 == 4 {
                [n, n - 2, n - 1]
            } else {
                [n, n + 1, n + 2]
            });
        }
        let ids: Vec<u32> = (0..tris.len() as u32).collect();
        let draw = |lanes: bool| {
            let mut picture = vec![EMPTY; w * h];
            for (b, rows) in picture.chunks_mut(w * band).enumerate() {
                let ys = b * band..(b * band + band).min(h);
                // SAFETY: `rows` holds the band's samples; `lanes` only
                // where the processor has them.
                unsafe { draw_chunks_by(lanes, rows, w, ys, &tris, &nodes, ids.chunks(1000)) };
            }
            picture
        };
        let scalar = draw(false);
        let filled = scalar.iter().filter(|&&v| v != EMPTY).count();
        let zeros = scalar
            .iter()
            .filter(|&&v| v != EMPTY && depth_of(v) == 0.0)
            .count();
        assert!(
            filled > 4000 && zeros > 100,
            "{filled} filled, {zeros} at depth 0"
        );
        #[cfg(target_arch = "x86_64")]
        if lanes::available() {
            let lanes = draw(true);
            let differ = (0..w * h).filter(|&i| lanes[i] != scalar[i]).count();
            assert_eq!(differ, 0, "samples differ");
        }
    }
}
