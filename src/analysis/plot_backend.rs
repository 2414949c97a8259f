//! A plotters bitmap backend whose text is the 8×8 bitmap font of [`super::pixel_font`]:
//! plotters built without its font features (font-kit and system fonts) draws no text into
//! bitmaps, so the PNG plots of `caustic converge` draw their own.

use plotters::prelude::BitMapBackend;
use plotters_backend::{
    BackendColor, BackendCoord, BackendStyle, BackendTextStyle, DrawingBackend, DrawingErrorKind,
    text_anchor,
};

use super::pixel_font::GLYPH;

/// A bitmap backend whose text is the 8×8 bitmap font (plotters draws no text into bitmaps
/// without its font features). Everything else is the bitmap backend's.
pub struct PixelFontBackend<'a> {
    /// The backend that draws everything but text.
    pub inner: BitMapBackend<'a>,
}

/// Glyph scale for a font size in pixels: plotters' layout estimate of a character's advance
/// is 0.7 em, em = size / 1.24², i.e. 8 px at 17.6 px; each 17.6 px is one more 8 px glyph.
fn scale_for(size: f64) -> i32 {
    ((size / 17.6).round() as i32).clamp(1, 4)
}

impl DrawingBackend for PixelFontBackend<'_> {
    type ErrorType = <BitMapBackend<'static> as DrawingBackend>::ErrorType;

    fn get_size(&self) -> (u32, u32) {
        self.inner.get_size()
    }

    fn ensure_prepared(&mut self) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.ensure_prepared()
    }

    fn present(&mut self) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.present()
    }

    fn draw_pixel(
        &mut self,
        point: BackendCoord,
        color: BackendColor,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_pixel(point, color)
    }

    fn draw_line<S: BackendStyle>(
        &mut self,
        from: BackendCoord,
        to: BackendCoord,
        style: &S,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_line(from, to, style)
    }

    fn draw_rect<S: BackendStyle>(
        &mut self,
        upper_left: BackendCoord,
        bottom_right: BackendCoord,
        style: &S,
        fill: bool,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_rect(upper_left, bottom_right, style, fill)
    }

    fn draw_path<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        path: I,
        style: &S,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_path(path, style)
    }

    fn draw_circle<S: BackendStyle>(
        &mut self,
        center: BackendCoord,
        radius: u32,
        style: &S,
        fill: bool,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_circle(center, radius, style, fill)
    }

    fn fill_polygon<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        vert: I,
        style: &S,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.fill_polygon(vert, style)
    }

    fn blit_bitmap(
        &mut self,
        pos: BackendCoord,
        size: (u32, u32),
        src: &[u8],
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.blit_bitmap(pos, size, src)
    }

    fn estimate_text_size<TStyle: BackendTextStyle>(
        &self,
        text: &str,
        style: &TStyle,
    ) -> Result<(u32, u32), DrawingErrorKind<Self::ErrorType>> {
        let s = scale_for(style.size()) as u32;
        let n = u32::try_from(text.chars().count()).unwrap_or(u32::MAX / 64);
        Ok((n * GLYPH * s, GLYPH * s))
    }

    fn draw_text<TStyle: BackendTextStyle>(
        &mut self,
        text: &str,
        style: &TStyle,
        pos: BackendCoord,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        let color = style.color();
        if color.alpha == 0.0 {
            return Ok(());
        }
        let s = scale_for(style.size());
        let g = GLYPH as i32 * s;
        let width = text.chars().count() as i32 * g;
        let dx = match style.anchor().h_pos {
            text_anchor::HPos::Left => 0,
            text_anchor::HPos::Right => -width,
            text_anchor::HPos::Center => -width / 2,
        };
        let dy = match style.anchor().v_pos {
            text_anchor::VPos::Top => 0,
            text_anchor::VPos::Center => -g / 2,
            text_anchor::VPos::Bottom => -g,
        };
        let trans = style.transform();
        let (w, h) = self.get_size();
        for (i, ch) in text.chars().enumerate() {
            let code = if ch.is_ascii() {
                ch as usize
            } else {
                '?' as usize
            };
            let glyph = font8x8::legacy::BASIC_LEGACY[code];
            for (row, bits) in glyph.iter().enumerate() {
                for col in 0..8 {
                    if bits >> col & 1 == 0 {
                        continue;
                    }
                    for (sx, sy) in (0..s).flat_map(|a| (0..s).map(move |b| (a, b))) {
                        let lx = i as i32 * g + col * s + sx + dx;
                        let ly = row as i32 * s + sy + dy;
                        let (x, y) = trans.transform(lx, ly);
                        let (x, y) = (pos.0 + x, pos.1 + y);
                        if x >= 0 && y >= 0 && x < w as i32 && y < h as i32 {
                            self.inner.draw_pixel((x, y), color)?;
                        }
                    }
                }
            }
        }
        Ok(())
    }
}
