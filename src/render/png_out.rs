//! PNG encoding with the `png` crate: 8-bit RGBA, fast deflate and one fixed
//! filter, so encoding stays a small part of a render and the bytes depend
//! only on the pixels.

use super::resolve::Image;

// Writing into a Vec cannot fail, and the header matches the data: a failure is a bug.
#[allow(clippy::expect_used)]
pub fn encode(image: &Image) -> Vec<u8> {
    let mut out = Vec::with_capacity(image.rgba.len() / 4);
    {
        let mut encoder = png::Encoder::new(&mut out, image.width, image.height);
        encoder.set_color(png::ColorType::Rgba);
        encoder.set_depth(png::BitDepth::Eight);
        encoder.set_compression(png::Compression::Fast);
        encoder.set_filter(png::Filter::Up);
        let mut writer = encoder.write_header().expect("PNG header into memory");
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
