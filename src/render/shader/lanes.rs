//! Shading eight pixels of a row at once. A pixel inside a surface is
//! shaded once, at its first sample; one at a time, each waits on its
//! triangle, then its corners, then a division. Queued eight at a time, the
//! loads of all eight are gathered together and one division serves eight
//! weights (AVX2): the same operations per lane as [`Shader::shade`], so
//! the same bytes. Without AVX2, or for scenes whose sides are looked up
//! per triangle, the resolver calls `shade` directly and queues nothing
//! ([`Shader::shades_lanes`]); a queued batch with a lane the vectors cannot
//! shade is shaded one pixel at a time.

use super::Shader;

/// Pixels per queue.
pub(in crate::render) const LANES: usize = 8;

/// One-surface pixels of one sample row waiting to be shaded: each one's
/// triangle side (`2 × triangle + back`), sample column and pixel column.
pub(in crate::render) struct Queue {
    ids: [u32; LANES],
    sx: [u32; LANES],
    px: [u32; LANES],
    len: usize,
}

impl Queue {
    pub(in crate::render) fn new() -> Queue {
        Queue {
            ids: [0; LANES],
            sx: [0; LANES],
            px: [0; LANES],
            len: 0,
        }
    }

    /// Queues pixel `px`, shown by side `id` at its first sample `sx`
    /// (callers keep sample columns below 2^31); true when the queue is full.
    #[inline(always)]
    pub(in crate::render) fn push(&mut self, id: u32, sx: u32, px: u32) -> bool {
        let i = self.len.min(LANES - 1);
        (self.ids[i], self.sx[i], self.px[i]) = (id, sx, px);
        self.len = i + 1;
        self.len == LANES
    }

    /// Shades the queued pixels of sample row `sy` (pixel row `py`) and
    /// writes them, opaque, into `row` (RGBA); empties the queue.
    #[inline(always)]
    pub(in crate::render) fn flush(
        &mut self,
        shader: &Shader,
        sy: usize,
        py: usize,
        row: &mut [u8],
    ) {
        if self.len == 0 {
            return;
        }
        // Lanes past the queued ones repeat the first: shaded, not written.
        for i in self.len..LANES {
            (self.ids[i], self.sx[i], self.px[i]) = (self.ids[0], self.sx[0], self.px[0]);
        }
        let colors = shader.shade_lanes(&self.ids, &self.sx, &self.px, sy, py);
        for (&px, color) in self.px.iter().zip(colors).take(self.len) {
            let px = px as usize;
            row[px * 4..px * 4 + 4].copy_from_slice(&color);
        }
        self.len = 0;
    }
}

impl Shader<'_, '_> {
    /// The opaque colours of eight one-surface pixels of sample row `sy`
    /// (pixel row `py`): side `ids[i]` at sample (`sx[i]`, `sy`), as
    /// [`Shader::shade`] gives them.
    #[inline(always)]
    fn shade_lanes(
        &self,
        ids: &[u32; LANES],
        sx: &[u32; LANES],
        px: &[u32; LANES],
        sy: usize,
        py: usize,
    ) -> [[u8; 4]; LANES] {
        #[cfg(target_arch = "x86_64")]
        if let Some(colors) = self.lane_colors.and_then(|colors| {
            // SAFETY: `lane_colors` is set only when AVX2 was detected.
            unsafe { self.shade_lanes_avx2(colors, ids, sx, sy) }
        }) {
            return colors;
        }
        self.shade_each(ids, sx, px, sy, py)
    }

    /// [`Shader::shade_lanes`] one pixel at a time.
    fn shade_each(
        &self,
        ids: &[u32; LANES],
        sx: &[u32; LANES],
        px: &[u32; LANES],
        sy: usize,
        py: usize,
    ) -> [[u8; 4]; LANES] {
        std::array::from_fn(|i| {
            let [r, g, b] = self.shade(ids[i] as u64, sx[i] as usize, sy, px[i] as usize, py);
            [r, g, b, 255]
        })
    }

