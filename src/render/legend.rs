//! The legend: a swatch and the name of every colour group, drawn over the
//! picture's top-left corner with the built-in font.

use super::font;
use super::resolve::Image;
use super::scene::Group;

/// Where one legend line was drawn (pixel rectangles), for tests and the SVG.
#[derive(Debug, Clone, PartialEq)]
pub struct LegendEntry {
    pub name: String,
    pub color: [u8; 3],
    /// x, y, width, height of the colour swatch.
    pub swatch: [u32; 4],
    /// x, y, width, height of the text.
    pub text: [u32; 4],
}

/// Font pixels are drawn as squares of this many image pixels.
pub fn font_scale(width: u32, height: u32) -> u32 {
    (width.min(height) / 300).clamp(1, 4)
}

/// Lays the legend out: one line per group while they fit in the picture's
/// height; returns the entries and how many groups did not fit.
pub fn layout(groups: &[Group], width: u32, height: u32) -> (Vec<LegendEntry>, usize) {
    let s = font_scale(width, height);
    let line = (font::GLYPH_H + 4) * s;
    let pad = 4 * s;
    let mut entries = Vec::new();
    let mut y = pad;
    for (i, g) in groups.iter().enumerate() {
        // Keep room for the "… more" line if this is not the last.
        let needed = if i + 1 < groups.len() { 2 * line } else { line };
        if y + needed > height {
            return (entries, groups.len() - i);
        }
        let size = font::GLYPH_H * s;
        let text_w = font::text_width(&g.name) * s;
        entries.push(LegendEntry {
            name: g.name.clone(),
            color: g.color,
            swatch: [pad, y, size, size],
            text: [pad + size + 2 * s, y, text_w, size],
        });
        y += line;
    }
    (entries, 0)
}

pub fn draw(image: &mut Image, entries: &[LegendEntry], not_shown: usize) {
    let s = font_scale(image.width, image.height);
    let more = (not_shown > 0).then(|| format!("... and {not_shown} more"));
    let bottom = entries.last().map_or(0, |e| e.text[1] + e.text[3])
        + if more.is_some() {
            (font::GLYPH_H + 4) * s
        } else {
            0
        };
    let right = entries
        .iter()
        .map(|e| e.text[0] + e.text[2])
        .chain(more.as_ref().map(|m| 4 * s + font::text_width(m) * s))
        .max()
        .unwrap_or(0);
    // A light panel keeps the names readable over the model.
    for y in 0..(bottom + 3 * s).min(image.height) {
        for x in 0..(right + 4 * s).min(image.width) {
            image.blend(x as i64, y as i64, [255, 255, 255], 0.8);
        }
    }
    for e in entries {
        for y in e.swatch[1]..e.swatch[1] + e.swatch[3] {
            for x in e.swatch[0]..e.swatch[0] + e.swatch[2] {
                image.blend(x as i64, y as i64, e.color, 1.0);
            }
        }
        text(image, &e.name, e.text[0], e.text[1], s);
    }
    if let Some(m) = more {
        let y = entries
            .last()
            .map_or(4 * s, |e| e.text[1] + (font::GLYPH_H + 4) * s);
        text(image, &m, 4 * s, y, s);
    }
}

fn text(image: &mut Image, text: &str, x0: u32, y0: u32, s: u32) {
    font::for_each_pixel(text, |fx, fy| {
        for dy in 0..s {
            for dx in 0..s {
                image.blend(
                    (x0 + fx * s + dx) as i64,
                    (y0 + fy * s + dy) as i64,
                    [0, 0, 0],
                    1.0,
                );
            }
        }
    });
}
