//! Shading a visible sample: its triangle side's group colour times the light
//! interpolated at the sample. A picture shades about one sample per covered
//! pixel (a third of a million for the bench's torus), so what every call
//! would look up again is looked up once per band: the slices are cut to
//! common lengths (one bounds check then serves several gathers), the
//! triangle is read once when its light slots are its own nodes (smooth
//! shading of one face), and when every face shows the same pair of groups
//! each side's colour is kept as the float lanes [`tint`] multiplies. The
//! same arithmetic in the same order as the plain lookups, so the same bytes.

use super::project::XyLight;
use super::raster::Projected;
use super::scene::{HIDDEN, Scene};
use crate::cache_hint::prefetch_at;

mod lanes;
#[cfg(target_arch = "x86_64")]
mod record_lanes;
pub(super) use lanes::Queue;

/// Pixels ahead whose triangle's corners are fetched while one is shaded.
const AHEAD: usize = 8;

/// What one side of a triangle shows: its group's colour as `f32` lanes
/// (exact: every `u8` is an `f32`) and whether it is a section cap.
#[derive(Clone, Copy)]
struct Look {
    color: [f32; 4],
    cap: bool,
}

impl Look {
    /// Looked up per call only when faces show different groups: out of
    /// line, off the common path of [`Shader::shade`].
    #[cold]
    #[inline(never)]
    fn of(scene: &Scene, group: u32) -> Look {
        let group = &scene.groups[group as usize];
        let [r, g, b] = group.color;
        Look {
            color: [r as f32, g as f32, b as f32, 0.0],
            cap: group.cap,
        }
    }
}

/// The lookups of [`Shader::shade`], prepared for one band of pixels.
pub(super) struct Shader<'s, 'a> {
    scene: &'s Scene<'a>,
    /// The triangles and their light slots, cut to one length.
    tris: &'s [[u32; 3]],
    slots: &'s [[u32; 3]],
    /// The slots are the triangles themselves (one face, smooth).
    own_slots: bool,
    /// The nodes' unsnapped positions and the slots' light; cut to one
    /// length when the slots are the nodes.
    xy: &'s [[f32; 2]],
    light: &'s [[f32; 2]],
    /// Each node's position and light in one record, when the slots are
    /// the nodes and the projection made them (`xy` is then empty); empty
    /// otherwise.
    records: &'s [XyLight],
    /// Front and back when every face shows the same groups (`None` for a
    /// side that is looked up per triangle).
    sides: [Option<Look>; 2],
    /// The front and back colours when eight pixels can be shaded at once
    /// ([`lanes`]: AVX2, the sides known and neither a cap, indices that
    /// fit AVX2's 32-bit gathers).
    lane_colors: Option<[[f32; 4]; 2]>,
}

impl<'s, 'a> Shader<'s, 'a> {
    pub(super) fn new(scene: &'s Scene<'a>, proj: &'s Projected) -> Shader<'s, 'a> {
        let own_slots = std::ptr::eq(scene.corner_slots.as_ptr(), scene.tris.as_ptr());
        let k = scene.tris.len().min(scene.corner_slots.len());
        let records = if own_slots { &proj.xy_light[..] } else { &[] };
        let (mut xy, mut light) = (&proj.xy_f[..], &scene.light[..]);
        if own_slots {
            let m = xy.len().min(light.len());
            (xy, light) = (&xy[..m], &light[..m]);
        }
        let sides = match scene.same_sides {
            Some(pair) => pair.map(|g| (g != HIDDEN).then(|| Look::of(scene, g))),
            None => [None; 2],
        };
        // A side no face shows (hidden) takes the other's colour: a lane
        // showing it falls back to `shade` (see `lanes`).
        let lane_colors = match sides {
            [Some(front), Some(back)] => Some([front, back]),
            [Some(look), None] | [None, Some(look)] => Some([look; 2]),
            [None, None] => None,
        }
        .filter(|[front, back]| {
            !front.cap
                && !back.cap
                && k <= i32::MAX as usize / 3
                && xy.len().max(scene.light.len()) <= i32::MAX as usize / 2
                && records.len() <= i32::MAX as usize / 4
                && avx2()
        })
        .map(|looks| looks.map(|look| look.color));
        Shader {
            scene,
            tris: &scene.tris[..k],
            slots: &scene.corner_slots[..k],
            own_slots,
            xy,
            light,
            records,
            sides,
            lane_colors,
        }
    }