    /// [`Shader::shade_lanes`] with AVX2, given the front and back colours
    /// (neither a cap); `None` when a lane shows a side without a known
    /// colour or an index is out of range (the plain lookups then shade it,
    /// or report it as they always did).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn shade_lanes_avx2(
        &self,
        colors: [[f32; 4]; 2],
        ids: &[u32; LANES],
        sx: &[u32; LANES],
        sy: usize,
    ) -> Option<[[u8; 4]; LANES]> {
        // One call of the colours below, so it is inlined.
        let inputs = if !self.records.is_empty() {
            self.record_inputs(ids, sx)?
        } else {
            self.gathered_inputs(ids, sx)?
        };
        Some(tinted_lanes(colors, inputs, sy))
    }

    /// What [`tinted_lanes`] needs of eight lanes, gathered from the
    /// triangles, slots, positions and light; `None` as for
    /// [`Shader::shade_lanes_avx2`].
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn gathered_inputs(&self, ids: &[u32; LANES], sx: &[u32; LANES]) -> Option<LaneInputs> {
        use std::arch::x86_64::*;
        // SAFETY: eight u32s each.
        let (ids, sx) = unsafe {
            (
                _mm256_loadu_si256(ids.as_ptr().cast()),
                _mm256_loadu_si256(sx.as_ptr().cast()),
            )
        };
        let one_int = _mm256_set1_epi32(1);
        let tri = _mm256_srli_epi32::<1>(ids);
        let back = _mm256_and_si256(ids, one_int);
        // Whether every lane of `v` is below `len` (unsigned).
        let below = |v: __m256i, len: usize| {
            let last = _mm256_set1_epi32((len as u32).wrapping_sub(1) as i32);
            len > 0
                && _mm256_movemask_epi8(_mm256_cmpeq_epi32(_mm256_max_epu32(v, last), last)) == -1
        };
        // A side not known per scene (hidden) is shaded by `shade`.
        let unknown = |side: usize| self.sides[side].is_none();
        let backs = _mm256_movemask_ps(_mm256_castsi256_ps(_mm256_slli_epi32::<31>(ids)));
        if (unknown(0) && backs != 0xff)
            || (unknown(1) && backs != 0)
            || !below(tri, self.tris.len())
        {
            return None;
        }
        let three = |k: i32| {
            _mm256_add_epi32(
                _mm256_mullo_epi32(tri, _mm256_set1_epi32(3)),
                _mm256_set1_epi32(k),
            )
        };
        let (i0, i1, i2) = (three(0), three(1), three(2));
        // SAFETY: every triangle is below `tris.len()` (checked above), which
        // `Shader::new` keeps below 2^31 / 3, so `3 × triangle + 2` is an
        // i32 index into `tris` seen as u32s; `slots` has the same length.
        let gather = |base: *const [u32; 3], at: __m256i| unsafe {
            _mm256_i32gather_epi32::<4>(base.cast(), at)
        };
        let t = [
            gather(self.tris.as_ptr(), i0),
            gather(self.tris.as_ptr(), i1),
            gather(self.tris.as_ptr(), i2),
        ];
        let s = if self.own_slots {
            t
        } else {
            [
                gather(self.slots.as_ptr(), i0),
                gather(self.slots.as_ptr(), i1),
                gather(self.slots.as_ptr(), i2),
            ]
        };
        if !t.iter().all(|&n| below(n, self.xy.len()))
            || !s.iter().all(|&n| below(n, self.light.len()))
        {
            return None;
        }
        // SAFETY: every node is below `xy.len()` and every slot below
        // `light.len()` (checked above), both kept below 2^30 by
        // `Shader::new`, so `2 × index + 1` is an i32 index into the f32s.
        let coord = |n: __m256i, axis: i32| unsafe {
            _mm256_i32gather_ps::<4>(
                self.xy.as_ptr().cast(),
                _mm256_add_epi32(_mm256_add_epi32(n, n), _mm256_set1_epi32(axis)),
            )
        };
        let lit = |slot: __m256i| unsafe {
            _mm256_i32gather_ps::<4>(
                self.light.as_ptr().cast(),
                _mm256_add_epi32(_mm256_add_epi32(slot, slot), back),
            )
        };
        let corners = [
            coord(t[0], 0),
            coord(t[0], 1),
            coord(t[1], 0),
            coord(t[1], 1),
            coord(t[2], 0),
            coord(t[2], 1),
        ];
        // A triangle whose slots are all one shows that slot's light.
        let one_slot = _mm256_and_si256(
            _mm256_cmpeq_epi32(s[0], s[1]),
            _mm256_cmpeq_epi32(s[1], s[2]),
        );
        Some(LaneInputs {
            corners,
            // Not `array::map`: without AVX2 it would pass vectors through memory.
            light: [lit(s[0]), lit(s[1]), lit(s[2])],
            one_slot,
            back,
            sx,
        })
    }
}

