//! From samples to pixels: each visible sample is shaded with its group's
//! colour times the interpolated light, once per distinct triangle in a pixel
//! (as multisampling does, so anti-aliasing costs coverage tests, not shading),
//! and the samples of a pixel are averaged with straight alpha.

use super::raster::{EMPTY, Projected, ZBuffer};
use super::resolve_unmarked::unmarked_rows;
use super::scene::Scene;
use super::shader::Shader;
use rayon::prelude::*;

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

/// A pixel whose samples all show one colour group's surface (no edge mark,
/// no background, no section cap) lies inside a smooth surface: it is
/// shaded once, at its first sample, instead of once per triangle in it.
/// Anti-aliasing is thus spent on the pixels where colours change.
#[inline]
fn uniform(
    scene: &Scene,
    shader: &Shader,
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
    Some(shader.shade(first_id, sx, sy, px, py))
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
    let shader = Shader::new(scene, proj);
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
            shader.prefetch_ahead(px, cols.end, |px| first_tri(px, py));
            if let Some(color) = uniform(scene, &shader, samples, ss, px, py) {
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
                            shader.shade(value & 0xffff_ffff, sx, sy, px, py)
                        });
                    }
                }
            }
            sum.write((ss * ss) as u32, &mut row[px * 4..px * 4 + 4]);
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