    /// Whether one-surface pixels can be shaded eight at a time ([`lanes`]).
    pub(super) fn shades_lanes(&self) -> bool {
        self.lane_colors.is_some()
    }

    /// The colour of sample (`sx`, `sy`) of pixel (`px`, `py`) showing
    /// triangle side `id` (`2 × triangle + back`). Not inlined: in the
    /// resolver's pixel loop its registers would push the pixel's samples
    /// onto the stack, and reading them back costs more than the call.
    #[inline(never)]
    pub(super) fn shade(&self, id: u64, sx: usize, sy: usize, px: usize, py: usize) -> [u8; 3] {
        let tri = (id >> 1) as usize;
        let back = (id & 1) as usize;
        let look = match self.sides[back] {
            Some(look) => look,
            None => Look::of(self.scene, self.scene.side_group(tri, back)),
        };
        let light = if look.cap {
            // Section caps are flat and hatched, as drawings show cut material.
            if (px + py) % 8 < 2 { 0.6 } else { 0.95 }
        } else {
            self.light_at(tri, back, sx, sy)
        };
        tint(look.color, light)
    }

    /// The light of triangle `tri`'s side `back` at sample (`sx`, `sy`).
    #[inline(always)]
    fn light_at(&self, tri: usize, back: usize, sx: usize, sy: usize) -> f32 {
        let t = self.tris[tri];
        if !self.records.is_empty() {
            return interpolate_records(self.records, t, back, sx, sy);
        }
        if self.own_slots {
            // The light cut to the positions' length (it is that length
            // already): a corner's position check then covers its light.
            let light = &self.light[..self.xy.len()];
            interpolate(self.xy, light, t, t, back, sx, sy)
        } else {
            self.slot_light(t, self.slots[tri], back, sx, sy)
        }
    }

    /// [`interpolate`] with light slots of their own (flat shading, several
    /// faces, a section): out of line, as [`Look::of`] is.
    #[inline(never)]
    fn slot_light(&self, t: [u32; 3], s: [u32; 3], back: usize, sx: usize, sy: usize) -> f32 {
        interpolate(self.xy, self.light, t, s, back, sx, sy)
    }

    /// Whether side `id` (`2 × triangle + back`), of group `group`, shows
    /// a section cap: known per side when every face shows the same groups.
    #[inline(always)]
    pub(super) fn is_cap(&self, id: u64, group: u32) -> bool {
        match self.sides[(id & 1) as usize] {
            Some(look) => look.cap,
            None => self.scene.groups[group as usize].cap,
        }
    }

    /// Fetches what shading a pixel ahead will gather: a triangle, then its
    /// corners' positions and light. The triangle of the pixel 16 ahead and
    /// the corners of the one 8 ahead, so the loads overlap (`first_tri`
    /// gives the triangle at a pixel's first sample; `end` ends the row's
    /// columns). A hint needs no bounds check: it reads nothing.
    #[inline(always)]
    pub(super) fn prefetch_ahead(
        &self,
        px: usize,
        end: usize,
        first_tri: impl Fn(usize) -> Option<usize>,
    ) {
        if let Some(tri) = (px + 2 * AHEAD < end)
            .then(|| first_tri(px + 2 * AHEAD))
            .flatten()
        {
            prefetch_at(self.tris.as_ptr().wrapping_add(tri));
            if !self.own_slots {
                prefetch_at(self.slots.as_ptr().wrapping_add(tri));
            }
        }
        if let Some(tri) = (px + AHEAD < end).then(|| first_tri(px + AHEAD)).flatten() {
            let Some(&t) = self.tris.get(tri) else {
                return;
            };
            if !self.records.is_empty() {
                for n in t {
                    prefetch_at(self.records.as_ptr().wrapping_add(n as usize));
                }
                return;
            }
            let s = if self.own_slots { t } else { self.slots[tri] };
            for (n, slot) in t.into_iter().zip(s) {
                prefetch_at(self.xy.as_ptr().wrapping_add(n as usize));
                prefetch_at(self.light.as_ptr().wrapping_add(slot as usize));
            }
        }
    }
}