/// What the colours of eight lanes are computed from: the corners'
/// positions (`ax, ay, bx, by, cx, cy`) and light on the lane's side,
/// whether the triangle's slots are all one (all ones, else zero), the side
/// (0 front, 1 back) and the sample column.
#[cfg(target_arch = "x86_64")]
pub(super) struct LaneInputs {
    pub corners: [std::arch::x86_64::__m256; 6],
    pub light: [std::arch::x86_64::__m256; 3],
    pub one_slot: std::arch::x86_64::__m256i,
    pub back: std::arch::x86_64::__m256i,
    pub sx: std::arch::x86_64::__m256i,
}

/// The colours of eight lanes: side colour `colors[back]` times the light
/// interpolated from the corners at sample (`sx + 0.5`, `sy + 0.5`), or the
/// first corner's light where `one_slot` is set. [`Shader::shade`]'s
/// operations per lane, so its bits.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
fn tinted_lanes(colors: [[f32; 4]; 2], inputs: LaneInputs, sy: usize) -> [[u8; 4]; LANES] {
    use std::arch::x86_64::*;
    let LaneInputs {
        corners: [ax, ay, bx, by, cx, cy],
        light: [l0, l1, l2],
        one_slot,
        back,
        sx,
    } = inputs;
    let one_int = _mm256_set1_epi32(1);
    let half = _mm256_set1_ps(0.5);
    let x = _mm256_add_ps(_mm256_cvtepi32_ps(sx), half);
    let y = _mm256_set1_ps(sy as u32 as f32 + 0.5);
    // `scalar_weights`, lane by lane, in its order.
    let (dbx, dby) = (_mm256_sub_ps(bx, ax), _mm256_sub_ps(by, ay));
    let (dcx, dcy) = (_mm256_sub_ps(cx, ax), _mm256_sub_ps(cy, ay));
    let (dx, dy) = (_mm256_sub_ps(x, ax), _mm256_sub_ps(y, ay));
    let area = _mm256_sub_ps(_mm256_mul_ps(dbx, dcy), _mm256_mul_ps(dby, dcx));
    let num1 = _mm256_sub_ps(_mm256_mul_ps(dcx, dy), _mm256_mul_ps(dcy, dx));
    let num2 = _mm256_sub_ps(_mm256_mul_ps(dbx, dy), _mm256_mul_ps(dby, dx));
    let sign = _mm256_set1_ps(-0.0);
    let (zero, one) = (_mm256_setzero_ps(), _mm256_set1_ps(1.0));
    // `maxps 0, w` then `minps 1, v`: `f32::clamp`, NaN and −0 kept.
    let clamp = |w: __m256| _mm256_min_ps(one, _mm256_max_ps(zero, w));
    let w1 = clamp(_mm256_div_ps(num1, _mm256_xor_ps(area, sign)));
    let w2 = clamp(_mm256_div_ps(num2, area));
    // `maxps w, 0` is `w > 0 ? w : 0`, as `f32::max(w, 0.0)` compiles.
    let w0 = _mm256_max_ps(_mm256_sub_ps(_mm256_sub_ps(one, w1), w2), zero);
    let sum = _mm256_add_ps(
        _mm256_add_ps(_mm256_mul_ps(w0, l0), _mm256_mul_ps(w1, l1)),
        _mm256_mul_ps(w2, l2),
    );
    let light = _mm256_blendv_ps(sum, l0, _mm256_castsi256_ps(one_slot));
    // `tint` per channel: the side's colour times the light plus a half,
    // at most 255, truncated; a NaN or a negative gives 0, as `as u8`.
    let is_back = _mm256_castsi256_ps(_mm256_cmpeq_epi32(back, one_int));
    let channel = |k: usize| {
        let c = _mm256_blendv_ps(
            _mm256_set1_ps(colors[0][k]),
            _mm256_set1_ps(colors[1][k]),
            is_back,
        );
        let v = _mm256_min_ps(
            _mm256_set1_ps(255.0),
            _mm256_add_ps(_mm256_mul_ps(c, light), half),
        );
        _mm256_max_epi32(_mm256_cvttps_epi32(v), _mm256_setzero_si256())
    };
    let rgba = _mm256_or_si256(
        _mm256_or_si256(channel(0), _mm256_slli_epi32::<8>(channel(1))),
        _mm256_or_si256(
            _mm256_slli_epi32::<16>(channel(2)),
            _mm256_set1_epi32(255 << 24),
        ),
    );
    let mut out = [[0u8; 4]; LANES];
    // SAFETY: `out` is 32 bytes.
    unsafe { _mm256_storeu_si256(out.as_mut_ptr().cast(), rgba) };
    out
}

