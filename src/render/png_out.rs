//! PNG encoding with the `png` crate: 8-bit RGBA, fast deflate and one fixed
//! filter, so encoding stays a small part of a render and the bytes depend
//! only on the pixels.

use super::resolve::Image;

/// PNG filter type 2 (Up): each byte minus the byte above it.
const FILTER_UP: u8 = 2;

// Writing into a Vec cannot fail, and the header matches the data: a failure is a bug.
#[allow(clippy::expect_used)]
pub fn encode(image: &Image) -> Vec<u8> {
    let zlib = up_filtered_zlib(image);
    let row = image.width as usize * 4;
    let stored =
        fdeflate::StoredOnlyCompressor::<()>::compressed_size((row + 1) * image.height as usize);
    if zlib.len() > stored {
        // The png crate stores such data uncompressed: let it.
        return encode_with_crate(image);
    }
    let mut out = Vec::with_capacity(zlib.len() + 64);
    {
        let mut writer = encoder(&mut out, image)
            .write_header()
            .expect("PNG header into memory");
        // One IDAT chunk, as the png crate writes a stream under 2 GB; the
        // writer adds IEND when dropped.
        writer
            .write_chunk(png::chunk::IDAT, &zlib)
            .expect("PNG data into memory");
    }
    out
}

/// The zlib stream `png::Writer::write_image_data` makes with the options of
/// [`encoder`]: each row Up-filtered behind its filter byte and given to
/// fdeflate's fast coder in one call, so the same bytes, without the png
/// crate's growing output buffer and scalar filter loop.
// Writing into a Vec cannot fail.
#[allow(clippy::expect_used)]
fn up_filtered_zlib(image: &Image) -> Vec<u8> {
    let row = image.width as usize * 4;
    // Fast deflate of a rendered picture: about a quarter of the pixels' bytes.
    let mut compressor =
        fdeflate::Compressor::new(Vec::with_capacity(image.rgba.len() / 4)).expect("into memory");
    let mut line = vec![0u8; row + 1];
    line[0] = FILTER_UP;
    let mut above: &[u8] = &[];
    for current in image.rgba.chunks_exact(row) {
        if above.is_empty() {
            line[1..].copy_from_slice(current);
        } else {
            for ((o, &c), &a) in line[1..].iter_mut().zip(current).zip(above) {
                *o = c.wrapping_sub(a);
            }
        }
        compressor.write_data(&line).expect("into memory");
        above = current;
    }
    compressor.finish().expect("into memory")
}

fn encoder<W: std::io::Write>(out: W, image: &Image) -> png::Encoder<'static, W> {
    let mut encoder = png::Encoder::new(out, image.width, image.height);
    encoder.set_color(png::ColorType::Rgba);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_compression(png::Compression::Fast);
    encoder.set_filter(png::Filter::Up);
    encoder
}

// Writing into a Vec cannot fail, and the header matches the data: a failure is a bug.
#[allow(clippy::expect_used)]
fn encode_with_crate(image: &Image) -> Vec<u8> {
    let mut out = Vec::with_capacity(image.rgba.len() / 4);
    {
        let mut writer = encoder(&mut out, image)
            .write_header()
            .expect("PNG header into memory");
        writer
            .write_image_data(&image.rgba)
            .expect("PNG data into memory");
    }
    out
}

pub fn decode(bytes: &[u8]) -> Option<Image> {
    let decoder = png::Decoder::new(std::io::Cursor::new(bytes));
    let mut reader = decoder.read_info().ok()?;
    let mut rgba = vec![0; reader.output_buffer_size()?];
    let info = reader.next_frame(&mut rgba).ok()?;
    if info.color_type != png::ColorType::Rgba || info.bit_depth != png::BitDepth::Eight {
        return None;
    }
    rgba.truncate(info.buffer_size());
    Some(Image {
        width: info.width,
        height: info.height,
        rgba,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn picture(width: u32, height: u32, pixel: impl Fn(u32, u32) -> [u8; 4]) -> Image {
        let rgba = (0..height)
            .flat_map(|y| (0..width).map(move |x| (x, y)))
            .flat_map(|(x, y)| pixel(x, y))
            .collect();
        Image {
            width,
            height,
            rgba,
        }
    }

    #[test]
    fn direct_coding_writes_the_png_crates_bytes() {
        // A background with a shaded disc (runs and varied bytes), one
        // pixel rows and columns, and noise (stored, not compressed).
        let mut rng = crate::test_rng::TestRng::new(0x3c6e_f372_fe94_f82b);
        let noise: Vec<u8> = (0..37 * 23 * 4).map(|_| rng.below(256) as u8).collect();
        let disc = |x: u32, y: u32| {
            let (dx, dy) = (x as i64 - 60, y as i64 - 40);
            if dx * dx + dy * dy < 900 {
                [(x * 3) as u8, (y * 5) as u8, 200, 255]
            } else {
                [255, 255, 255, 255]
            }
        };
        let images = [
            picture(130, 90, disc),
            picture(1, 17, disc),
            picture(17, 1, disc),
            picture(37, 23, |x, y| {
                let i = 4 * (y * 37 + x) as usize;
                [noise[i], noise[i + 1], noise[i + 2], noise[i + 3]]
            }),
        ];
        for image in &images {
            let png = encode(image);
            assert_eq!(
                png,
                encode_with_crate(image),
                "{}x{}",
                image.width,
                image.height
            );
            let back = decode(&png).expect("decodes");
            assert_eq!(back.rgba, image.rgba);
        }
    }
}
