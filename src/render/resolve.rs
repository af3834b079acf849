//! From samples to pixels: each visible sample is shaded with its group's
//! colour times the interpolated light, once per distinct triangle in a pixel
//! (as multisampling does, so anti-aliasing costs coverage tests, not shading),
//! and the samples of a pixel are averaged with straight alpha.

use super::raster::{EMPTY, Projected, ZBuffer};
use super::resolve_unmarked::unmarked_rows;
use super::scene::Scene;
use crate::cache_hint::prefetch;
use rayon::prelude::*;

/// Pixels ahead whose triangle's corners are fetched while one is shaded.
pub(super) const AHEAD: usize = 8;

pub const EDGE_COLOR: [u8; 4] = [25, 25, 30, 255];

/// An RGBA picture, 8 bits per channel, straight (not premultiplied) alpha.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Image {
    pub width: u32,
    pub height: u32,
    pub rgba: Vec<u8>,
}

impl Image {
    pub fn pixel(&self, x: u32, y: u32) -> [u8; 4] {
        let i = 4 * (y as usize * self.width as usize + x as usize);
        [
            self.rgba[i],
            self.rgba[i + 1],
            self.rgba[i + 2],
            self.rgba[i + 3],
        ]
    }

    /// Blends `color` over the pixel with coverage `alpha` in [0, 1].
    pub fn blend(&mut self, x: i64, y: i64, color: [u8; 3], alpha: f32) {
        if x < 0 || y < 0 || x >= self.width as i64 || y >= self.height as i64 {
            return;
        }
        let i = 4 * (y as usize * self.width as usize + x as usize);
        let dst_a = self.rgba[i + 3] as f32 / 255.0;
        let out_a = alpha + dst_a * (1.0 - alpha);
        if out_a <= 0.0 {
            return;
        }
        for (c, &src) in color.iter().enumerate() {
            let v = (src as f32 * alpha + self.rgba[i + c] as f32 * dst_a * (1.0 - alpha)) / out_a;
            self.rgba[i + c] = v.round().clamp(0.0, 255.0) as u8;
        }
        self.rgba[i + 3] = (out_a * 255.0).round() as u8;
    }
}

#[inline]
pub(super) fn shade(
    scene: &Scene,
    proj: &Projected,
    id: u64,
    sx: usize,
    sy: usize,
    px: usize,
    py: usize,
) -> [u8; 3] {
    let tri = (id >> 1) as usize;
    let back = (id & 1) as usize;
    let group = &scene.groups[scene.side_group(tri, back) as usize];
    let light = if group.cap {
        // Section caps are flat and hatched, as drawings show cut material.
        if (px + py) % 8 < 2 { 0.6 } else { 0.95 }
    } else {
        let s = scene.corner_slots[tri];
        if s[0] == s[1] && s[1] == s[2] {
            scene.light[s[0] as usize][back]
        } else {
            let t = scene.tris[tri];
            let (a, b, c) = (
                proj.xy_f[t[0] as usize],
                proj.xy_f[t[1] as usize],
                proj.xy_f[t[2] as usize],
            );
            // Sample indices are below 2^17, so `u32` to `f32` is exact, as
            // `usize` to `f32` is, in one conversion instead of six.
            let (x, y) = (sx as u32 as f32 + 0.5, sy as u32 as f32 + 0.5);
            let area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
            let w1 = ((c[0] - a[0]) * (y - a[1]) - (c[1] - a[1]) * (x - a[0])) / -area;
            let w2 = ((b[0] - a[0]) * (y - a[1]) - (b[1] - a[1]) * (x - a[0])) / area;
            let (w1, w2) = (w1.clamp(0.0, 1.0), w2.clamp(0.0, 1.0));
            let w0 = (1.0 - w1 - w2).max(0.0);
            let l = |k: usize| scene.light[s[k] as usize][back];
            w0 * l(0) + w1 * l(1) + w2 * l(2)
        }
    };
    tint(group.color, light)
}

