//! The false-colour error image of `caustic compare --error-image`: each pixel's error mapped
//! through viridis (perceptually uniform, readable in grey and by most colour-blind viewers),
//! with a colour bar under the image labelled with its scale, so the file explains itself.

use std::io::Cursor;
use std::path::Path;

use image::{ImageFormat, Rgb, RgbImage};
use plotters::style::colors::colormaps::{ColorMap, ViridisRGB};

use crate::render::output::{OutputError, write_atomic};

use super::pixel_font::{GLYPH, draw_text, text_width};

/// Narrowest canvas: room for the colour bar's labels.
const MIN_WIDTH: u32 = 240;
/// Margin, gap and bar height, in pixels.
const PAD: u32 = 4;
const BAR: u32 = 12;
/// Background and text colours.
const BACKGROUND: [u8; 3] = [24, 24, 24];
const INK: [u8; 3] = [235, 235, 235];
/// Colour of pixels whose error is not a number (a NaN in either image).
const NAN_COLOUR: [u8; 3] = [255, 0, 255];

/// The colour scale of an error image: errors from 0 to `max` span viridis; larger ones are
/// drawn in its top colour.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ErrorScale {
    /// The error drawn in the top colour.
    pub max: f32,
    /// Where `max` came from, for the summary (`"99th percentile"`, `"--error-max"`).
    pub source: &'static str,
}

/// The scale for `errors` when the user gave none: the 99th percentile (so a few fireflies do
/// not turn the rest of the image dark), or 1 when nearly every pixel is exact.
#[must_use]
pub fn default_scale(errors: &[f32]) -> ErrorScale {
    let mut v: Vec<f32> = errors.iter().copied().filter(|e| e.is_finite()).collect();
    v.sort_by(f32::total_cmp);
    let p99 = if v.is_empty() {
        0.0
    } else {
        v[((v.len() - 1) as f64 * 0.99).round() as usize]
    };
    if p99 > 0.0 {
        ErrorScale {
            max: p99,
            source: "99th percentile",
        }
    } else {
        ErrorScale {
            max: 1.0,
            source: "1: the 99th percentile is 0",
        }
    }
}

/// A value for a label: three significant digits, in scientific notation when very small or
/// large.
#[must_use]
pub fn label(v: f32) -> String {
    let a = v.abs();
    if v == 0.0 {
        "0".into()
    } else if (0.01..1000.0).contains(&a) {
        let digits = (2 - a.log10().floor() as i32).max(0) as usize;
        format!("{v:.digits$}")
    } else {
        format!("{v:.2e}")
    }
}

/// Whole-pixel magnification of a small error image (a `--region` crop, a thumbnail), so that
/// it is about as wide as the colour bar: 1 for images at least [`MIN_WIDTH`] wide, at most 16.
#[must_use]
pub fn zoom(width: u32) -> u32 {
    (MIN_WIDTH / width.max(1)).clamp(1, 16)
}

/// The error image: `errors` (row-major, `width`×`height`) in false colour on top, each pixel a
/// [`zoom`]×zoom square, then a colour bar from 0 to `scale.max` with both ends labelled and the
/// quantity named.
#[must_use]
pub fn render(errors: &[f32], width: u32, height: u32, scale: ErrorScale) -> RgbImage {
    render_named(errors, width, height, scale, "RMS error (linear)")
}

