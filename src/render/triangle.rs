//! One triangle drawn into a band of the z-buffer: its sample box, its depth
//! plane and its three edge functions, then the samples of the box inside it.
//!
//! A million-triangle mesh gives triangles of a few samples each, so the
//! set-up per triangle, not the sample loop, is most of the drawing; the
//! set-up keeps few values live (corners relative to the first one) and a
//! triangle under `SMALL` snapped units across steps its three edges as
//! fields of one integer: one add per sample and one test of three sign
//! bits, instead of three adds and three tests.

use super::raster::Snapped;

/// Sub-sample steps per sample of the snapped coordinates.
pub const SUB: i64 = 16;

/// Fills the samples of rows `y0..y1` (stored from `rows[0]`) inside
/// triangle `tri` with corners `t` where it is nearer than what is there:
/// each sample keeps the smaller of its value and the triangle's depth bits
/// above `2 × tri + back side`. Edge-on triangles draw nothing.
///
/// # Safety
/// `y0 <= y1` and `rows` holds at least `(y1 - y0) × width` samples: the
/// sample loops index without bounds checks.
#[inline(always)]
pub unsafe fn draw(
    rows: &mut [u64],
    width: usize,
    y0: usize,
    y1: usize,
    t: [Snapped; 3],
    tri: u32,
) {
    let [p, q, r] = t;
    let (ax, ay) = (p.x as i64, p.y as i64);
    // Corners b and c relative to a: the values the set-up keeps are small.
    let (qx, qy) = (q.x as i64 - ax, q.y as i64 - ay);
    let (rx, ry) = (r.x as i64 - ax, r.y as i64 - ay);
    let signed = qx * ry - qy * rx;
    if signed == 0 {
        return;
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
        return;
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
    let fill = Fill {
        width,
        rows_n,
        row_len,
        plane,
        id,
    };
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
        let outside = BIAS.wrapping_add(owned).wrapping_sub(e);
        // SAFETY: the box's samples lie in rows y_first..=sy1 ⊂ y0..y1 and
        // columns x_first..=sx1 ⊂ 0..width, so every index from `first` is
        // below (y1 - y0) × width <= rows.len() (the caller's promise).
        unsafe {
            fill.packed(
                rows.as_mut_ptr().add(first),
                outside,
                dys.wrapping_mul(SUB),
                dxs.wrapping_mul(-SUB),
            )
        }
    } else {
        let e = [
            dx0 * py - dy0 * px - not_owned(dx0, dy0),
            dx1 * py - dy1 * px + area - not_owned(dx1, dy1),
            dx2 * py - dy2 * px - not_owned(dx2, dy2),
        ];
        // SAFETY: as for the packed fill above.
        unsafe {
            fill.wide(
                rows.as_mut_ptr().add(first),
                e,
                [-dy0 * SUB, -dy1 * SUB, -dy2 * SUB],
                [dx0 * SUB, dx1 * SUB, dx2 * SUB],
            )
        }
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
struct Plane {
    z_ref: f32,
    dzdx: f32,
    dzdy: f32,
    off_x: i64,
    off_y: i64,
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
            off_x: off[0],
            off_y: off[1],
        }
    }
}

/// What the sample loops need of a triangle besides its edges: the box
/// (`rows_n + 1` rows of `row_len + 1` samples, rows `width` apart), the
/// depth plane and the id.
struct Fill {
    width: usize,
    rows_n: i64,
    row_len: i64,
    plane: Plane,
    id: u64,
}

impl Fill {
    /// The value of the sample `k` places along a row whose depth at its
    /// first drawn sample is `zy`, stored where it is nearer.
    ///
    /// # Safety
    /// `row.add(k)` is a sample of the band.
    #[inline(always)]
    unsafe fn store(&self, row: *mut u64, k: i64, zy: f32) {
        let depth = (zy + self.plane.dzdx * (k + self.plane.off_x) as f32).max(0.0);
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
        self.plane.z_ref + self.plane.dzdy * (j + self.plane.off_y) as f32
    }

    /// The sample loop over packed edges (`outside` at the first sample,
    /// `sx` and `sy` its steps per sample and per row).
    ///
    /// # Safety
    /// Every sample of the box from `row` lies in the band.
    #[inline(always)]
    unsafe fn packed(&self, mut row: *mut u64, mut outside: i64, sx: i64, sy: i64) {
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
                if k == self.row_len {
                    break;
                }
                k += 1;
                f = f.wrapping_add(sx);
            }
            if j == self.rows_n {
                break;
            }
            j += 1;
            // SAFETY: j <= rows_n: the next row of the box.
            row = unsafe { row.add(self.width) };
            outside = outside.wrapping_add(sy);
        }
    }

    /// The sample loop over three `i64` edge values (`e` at the first
    /// sample, `sx` and `sy` their steps per sample and per row).
    ///
    /// # Safety
    /// Every sample of the box from `row` lies in the band.
    #[inline(always)]
    unsafe fn wide(&self, mut row: *mut u64, mut e: [i64; 3], sx: [i64; 3], sy: [i64; 3]) {
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
                if k == self.row_len {
                    break;
                }
                k += 1;
                f = [f[0] + sx[0], f[1] + sx[1], f[2] + sx[2]];
            }
            if j == self.rows_n {
                break;
            }
            j += 1;
            // SAFETY: j <= rows_n: the next row of the box.
            row = unsafe { row.add(self.width) };
            e = [e[0] + sy[0], e[1] + sy[1], e[2] + sy[2]];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::raster::{EMPTY, depth_of};

    /// The samples of a `w`×`h` picture that `draw` fills with triangle `v`
    /// (snapped units, either orientation), corner depths `z`, id 7.
    fn drawn(v: [[i64; 2]; 3], z: [f32; 3], w: usize, h: usize) -> Vec<u64> {
        let mut rows = vec![EMPTY; w * h];
        let t = [0, 1, 2].map(|k| Snapped {
            x: v[k][0] as i32,
            y: v[k][1] as i32,
            z: z[k],
        });
        // SAFETY: `rows` holds h × w samples.
        unsafe { draw(&mut rows, w, 0, h, t, 7) };
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
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut next = |range: i64| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed % (2 * range as u64 + 1)) as i64 - range
        };
        let (mut filled, mut wide, mut near_limit) = (0, 0, 0);
        for round in 0..600 {
            let reach = [120, 255, 1 << 20][round % 3];
            let c = [next(300) + 320, next(200) + 190];
            let v = [0, 1, 2].map(|_| [c[0] + next(reach), c[1] + next(reach)]);
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
}
