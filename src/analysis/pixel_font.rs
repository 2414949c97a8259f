//! Text in 8-bit images without a font file: the public-domain 8×8 bitmap font of the
//! `font8x8` crate, scaled by whole pixels. Used for the labels of `compare --error-image`'s
//! colour bar and of the PNG plots of `caustic converge`.

use image::{Rgb, RgbImage};

/// Width and height of one glyph at scale 1, in pixels.
pub const GLYPH: u32 = 8;

/// Width in pixels of `text` drawn at `scale` (every character is one glyph wide).
#[must_use]
pub fn text_width(text: &str, scale: u32) -> u32 {
    u32::try_from(text.chars().count()).unwrap_or(u32::MAX / 64) * GLYPH * scale
}

/// Draws `text` with its top-left corner at (`x`, `y`), each font pixel a `scale`×`scale`
/// square of `colour`. Characters outside ASCII are drawn as `?`; parts outside the image are
/// clipped.
pub fn draw_text(img: &mut RgbImage, x: i64, y: i64, text: &str, scale: u32, colour: [u8; 3]) {
    let s = i64::from(scale.max(1));
    for (i, ch) in text.chars().enumerate() {
        let code = if ch.is_ascii() {
            ch as usize
        } else {
            '?' as usize
        };
        let glyph = font8x8::legacy::BASIC_LEGACY[code];
        let left = x + i as i64 * i64::from(GLYPH) * s;
        for (row, bits) in glyph.iter().enumerate() {
            for col in 0..8 {
                if bits >> col & 1 == 1 {
                    fill(img, left + col * s, y + row as i64 * s, s, colour);
                }
            }
        }
    }
}

/// Fills the `size`×`size` square at (`x`, `y`), clipped to the image.
fn fill(img: &mut RgbImage, x: i64, y: i64, size: i64, colour: [u8; 3]) {
    let (w, h) = (i64::from(img.width()), i64::from(img.height()));
    for py in y.max(0)..(y + size).min(h) {
        for px in x.max(0)..(x + size).min(w) {
            img.put_pixel(px as u32, py as u32, Rgb(colour));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn glyphs_land_where_the_font_table_says() {
        // '1' in font8x8 is rows 0x0C, 0x0E, 0x0C, 0x0C, 0x0C, 0x0C, 0x3F, 0x00: the top row has
        // columns 2 and 3 set (0x0C = bits 2, 3), the seventh row columns 0–5.
        let mut img = RgbImage::new(20, 10);
        draw_text(&mut img, 1, 1, "1", 1, [255, 0, 0]);
        let on = |x: u32, y: u32| img.get_pixel(x, y).0 == [255, 0, 0];
        assert!(on(3, 1) && on(4, 1) && !on(2, 1) && !on(5, 1));
        assert!((1..7).all(|x| on(x, 7)) && !on(7, 7));
        assert!((0..20).all(|x| !on(x, 8)));
        // Scale 2 doubles every pixel; drawing off the edge is clipped, not a panic.
        let mut big = RgbImage::new(40, 20);
        draw_text(&mut big, 0, 0, "1", 2, [9, 9, 9]);
        assert_eq!(big.get_pixel(4, 0).0, [9, 9, 9]);
        assert_eq!(big.get_pixel(7, 1).0, [9, 9, 9]);
        assert_eq!(big.get_pixel(3, 0).0, [0, 0, 0]);
        draw_text(&mut big, -30, 15, "héllo", 3, [1, 1, 1]);
        assert_eq!(text_width("héllo", 3), 120);
    }
}
