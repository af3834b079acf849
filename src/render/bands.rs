//! Rasterising and resolving fused per band of pixel rows, the path of every
//! picture without an edge overlay: a band's samples live in a buffer of its
//! own, small enough to stay in cache (16 pixel rows), and are resolved to
//! pixels as soon as the band is drawn. The full-picture sample buffer
//! (8 bytes × ss² per pixel: 32 MB at 1024² with 2×2 anti-aliasing) is never
//! built, filled or read back. Each sample is still the minimum over the
//! triangles, so any thread count gives the same picture.

use super::raster::{self, EMPTY, Projected};
use super::resolve::{Image, Samples, background_pixel, resolve_rows};
use super::scene::Scene;
use rayon::prelude::*;

/// Pixel rows per band (the unit of parallel work).
const BAND_PIXELS: usize = 16;

/// The picture of `width`×`height` pixels at `ss`×`ss` samples each.
pub fn render(
    scene: &Scene,
    proj: &Projected,
    width: usize,
    height: usize,
    ss: usize,
    background: [u8; 4],
) -> Image {
    let (sw, sh) = (width * ss, height * ss);
    let band_rows = BAND_PIXELS * ss;
    let bins = raster::bin(scene, proj, sw, sh, band_rows);
    let mut rgba = vec![0u8; width * height * 4];
    rgba.par_chunks_mut(width * 4 * BAND_PIXELS)
        .enumerate()
        .for_each_init(Vec::new, |buf: &mut Vec<u64>, (band, out)| {
            // A band no triangle reaches is background (the margins above
            // and below the model): no samples to fill and read back. Of
            // the others only the pixel columns its triangles reach are
            // filled and resolved (the margins left and right of the model).
            let bg = background_pixel(background);
            let Some((first, last)) = raster::band_columns(&bins, band) else {
                for pixel in out.chunks_exact_mut(4) {
                    pixel.copy_from_slice(&bg);
                }
                return;
            };
            let cols = first / ss..last / ss + 1;
            let y0 = band * band_rows;
            let y1 = (y0 + band_rows).min(sh);
            // Samples outside the filled columns are left as the last band
            // had them: nothing draws or reads there.
            buf.resize(sw * (y1 - y0), EMPTY);
            for row in buf[..sw * (y1 - y0)].chunks_exact_mut(sw) {
                row[cols.start * ss..cols.end * ss].fill(EMPTY);
            }
            raster::draw_band(scene, proj, &bins, band, buf, sw, y0..y1);
            let samples = Samples {
                data: buf,
                width: sw,
                y0,
                edges: &[],
            };
            for row in out.chunks_exact_mut(width * 4) {
                let (left, rest) = row.split_at_mut(cols.start * 4);
                let right = &mut rest[(cols.end - cols.start) * 4..];
                for pixel in left.chunks_exact_mut(4).chain(right.chunks_exact_mut(4)) {
                    pixel.copy_from_slice(&bg);
                }
            }
            resolve_rows(
                scene,
                proj,
                &samples,
                ss,
                background,
                band * BAND_PIXELS,
                cols,
                out,
            );
        });
    Image {
        width: width as u32,
        height: height as u32,
        rgba,
    }
}