/// `color` times `light`, each channel rounded by adding a half (the value
/// is not negative, `as` saturates at 255, and `f32::round` is a library
/// call). With SSE2 the three channels are lanes of one vector: the same
/// multiplication and addition per lane, and a conversion that gives what
/// `as u8` gives for every value (NaN and negatives 0, above 255 255).
#[inline]
pub(super) fn tint(color: [u8; 3], light: f32) -> [u8; 3] {
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
fn scalar_tint(color: [u8; 3], light: f32) -> [u8; 3] {
    color.map(|c| (c as f32 * light + 0.5) as u8)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "sse2")]
#[inline]
fn tint_sse2(color: [u8; 3], light: f32) -> [u8; 3] {
    use std::arch::x86_64::*;
    let channels = _mm_set_epi32(0, color[2] as i32, color[1] as i32, color[0] as i32);
    let lit = _mm_add_ps(
        _mm_mul_ps(_mm_cvtepi32_ps(channels), _mm_set1_ps(light)),
        _mm_set1_ps(0.5),
    );
    // `minps 255, v` is `255 < v ? 255 : v`: a NaN stays NaN, and
    // truncation turns it (and anything below −2^31) into i32::MIN, which
    // the two saturating packs turn into 0, as they do every negative.
    let ints = _mm_cvttps_epi32(_mm_min_ps(_mm_set1_ps(255.0), lit));
    let bytes = _mm_packus_epi16(_mm_packs_epi32(ints, ints), _mm_setzero_si128());
    let [r, g, b, _] = _mm_cvtsi128_si32(bytes).to_le_bytes();
    [r, g, b]
}

/// A pixel whose samples all show one colour group's surface (no edge mark,
/// no background, no section cap) lies inside a smooth surface: it is
/// shaded once, at its first sample, instead of once per triangle in it.
/// Anti-aliasing is thus spent on the pixels where colours change.
#[inline]
fn uniform(
    scene: &Scene,
    proj: &Projected,
    samples: &Samples,
    ss: usize,
    px: usize,
    py: usize,
) -> Option<[u8; 3]> {
    let (sx, sy) = (px * ss, py * ss);
    let first = samples.value(sx, sy);
    if first == EMPTY {
        return None;
    }
    let first_id = first & 0xffff_ffff;
    let group_of = |id: u64| scene.side_group((id >> 1) as usize, (id & 1) as usize);
    let group = group_of(first_id);
    if scene.groups[group as usize].cap {
        return None;
    }
    for y in sy..sy + ss {
        for x in sx..sx + ss {
            let value = samples.value(x, y);
            if value == EMPTY || samples.edge(x, y) {
                return None;
            }
            let id = value & 0xffff_ffff;
            if id != first_id && group_of(id) != group {
                return None;
            }
        }
    }
    Some(shade(scene, proj, first_id, sx, sy, px, py))
}

/// Whether every sample of the pixel shows the background (no edge mark).
/// An empty sample is all ones, so the pixel's samples are all empty when
/// their bitwise AND is: one pass over its `ss` runs of samples, without a
/// branch per sample (most pixels of a picture are background).
#[inline]
fn background_only(samples: &Samples, ss: usize, px: usize, py: usize) -> bool {
    let mut all = EMPTY;
    for sy in py * ss..(py + 1) * ss {
        let start = (sy - samples.y0) * samples.width + px * ss;
        all = samples.data[start..start + ss]
            .iter()
            .fold(all, |a, &v| a & v);
    }
    all == EMPTY
        && (samples.edges.is_empty()
            || (py * ss..(py + 1) * ss)
                .all(|sy| (px * ss..(px + 1) * ss).all(|sx| !samples.edge(sx, sy))))
}

/// A pixel all of whose samples show `background`: the average the sums
/// of [`resolve_rows`] give (a transparent one has no colour: all zeros).
pub fn background_pixel(background: [u8; 4]) -> [u8; 4] {
    if background[3] == 0 {
        [0; 4]
    } else {
        background
    }
}