/// Whether the machine has AVX2 (for [`lanes`]).
fn avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// The light at sample (`sx`, `sy`) of a triangle with corners `t` and
/// light slots `s`: one slot's light when they are all one, else the
/// corners' light weighted by the sample's barycentric coordinates.
#[inline(always)]
fn interpolate(
    xy: &[[f32; 2]],
    light: &[[f32; 2]],
    t: [u32; 3],
    s: [u32; 3],
    back: usize,
    sx: usize,
    sy: usize,
) -> f32 {
    if s[0] == s[1] && s[1] == s[2] {
        return light[s[0] as usize][back];
    }
    let (a, b, c) = (xy[t[0] as usize], xy[t[1] as usize], xy[t[2] as usize]);
    // Sample indices are below 2^17, so `u32` to `f32` is exact, as
    // `usize` to `f32` is, in one conversion instead of six.
    let (x, y) = (sx as u32 as f32 + 0.5, sy as u32 as f32 + 0.5);
    let [w1, w2] = weights(a, b, c, x, y);
    let w0 = (1.0 - w1 - w2).max(0.0);
    let l = |k: usize| light[s[k] as usize][back];
    w0 * l(0) + w1 * l(1) + w2 * l(2)
}

/// [`interpolate`] of a triangle whose corners are their own light slots,
/// each corner's position and light read from its record: the same
/// arithmetic in the same order, so the same bits.
#[inline(always)]
fn interpolate_records(records: &[XyLight], t: [u32; 3], back: usize, sx: usize, sy: usize) -> f32 {
    if t[0] == t[1] && t[1] == t[2] {
        return records[t[0] as usize].light[back];
    }
    let (a, b, c) = (
        records[t[0] as usize],
        records[t[1] as usize],
        records[t[2] as usize],
    );
    let (x, y) = (sx as u32 as f32 + 0.5, sy as u32 as f32 + 0.5);
    let [w1, w2] = weights(a.xy, b.xy, c.xy, x, y);
    let w0 = (1.0 - w1 - w2).max(0.0);
    w0 * a.light[back] + w1 * b.light[back] + w2 * c.light[back]
}

/// The barycentric weights of corners `b` and `c` at (`x`, `y`), each
/// clamped to [0, 1] (a NaN stays NaN, as `f32::clamp` keeps it). With SSE2
/// the two divisions are one two-lane division (one waits on the divider
/// instead of two): the same operations per lane, so the same bits.
#[inline(always)]
fn weights(a: [f32; 2], b: [f32; 2], c: [f32; 2], x: f32, y: f32) -> [f32; 2] {
    #[cfg(target_arch = "x86_64")]
    {
        // SAFETY: SSE2 is part of every x86-64.
        unsafe { weights_sse2(a, b, c, x, y) }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        scalar_weights(a, b, c, x, y)
    }
}

#[cfg_attr(target_arch = "x86_64", allow(dead_code))]
#[inline]
fn scalar_weights(a: [f32; 2], b: [f32; 2], c: [f32; 2], x: f32, y: f32) -> [f32; 2] {
    let area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
    let w1 = ((c[0] - a[0]) * (y - a[1]) - (c[1] - a[1]) * (x - a[0])) / -area;
    let w2 = ((b[0] - a[0]) * (y - a[1]) - (b[1] - a[1]) * (x - a[0])) / area;
    [w1.clamp(0.0, 1.0), w2.clamp(0.0, 1.0)]
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "sse2")]
#[inline]
fn weights_sse2(a: [f32; 2], b: [f32; 2], c: [f32; 2], x: f32, y: f32) -> [f32; 2] {
    use std::arch::x86_64::*;
    let pair = |p: [f32; 2]| _mm_setr_ps(p[0], p[1], 0.0, 0.0);
    // Lanes (c.x − a.x, b.x − a.x, c.y − a.y, b.y − a.y).
    let d = _mm_sub_ps(
        _mm_unpacklo_ps(pair(c), pair(b)),
        _mm_unpacklo_ps(pair(a), pair(a)),
    );
    let dy = _mm_movehl_ps(d, d);
    // Lane 0 is w1's numerator, lane 1 w2's, each as `scalar_weights` has it.
    let num = _mm_sub_ps(
        _mm_mul_ps(d, _mm_set1_ps(y - a[1])),
        _mm_mul_ps(dy, _mm_set1_ps(x - a[0])),
    );
    // Lane 0 (c.x − a.x)(b.y − a.y), lane 1 (b.x − a.x)(c.y − a.y): the
    // area is lane 1 less lane 0, the scalar products in its order.
    const DY_SWAPPED: i32 = 0b10_11_10_11;
    let p = _mm_mul_ps(d, _mm_shuffle_ps::<DY_SWAPPED>(d, d));
    let area = _mm_sub_ss(_mm_shuffle_ps::<0b01_01_01_01>(p, p), p);
    // (−area, area, area, area): the negation flips the sign bit, as `-`
    // does (a zero area gives −0 and +0, so ±infinity as the scalar code).
    let den = _mm_xor_ps(
        _mm_shuffle_ps::<0>(area, area),
        _mm_setr_ps(-0.0, 0.0, 0.0, 0.0),
    );
    let w = _mm_div_ps(num, den);
    // `maxps 0, w` is `0 > w ? 0 : w` and `minps 1, v` is `1 < v ? 1 : v`:
    // a NaN and −0 pass through both, as through `f32::clamp`.
    let w = _mm_min_ps(_mm_set1_ps(1.0), _mm_max_ps(_mm_setzero_ps(), w));
    [
        _mm_cvtss_f32(w),
        _mm_cvtss_f32(_mm_shuffle_ps::<0b01_01_01_01>(w, w)),
    ]
}