#[cfg(test)]
mod tests {
    use super::super::super::raster::Projected;
    use super::super::super::scene::{Group, HIDDEN, Scene};
    use super::*;
    use crate::test_rng::TestRng;
    use std::borrow::Cow;

    #[test]
    fn eight_lanes_shade_as_one_pixel_at_a_time() {
        let mut rng = TestRng::new(0x9e37_79b9_7f4a_7c15);
        let mut unit = || (rng.next_u64() >> 40) as f32 / (1u64 << 24) as f32;
        let n = 64u32;
        // Scattered nodes, some repeated so that triangles are degenerate
        // (a zero area: infinite or NaN weights, clamped or not).
        let mut xy_f: Vec<[f32; 2]> = (0..n).map(|_| [unit() * 40.0, unit() * 30.0]).collect();
        xy_f[7] = xy_f[3];
        xy_f[8] = [2.0 * xy_f[3][0] - xy_f[5][0], 2.0 * xy_f[3][1] - xy_f[5][1]];
        let mut tris: Vec<[u32; 3]> = (0..200u32)
            .map(|i| [i % n, (i * 7 + 1) % n, (i * 13 + 2) % n])
            .collect();
        tris.extend([[3, 7, 9], [3, 5, 8], [4, 4, 4], [3, 7, 3]]);
        // Light above 1 too, so some channels saturate.
        let light: Vec<[f32; 2]> = (0..3 * n).map(|_| [unit() * 1.3, unit()]).collect();
        let slots: Vec<[u32; 3]> = tris
            .iter()
            .enumerate()
            // Every fifth triangle flat (its slots all one), as flat shading has.
            .map(|(i, t)| {
                if i % 5 == 0 {
                    [t[0] + n; 3]
                } else {
                    t.map(|k| k + 2 * n)
                }
            })
            .collect();
        let groups = vec![
            Group {
                name: "front".into(),
                color: [255, 120, 3],
                cap: false,
            },
            Group {
                name: "back".into(),
                color: [17, 200, 254],
                cap: false,
            },
        ];
        let points = vec![[0.0; 3]; n as usize];
        // The nodes' own light with their positions, one record per node,
        // as the projection makes them for nodes that are their own slots.
        let records = Projected::records_of(&xy_f, &light);
        let proj = Projected {
            snapped: Vec::new(),
            xy_f,
            xy_light: Vec::new(),
        };
        let mut lanes_used = 0;
        // Own slots, other slots, and a hidden back (front lanes only);
        // own slots read from records too.
        for (own, hidden, by_record) in [
            (true, false, false),
            (false, false, false),
            (true, true, false),
            (true, false, true),
            (true, true, true),
        ] {
            let scene = Scene {
                points: Cow::Borrowed(&points),
                tris: Cow::Borrowed(&tris),
                tri_face: Vec::new(),
                one_face: Some(0),
                face_sides: vec![[0, 1]],
                same_sides: Some([0, if hidden { HIDDEN } else { 1 }]),
                corner_slots: if own {
                    Cow::Borrowed(&tris)
                } else {
                    Cow::Borrowed(&slots)
                },
                light: light.clone(),
                groups: groups.clone(),
            };
            // The reference: positions and light read from their arrays.
            let plain = Shader::new(&scene, &proj);
            let shader = Shader::new(&scene, if by_record { &records } else { &proj });
            assert_eq!(shader.records.len(), if by_record { 64 } else { 0 });
            assert_eq!(shader.lane_colors.is_some(), super::super::avx2());
            lanes_used += usize::from(shader.lane_colors.is_some());
            for round in 0..4000 {
                let ids: [u32; LANES] = std::array::from_fn(|_| {
                    let id = (rng.next_u64() % (2 * tris.len() as u64)) as u32;
                    if hidden { id & !1 } else { id }
                });
                let sx: [u32; LANES] = std::array::from_fn(|_| (rng.next_u64() % 48) as u32);
                let px = sx.map(|x| x / 2);
                let sy = round % 36;
                let want = plain.shade_each(&ids, &sx, &px, sy, sy / 2);
                assert_eq!(shader.shade_each(&ids, &sx, &px, sy, sy / 2), want);
                let got = shader.shade_lanes(&ids, &sx, &px, sy, sy / 2);
                assert_eq!(got, want, "{own} {ids:?} {sx:?} {sy}");
            }
            // A triangle past the end: the plain lookup's panic, not a gather.
            let past = [2 * tris.len() as u32; LANES];
            let caught = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                shader.shade_lanes(&past, &[0; LANES], &[0; LANES], 0, 0)
            }));
            assert!(caught.is_err());
        }
        assert_eq!(lanes_used, 5 * usize::from(super::super::avx2()));
    }

    #[test]
    fn the_queue_writes_each_pixel_once_and_empties() {
        let tris = vec![[0, 1, 2]];
        let scene = Scene {
            points: Cow::Owned(vec![[0.0; 3]; 3]),
            tris: Cow::Borrowed(&tris),
            tri_face: Vec::new(),
            one_face: Some(0),
            face_sides: vec![[0, 0]],
            same_sides: Some([0, 0]),
            corner_slots: Cow::Borrowed(&tris),
            light: vec![[1.0, 0.5], [0.5, 0.25], [0.0, 1.0]],
            groups: vec![Group {
                name: "g".into(),
                color: [200, 100, 50],
                cap: false,
            }],
        };
        let proj = Projected {
            snapped: Vec::new(),
            xy_f: vec![[0.0, 0.0], [10.0, 0.0], [0.0, 10.0]],
            xy_light: Vec::new(),
        };
        let shader = Shader::new(&scene, &proj);
        let mut row = vec![7u8; 12 * 4];
        let mut queue = Queue::new();
        // Nine pixels (a full queue, then one more), every other column.
        let mut full = 0;
        for px in (0..12).filter(|px| px % 4 != 3) {
            if queue.push((px % 2) as u32, px as u32, px as u32) {
                queue.flush(&shader, 0, 0, &mut row);
                full += 1;
            }
        }
        queue.flush(&shader, 0, 0, &mut row);
        assert_eq!(full, 1);
        for px in 0..12 {
            let pixel = &row[px * 4..px * 4 + 4];
            if px % 4 == 3 {
                assert_eq!(pixel, [7; 4]);
            } else {
                let [r, g, b] = shader.shade((px % 2) as u64, px, 0, px, 0);
                assert_eq!(pixel, [r, g, b, 255], "{px}");
            }
        }
        // Pixel 0 (front, sample centre (0.5, 0.5)): weights 0.9, 0.05, 0.05
        // of the corners' front light 1, 0.5, 0: 0.925 of (200, 100, 50).
        assert_eq!(&row[..4], [185, 92, 46, 255]);
    }
}