/// [`render`] with the quantity under the colour bar named `name`.
#[must_use]
pub fn render_named(
    errors: &[f32],
    width: u32,
    height: u32,
    scale: ErrorScale,
    name: &str,
) -> RgbImage {
    let z = zoom(width);
    let canvas_w = (width * z).max(MIN_WIDTH);
    let bar_top = height * z + PAD;
    let text_top = bar_top + BAR + PAD;
    let canvas_h = text_top + 2 * GLYPH + 2 * PAD;
    let mut img = RgbImage::from_pixel(canvas_w, canvas_h, Rgb(BACKGROUND));
    let colour = |e: f32| -> [u8; 3] {
        if e.is_nan() {
            return NAN_COLOUR;
        }
        let c = ViridisRGB.get_color_normalized(e.clamp(0.0, scale.max), 0.0, scale.max);
        [c.0, c.1, c.2]
    };
    for (i, e) in errors.iter().enumerate() {
        let (x, y) = (i as u32 % width, i as u32 / width);
        if y < height {
            for (dx, dy) in (0..z).flat_map(|a| (0..z).map(move |b| (a, b))) {
                img.put_pixel(x * z + dx, y * z + dy, Rgb(colour(*e)));
            }
        }
    }
    let bar_w = canvas_w - 2 * PAD;
    for x in 0..bar_w {
        let e = scale.max * x as f32 / (bar_w - 1).max(1) as f32;
        for y in bar_top..bar_top + BAR {
            img.put_pixel(PAD + x, y, Rgb(colour(e)));
        }
    }
    let top = i64::from(text_top);
    draw_text(&mut img, i64::from(PAD), top, "0", 1, INK);
    let max = format!(">={}", label(scale.max));
    let right = i64::from(canvas_w - PAD) - i64::from(text_width(&max, 1));
    draw_text(&mut img, right, top, &max, 1, INK);
    let centre = (i64::from(canvas_w) - i64::from(text_width(name, 1))) / 2;
    draw_text(&mut img, centre, top + i64::from(GLYPH + PAD), name, 1, INK);
    img
}

/// Writes `img` as a PNG at `path`, atomically.
pub fn write_png(img: &RgbImage, path: &Path) -> Result<(), OutputError> {
    let mut bytes = Cursor::new(Vec::new());
    img.write_to(&mut bytes, ImageFormat::Png)
        .map_err(|source| OutputError::Encode {
            path: path.to_path_buf(),
            source,
        })?;
    write_atomic(path, bytes.get_ref())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_scale_is_the_99th_percentile_and_labels_are_readable() {
        // 0.00, 0.01, ..., 0.99 and one firefly of 50: 101 values, the 99th percentile is the
        // value at index round(100 × 0.99) = 99 of the sorted list, 0.99.
        let mut e: Vec<f32> = (0..100).map(|i| i as f32 / 100.0).collect();
        e.push(50.0);
        assert_eq!(default_scale(&e).max, 0.99);
        assert_eq!(default_scale(&[0.0; 5]).max, 1.0);
        assert_eq!(label(0.0), "0");
        assert_eq!(label(0.012_345), "0.0123");
        assert_eq!(label(1.5), "1.50");
        assert_eq!(label(123.4), "123");
        assert_eq!(label(0.000_123_4), "1.23e-4");
    }

    #[test]
    fn pixels_map_to_the_ends_of_viridis_and_the_bar_runs_between_them() {
        let scale = ErrorScale {
            max: 0.5,
            source: "test",
        };
        let img = render(&[0.0, 0.5, 7.0, f32::NAN], 2, 2, scale);
        // A 2×2 image is drawn 16 times larger: 32×32 pixels.
        assert_eq!((zoom(2), zoom(100), zoom(240), zoom(1000)), (16, 2, 1, 1));
        assert_eq!(img.width(), MIN_WIDTH);
        // Viridis runs from dark purple (68, 1, 84) to yellow (253, 231, 37).
        let (low, high) = (img.get_pixel(0, 0).0, img.get_pixel(16, 0).0);
        assert!(low[2] > low[1] && low[0] < 100, "{low:?}");
        assert!(high[0] > 200 && high[1] > 200 && high[2] < 100, "{high:?}");
        assert_eq!(img.get_pixel(15, 15).0, low);
        assert_eq!(
            img.get_pixel(0, 16).0,
            high,
            "errors above the scale saturate"
        );
        assert_eq!(img.get_pixel(31, 31).0, NAN_COLOUR);
        assert_eq!(img.get_pixel(32, 0).0, BACKGROUND);
        let bar_y = 32 + PAD + BAR / 2;
        assert_eq!(img.get_pixel(PAD, bar_y).0, low);
        assert_eq!(img.get_pixel(MIN_WIDTH - PAD - 1, bar_y).0, high);
    }
}