/// `color` (lanes r, g, b, 0) times `light`, each channel rounded by adding
/// a half (the value is not negative, `as` saturates at 255, and
/// `f32::round` is a library call). With SSE2 the three channels are lanes of
/// one vector: the same multiplication and addition per lane, and a
/// conversion that gives what `as u8` gives for every value (NaN and
/// negatives 0, above 255 255).
#[inline(always)]
pub(super) fn tint(color: [f32; 4], light: f32) -> [u8; 3] {
    #[cfg(target_arch = "x86_64")]
    {
        // SAFETY: SSE2 is part of every x86-64.
        unsafe { tint_sse2(color, light) }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        scalar_tint(color, light)
    }
}

#[cfg_attr(target_arch = "x86_64", allow(dead_code))]
#[inline]
fn scalar_tint(color: [f32; 4], light: f32) -> [u8; 3] {
    [0, 1, 2].map(|k| (color[k] * light + 0.5) as u8)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "sse2")]
#[inline]
fn tint_sse2(color: [f32; 4], light: f32) -> [u8; 3] {
    use std::arch::x86_64::*;
    // SAFETY: `color` is four f32s.
    let channels = unsafe { _mm_loadu_ps(color.as_ptr()) };
    let lit = _mm_add_ps(_mm_mul_ps(channels, _mm_set1_ps(light)), _mm_set1_ps(0.5));
    // `minps 255, v` is `255 < v ? 255 : v`: a NaN stays NaN, and
    // truncation turns it (and anything below −2^31) into i32::MIN, which
    // the two saturating packs turn into 0, as they do every negative.
    let ints = _mm_cvttps_epi32(_mm_min_ps(_mm_set1_ps(255.0), lit));
    let bytes = _mm_packus_epi16(_mm_packs_epi32(ints, ints), _mm_setzero_si128());
    let [r, g, b, _] = _mm_cvtsi128_si32(bytes).to_le_bytes();
    [r, g, b]
}

#[cfg(test)]
mod tests {
    use super::super::scene::Group;
    use super::*;
    use std::borrow::Cow;

    #[test]
    fn tint_is_the_scalar_rounding_for_every_light() {
        let mut lights: Vec<f32> = (0..=2000).map(|i| i as f32 / 1000.0).collect();
        lights.extend([
            -0.0,
            -0.001,
            -1.5,
            0.498_039_2,
            1.000_000_1,
            3.0,
            1e30,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
            f32::MIN_POSITIVE,
        ]);
        let lanes = |c: [u8; 3]| [c[0] as f32, c[1] as f32, c[2] as f32, 0.0];
        let mut saturated = 0;
        for light in lights {
            for c in (0..=255u8).step_by(17).chain([1, 254]) {
                let color = [c, 255 - c, c / 3];
                // The plain rounding of each `u8` channel.
                let want = color.map(|c| (c as f32 * light + 0.5) as u8);
                assert_eq!(tint(lanes(color), light), want, "{color:?} × {light}");
                assert_eq!(scalar_tint(lanes(color), light), want);
                saturated += usize::from(want.contains(&255) && light > 1.0);
            }
        }
        assert!(saturated > 0);
        assert_eq!(tint(lanes([200, 100, 50]), 0.5), [100, 50, 25]);
        assert_eq!(tint(lanes([255, 255, 255]), f32::NAN), [0, 0, 0]);
        assert_eq!(tint(lanes([3, 255, 128]), 2.0), [6, 255, 255]);
    }

