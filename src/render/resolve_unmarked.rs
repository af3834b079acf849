//! Resolving pixels without an edge overlay (every banded picture), with the
//! anti-aliasing factor `SS` a constant: a pixel's `SS`×`SS` samples are read
//! once, and that one read decides whether the pixel is background, one
//! colour group's surface (shaded once) or mixed (shaded per triangle). The
//! general resolver read them up to three times (background test, colour
//! test, averaging) with a bounds check per sample. The same decisions and
//! the same arithmetic in the same order as [`super::resolve::resolve_rows`]
//! without edges, so the same bytes.

use super::raster::{EMPTY, Projected};
use super::resolve::{PixelSum, Samples, background_pixel};
use super::scene::Scene;
use super::shader::{Queue, Shader};

/// What [`unmarked_rows`] resolves: the scene, the projection, the samples
/// (no edge mask), the background, the first pixel row and the pixel columns.
pub(super) type Rows<'s, 'a> = (
    &'s Scene<'a>,
    &'s Projected,
    &'s Samples<'s>,
    [u8; 4],
    usize,
    std::ops::Range<usize>,
);

/// Resolves the pixel columns `cols` of the pixel rows from `py0` that `out`
/// holds (RGBA, the picture's width), `SS`×`SS` samples per pixel.
pub(super) fn unmarked_rows<const SS: usize>(
    (scene, proj, samples, background, py0, cols): Rows,
    out: &mut [u8],
) {
    let sample_width = samples.width;
    let width = sample_width / SS;
    let bg = background_pixel(background);
    let shader = Shader::new(scene, proj);
    let group_of = |id: u64| scene.side_group((id >> 1) as usize, (id & 1) as usize);
    // One-surface pixels wait in a queue and are shaded eight at a time
    // (their sample columns fit the queue's u32s below 2^31); where the
    // lanes cannot run, the queue would only delay `shade`.
    let queued = shader.shades_lanes() && sample_width <= i32::MAX as usize;
    let mut queue = Queue::new();
    for (dy, row) in out.chunks_mut(width * 4).enumerate() {
        let py = py0 + dy;
        let sy = py * SS;
        let first_row = (sy - samples.y0) * sample_width;
        let lines: [&[u64]; SS] = std::array::from_fn(|r| {
            &samples.data[first_row + r * sample_width..first_row + (r + 1) * sample_width]
        });
        // The triangle shown at a pixel's first sample, when there is one.
        let first_tri = |px: usize| {
            let value = lines[0][px * SS];
            (value != EMPTY).then_some(((value & 0xffff_ffff) >> 1) as usize)
        };
        for px in cols.clone() {
            let sx = px * SS;
            // One range check per sample row: the run then has SS samples.
            let pixel: [[u64; SS]; SS] = std::array::from_fn(|r| {
                let run = &lines[r][sx..sx + SS];
                std::array::from_fn(|c| run[c])
            });
            // An empty sample is all ones: the AND of all-empty samples is.
            let mut all = EMPTY;
            let mut any_empty = false;
            for run in pixel {
                for value in run {
                    all &= value;
                    any_empty |= value == EMPTY;
                }
            }
            if all == EMPTY {
                row[px * 4..px * 4 + 4].copy_from_slice(&bg);
                continue;
            }
            shader.prefetch_ahead(px, cols.end, first_tri);
            // Every sample shows one colour group's surface (no section
            // cap): shaded once, at the first sample.
            if !any_empty {
                let first_id = pixel[0][0] & 0xffff_ffff;
                let group = group_of(first_id);
                let one_group = !shader.is_cap(first_id, group)
                    && match scene.same_sides {
                        // A sample's group is its side's (the id's low bit):
                        // all one when both sides show one group, else when
                        // every sample shows the first one's side.
                        Some([front, back]) => {
                            front == back
                                || pixel.iter().flatten().fold(0, |d, &v| d | (v ^ first_id)) & 1
                                    == 0
                        }
                        None => pixel.iter().all(|run| {
                            run.iter().all(|&value| {
                                let id = value & 0xffff_ffff;
                                id == first_id || group_of(id) == group
                            })
                        }),
                    };
                if one_group && queued {
                    if queue.push(first_id as u32, sx as u32, px as u32) {
                        queue.flush(&shader, sy, py, row);
                    }
                    continue;
                }
                if one_group {
                    let color = shader.shade(first_id, sx, sy, px, py);
                    row[px * 4..px * 4 + 4].copy_from_slice(&[color[0], color[1], color[2], 255]);
                    continue;
                }
            }
            let mut sum = PixelSum::default();
            for (r, run) in pixel.iter().enumerate() {
                for (c, &value) in run.iter().enumerate() {
                    sum.add_sample(value, background, || {
                        shader.shade(value & 0xffff_ffff, sx + c, sy + r, px, py)
                    });
                }
            }
            sum.write((SS * SS) as u32, &mut row[px * 4..px * 4 + 4]);
        }
        queue.flush(&shader, sy, py, row);
    }
}