/// Samples of sample rows `y0..` (stored from `data[0]`), `width` per row,
/// and the edge mask of the whole picture (empty: no edges).
pub struct Samples<'a> {
    pub data: &'a [u64],
    pub width: usize,
    pub y0: usize,
    pub edges: &'a [bool],
}

impl Samples<'_> {
    #[inline]
    fn value(&self, sx: usize, sy: usize) -> u64 {
        self.data[(sy - self.y0) * self.width + sx]
    }

    #[inline]
    fn edge(&self, sx: usize, sy: usize) -> bool {
        !self.edges.is_empty() && self.edges[sy * self.width + sx]
    }
}

/// Averages `ss`×`ss` samples per pixel over `background`.
pub fn resolve(
    scene: &Scene,
    proj: &Projected,
    zbuf: &ZBuffer,
    edges: &[bool],
    ss: usize,
    background: [u8; 4],
) -> Image {
    let width = zbuf.width / ss;
    let height = zbuf.height / ss;
    let samples = Samples {
        data: &zbuf.data,
        width: zbuf.width,
        y0: 0,
        edges,
    };
    let mut rgba = vec![0u8; width * height * 4];
    rgba.par_chunks_mut(width * 4)
        .enumerate()
        .for_each(|(py, row)| {
            resolve_rows(scene, proj, &samples, ss, background, py, 0..width, row)
        });
    Image {
        width: width as u32,
        height: height as u32,
        rgba,
    }
}

/// Resolves the pixel columns `cols` of the pixel rows from `py0` that `out`
/// holds (RGBA, the picture's width); their samples must be in `samples`
/// (those of other columns are not read).
#[allow(clippy::too_many_arguments)]
pub fn resolve_rows(
    scene: &Scene,
    proj: &Projected,
    samples: &Samples,
    ss: usize,
    background: [u8; 4],
    py0: usize,
    cols: std::ops::Range<usize>,
    out: &mut [u8],
) {
    // Without an edge overlay (every banded picture), a pixel's samples
    // are read once, with the anti-aliasing factor a constant.
    if samples.edges.is_empty() {
        let args = (scene, proj, samples, background, py0, cols.clone());
        match ss {
            1 => return unmarked_rows::<1>(args, out),
            2 => return unmarked_rows::<2>(args, out),
            3 => return unmarked_rows::<3>(args, out),
            4 => return unmarked_rows::<4>(args, out),
            _ => {}
        }
    }
    let width = samples.width / ss;
    // The triangle shown at a pixel's first sample, when there is one.
    let first_tri = |px: usize, py: usize| {
        let value = samples.value(px * ss, py * ss);
        (value != EMPTY).then_some(((value & 0xffff_ffff) >> 1) as usize)
    };
    let bg = background_pixel(background);
    for (dy, row) in out.chunks_mut(width * 4).enumerate() {
        let py = py0 + dy;
        for px in cols.clone() {
            // Background first: such a pixel shows no triangle (`uniform`
            // would find none), so it skips the look-ahead fetches too.
            if background_only(samples, ss, px, py) {
                // The average of equal samples, as the sums below give it.
                row[px * 4..px * 4 + 4].copy_from_slice(&bg);
                continue;
            }
            prefetch_ahead(scene, proj, px, cols.end, |px| first_tri(px, py));
            if let Some(color) = uniform(scene, proj, samples, ss, px, py) {
                row[px * 4..px * 4 + 4].copy_from_slice(&[color[0], color[1], color[2], 255]);
                continue;
            }
            let mut sum = PixelSum::default();
            for sy in py * ss..(py + 1) * ss {
                for sx in px * ss..(px + 1) * ss {
                    if samples.edge(sx, sy) {
                        sum.add([EDGE_COLOR[0], EDGE_COLOR[1], EDGE_COLOR[2]], 255);
                    } else {
                        let value = samples.value(sx, sy);
                        sum.add_sample(value, background, || {
                            shade(scene, proj, value & 0xffff_ffff, sx, sy, px, py)
                        });
                    }
                }
            }
            sum.write((ss * ss) as u32, &mut row[px * 4..px * 4 + 4]);
        }
    }
}