    #[test]
    fn two_lane_weights_are_the_scalar_weights_bit_for_bit() {
        let mut rng = crate::test_rng::TestRng::new(0x2545_f491_4f6c_dd1d);
        let mut coordinate =
            |scale: f32| (rng.next_u64() >> 40) as f32 / (1u64 << 24) as f32 * scale;
        let mut checked = 0;
        let mut clamped = [0usize; 2];
        for round in 0..20_000 {
            let scale = [1.0, 37.0, 2048.0, 1e-3][round % 4];
            let [a, b, mut c] = [0; 3].map(|_| [coordinate(scale), coordinate(scale)]);
            if round % 7 == 0 {
                // Collinear corners: a zero area, each sign of it.
                c = [2.0 * b[0] - a[0], 2.0 * b[1] - a[1]];
            }
            let (x, y) = (coordinate(scale), coordinate(scale));
            let got = weights(a, b, c, x, y);
            let want = scalar_weights(a, b, c, x, y);
            assert_eq!(
                got.map(f32::to_bits),
                want.map(f32::to_bits),
                "{a:?} {b:?} {c:?}"
            );
            checked += 1;
            for k in 0..2 {
                clamped[k] += usize::from(want[k] == 0.0 || want[k] == 1.0);
            }
        }
        // Degenerate and outside samples: NaN, the infinities clamped.
        let odd = [
            ([0.0, 0.0], [1.0, 1.0], [2.0, 2.0], 0.5, 0.5),
            ([0.0, 0.0], [1.0, 1.0], [2.0, 2.0], 0.5, 0.0),
            ([0.0, 0.0], [0.0, 0.0], [0.0, 0.0], 0.0, 0.0),
            ([f32::NAN, 0.0], [1.0, 0.0], [0.0, 1.0], 0.2, 0.2),
            ([0.0, 0.0], [f32::INFINITY, 0.0], [0.0, 1.0], 0.2, 0.2),
            ([-0.0, 0.0], [1.0, 0.0], [0.0, 1.0], -0.0, 0.0),
        ];
        for (a, b, c, x, y) in odd {
            let want = scalar_weights(a, b, c, x, y);
            assert_eq!(
                weights(a, b, c, x, y).map(f32::to_bits),
                want.map(f32::to_bits)
            );
        }
        assert!(scalar_weights([0.0, 0.0], [1.0, 1.0], [2.0, 2.0], 0.5, 0.5)[0].is_nan());
        assert_eq!(
            weights([0.0, 0.0], [4.0, 0.0], [0.0, 4.0], 1.0, 2.0),
            [0.25, 0.5]
        );
        assert_eq!(checked, 20_000);
        assert!(clamped[0] > 1000 && clamped[1] > 1000, "{clamped:?}");
    }

    /// The plain shading every lookup of [`Shader`] stands for: the group
    /// through the face, the slots and the triangle read separately.
    fn plain_shade(
        scene: &Scene,
        proj: &Projected,
        id: u64,
        (sx, sy, px, py): (usize, usize, usize, usize),
    ) -> [u8; 3] {
        let (tri, back) = ((id >> 1) as usize, (id & 1) as usize);
        let group = &scene.groups[scene.side_group(tri, back) as usize];
        let light = if group.cap {
            if (px + py) % 8 < 2 { 0.6 } else { 0.95 }
        } else {
            let s = scene.corner_slots[tri];
            if s[0] == s[1] && s[1] == s[2] {
                scene.light[s[0] as usize][back]
            } else {
                let t = scene.tris[tri];
                let [a, b, c] = t.map(|n| proj.xy_f[n as usize]);
                let (x, y) = (sx as f32 + 0.5, sy as f32 + 0.5);
                let area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
                let w1 = ((c[0] - a[0]) * (y - a[1]) - (c[1] - a[1]) * (x - a[0])) / -area;
                let w2 = ((b[0] - a[0]) * (y - a[1]) - (b[1] - a[1]) * (x - a[0])) / area;
                let (w1, w2) = (w1.clamp(0.0, 1.0), w2.clamp(0.0, 1.0));
                let w0 = (1.0 - w1 - w2).max(0.0);
                let l = |k: usize| scene.light[s[k] as usize][back];
                w0 * l(0) + w1 * l(1) + w2 * l(2)
            }
        };
        group.color.map(|c| (c as f32 * light + 0.5) as u8)
    }