#[cfg(test)]
mod tests {
    use super::super::resolve::{Samples, resolve_rows};
    use super::super::scene::{Group, Scene};
    use super::*;
    use std::borrow::Cow;

    /// Two triangles on two faces (a surface and a section cap), with
    /// distinct light per node, so pixels can be background, one group,
    /// mixed, or hatched.
    fn scene_and_projection(ss: usize) -> (Scene<'static>, Projected) {
        let tris = vec![[0, 1, 2], [1, 3, 2]];
        let scene = Scene {
            points: Cow::Owned(vec![[0.0; 3]; 4]),
            tris: Cow::Owned(tris.clone()),
            tri_face: vec![0, 1],
            one_face: None,
            face_sides: vec![[0, 1], [2, 2]],
            same_sides: None,
            corner_slots: Cow::Owned(tris),
            light: vec![[0.9, 0.3], [0.5, 0.7], [0.25, 1.0], [0.6, 0.4]],
            groups: (0..3)
                .map(|g| Group {
                    name: format!("g{g}"),
                    color: [40 + 70 * g as u8, 200 - 50 * g as u8, 90],
                    cap: g == 2,
                })
                .collect(),
        };
        let s = ss as f32;
        let proj = Projected {
            snapped: Vec::new(),
            xy_f: vec![
                [0.0, 0.0],
                [9.0 * s, 0.5],
                [0.5, 7.0 * s],
                [8.5 * s, 6.5 * s],
            ],
            xy_light: Vec::new(),
        };
        (scene, proj)
    }

    #[test]
    fn one_read_per_pixel_resolves_as_the_general_resolver() {
        for ss in 1..=4 {
            let (scene, proj) = scene_and_projection(ss);
            let (width, height) = (9, 7);
            let (sw, sh) = (width * ss, height * ss);
            // Samples drawn from empty, either side of either triangle, by a
            // fixed scramble: every kind of pixel shows up.
            let data: Vec<u64> = (0..sw * sh)
                .map(|i| match (i * 7919 + i / sw * 31) % 11 {
                    // The first pixel column is background.
                    _ if i % sw < ss => EMPTY,
                    // The second shows one triangle's front.
                    _ if i % sw < 2 * ss => 5 << 32,
                    0..=2 => EMPTY,
                    k => ((k as u64) << 32) | (k as u64 % 4),
                })
                .collect();
            let no_marks = vec![false; sw * sh];
            let resolve = |edges: &[bool], background: [u8; 4]| {
                let samples = Samples {
                    data: &data,
                    width: sw,
                    y0: 0,
                    edges,
                };
                let mut out = vec![0u8; width * height * 4];
                resolve_rows(
                    &scene,
                    &proj,
                    &samples,
                    ss,
                    background,
                    0,
                    0..width,
                    &mut out,
                );
                out
            };
            for background in [[255, 255, 255, 255], [32, 48, 64, 0]] {
                let general = resolve(&no_marks, background);
                let once = resolve(&[], background);
                assert_eq!(once, general, "ss {ss}");
                // Background and shaded pixels occur.
                let pixels: Vec<&[u8]> = once.chunks(4).collect();
                assert!(pixels.iter().any(|p| *p == background_pixel(background)));
                assert!(
                    pixels
                        .iter()
                        .any(|p| p[3] == 255 && *p != background_pixel(background))
                );
                // Over a transparent background, a pixel partly covered
                // is partly opaque.
                if ss > 1 && background[3] == 0 {
                    assert!(pixels.iter().any(|p| p[3] != 255 && p[3] != 0));
                }
            }
        }
    }
}