/// Fetches what shading a pixel ahead will gather: a triangle, then its
/// corners' positions and light. The triangle of the pixel 16 ahead and the
/// corners of the one 8 ahead, so the loads overlap (`first_tri` gives the
/// triangle at a pixel's first sample; `end` ends the row's columns).
#[inline(always)]
pub(super) fn prefetch_ahead(
    scene: &Scene,
    proj: &Projected,
    px: usize,
    end: usize,
    first_tri: impl Fn(usize) -> Option<usize>,
) {
    // A smooth one-face scene's light slots are its triangles' own nodes
    // (the same array): the triangle is then read and fetched once.
    let own_slots = std::ptr::eq(scene.corner_slots.as_ptr(), scene.tris.as_ptr());
    if let Some(tri) = (px + 2 * AHEAD < end)
        .then(|| first_tri(px + 2 * AHEAD))
        .flatten()
    {
        prefetch(&scene.tris[tri]);
        if !own_slots {
            prefetch(&scene.corner_slots[tri]);
        }
    }
    if let Some(tri) = (px + AHEAD < end).then(|| first_tri(px + AHEAD)).flatten() {
        let t = scene.tris[tri];
        let slots = if own_slots {
            t
        } else {
            scene.corner_slots[tri]
        };
        for (n, slot) in t.into_iter().zip(slots) {
            prefetch(&proj.xy_f[n as usize]);
            prefetch(&scene.light[slot as usize]);
        }
    }
}

/// The colour sums of a mixed pixel's samples; a run of samples showing one
/// triangle shades it once.
#[derive(Default)]
pub(super) struct PixelSum {
    sum: [u32; 4],
    last: Option<(u64, [u8; 3])>,
}

impl PixelSum {
    /// Adds a sample of `color` with coverage `alpha` (0–255).
    #[inline(always)]
    pub(super) fn add(&mut self, color: [u8; 3], alpha: u32) {
        for (sum, &channel) in self.sum.iter_mut().zip(&color) {
            *sum += channel as u32 * alpha;
        }
        self.sum[3] += alpha;
    }

    /// Adds a sample of value `value`: the background when empty, else its
    /// triangle's surface, shaded by `shade` unless the last shaded sample
    /// showed the same triangle side.
    #[inline(always)]
    pub(super) fn add_sample(
        &mut self,
        value: u64,
        background: [u8; 4],
        shade: impl FnOnce() -> [u8; 3],
    ) {
        if value == EMPTY {
            let color = [background[0], background[1], background[2]];
            return self.add(color, background[3] as u32);
        }
        let id = value & 0xffff_ffff;
        let color = match self.last {
            Some((l, c)) if l == id => c,
            _ => {
                let c = shade();
                self.last = Some((id, c));
                c
            }
        };
        self.add(color, 255);
    }

    /// Writes the average of `n` samples into `out` (RGBA).
    #[inline(always)]
    pub(super) fn write(&self, n: u32, out: &mut [u8]) {
        let sum = &self.sum;
        for c in 0..3 {
            if let Some(v) = (sum[c] + sum[3] / 2).checked_div(sum[3]) {
                out[c] = v as u8;
            }
        }
        out[3] = ((sum[3] + n / 2) / n) as u8;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
        let mut saturated = 0;
        for light in lights {
            for c in (0..=255u8).step_by(17).chain([1, 254]) {
                let color = [c, 255 - c, c / 3];
                let want = scalar_tint(color, light);
                assert_eq!(tint(color, light), want, "{color:?} × {light}");
                saturated += usize::from(want.contains(&255) && light > 1.0);
            }
        }
        assert!(saturated > 0);
        assert_eq!(tint([200, 100, 50], 0.5), [100, 50, 25]);
        assert_eq!(tint([255, 255, 255], f32::NAN), [0, 0, 0]);
        assert_eq!(tint([3, 255, 128], 2.0), [6, 255, 255]);
    }
}