    #[test]
    fn shading_is_the_plain_lookup_for_every_scene_shape() {
        // A fan of triangles over scattered nodes with distinct light per
        // slot; a degenerate triangle whose slots are all one.
        let n = 40u32;
        let points: Vec<[f64; 3]> = vec![[0.0; 3]; n as usize];
        let xy_f: Vec<[f32; 2]> = (0..n)
            .map(|i| {
                let t = i as f32 * 0.618;
                [(t * 7.3).sin() * 30.0 + 32.0, (t * 3.1).cos() * 20.0 + 24.0]
            })
            .collect();
        let mut tris: Vec<[u32; 3]> = (0..n - 2)
            .map(|i| [i, (i * 7 + 1) % n, (i * 13 + 2) % n])
            .collect();
        tris.push([5, 5, 5]);
        let light: Vec<[f32; 2]> = (0..3 * n)
            .map(|i| [0.25 + (i % 7) as f32 * 0.1, 1.0 - (i % 5) as f32 * 0.15])
            .collect();
        let groups: Vec<Group> = (0..3)
            .map(|g| Group {
                name: format!("g{g}"),
                color: [40 + 70 * g as u8, 250 - 60 * g as u8, 7 + 3 * g as u8],
                cap: g == 2,
            })
            .collect();
        // The same positions with the nodes' own light in records, as the
        // projection makes them for one face with its nodes as slots.
        let records = Projected::records_of(&xy_f, &light);
        let proj = Projected {
            snapped: Vec::new(),
            xy_f,
            xy_light: Vec::new(),
        };
        let slots_elsewhere: Vec<[u32; 3]> = tris.iter().map(|t| t.map(|k| k + n)).collect();
        let faces: Vec<u32> = (0..tris.len() as u32).map(|i| i % 2).collect();
        let (mut shaded, mut by_records) = (0, 0);
        // One face with its nodes as slots (the same array as the
        // triangles), one face with other slots, two faces of different
        // groups (a cap on one, a hidden side).
        for shape in 0..3 {
            let mut scene = Scene {
                points: Cow::Borrowed(&points),
                tris: Cow::Borrowed(&tris),
                tri_face: Vec::new(),
                one_face: Some(0),
                face_sides: vec![[0, 1]],
                same_sides: Some([0, 1]),
                corner_slots: Cow::Borrowed(&slots_elsewhere),
                light: light.clone(),
                groups: groups.clone(),
            };
            if shape == 0 {
                scene.corner_slots = Cow::Borrowed(&tris);
            }
            if shape == 2 {
                scene.tri_face = faces.clone();
                scene.one_face = None;
                scene.face_sides = vec![[0, 1], [2, HIDDEN]];
                scene.same_sides = None;
            }
            let shader = Shader::new(&scene, &proj);
            assert_eq!(shader.own_slots, shape == 0);
            let by_record = Shader::new(&scene, &records);
            assert_eq!(by_record.records.len(), if shape == 0 { 40 } else { 0 });
            for tri in 0..scene.tris.len() {
                for back in 0..2u64 {
                    if scene.side_group(tri, back as usize) == HIDDEN {
                        continue;
                    }
                    let id = 2 * tri as u64 + back;
                    for (sx, sy) in [(30, 20), (31, 27), (3, 50), (63, 0)] {
                        let at = (sx, sy, sx / 2, sy / 2);
                        let want = plain_shade(&scene, &proj, id, at);
                        assert_eq!(
                            shader.shade(id, sx, sy, sx / 2, sy / 2),
                            want,
                            "{shape} {id}"
                        );
                        shaded += 1;
                        if shape == 0 {
                            assert_eq!(by_record.shade(id, sx, sy, sx / 2, sy / 2), want);
                            by_records += 1;
                        }
                    }
                }
            }
        }
        assert!(shaded > 400, "{shaded}");
        assert!(by_records > 200, "{by_records}");
    }
}
