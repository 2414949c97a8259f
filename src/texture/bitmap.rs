//! Tiled colour textures from images, and the policy for reading a colour image file: sRGB or
//! linear by format unless the scene says, non-finite texels refused, negative ones clamped.

use std::path::Path;
use std::sync::Arc;

use glam::{Vec2, Vec3};
use image::DynamicImage;

use super::TextureError;
use super::footprint::{Footprint, lookup_anisotropic};
use super::mipmap::{MipMap, check_finite, decode_limited, file_reader};

/// A colour image file read into a linear-RGB pyramid, with what the reading did.
#[derive(Debug, Clone, PartialEq)]
pub struct ColourImage {
    /// The linear-RGB pyramid.
    pub mip: MipMap<Vec3>,
    /// The file holds float values (EXR), not 8/16-bit ones.
    pub float: bool,
    /// Values were decoded from sRGB (asked for, or by default for 8/16-bit images).
    pub srgb: bool,
    /// Texels with a negative channel (possible in float images), clamped to 0: a reflectance
    /// cannot be negative.
    pub negative_texels: usize,
    /// The first such texel (x, y from the top-left).
    pub first_negative: Option<(u32, u32)>,
}

/// Reads a colour texture image (PNG, JPEG or EXR by extension) under the texture limits.
/// `srgb`: decode the stored values from sRGB to linear; `None` decides by the format: yes for
/// 8/16-bit images (photographs and paintings are sRGB), no for float images (EXR holds linear
/// values). Negative channels are clamped to 0 and counted; finite values are clamped to
/// ±[`MAX_TEXEL`](super::mipmap::MAX_TEXEL).
///
/// # Errors
/// [`TextureError::NonFinite`] for NaN or infinite values, and the errors of
/// [`MipMap::open`].
pub fn read_colour_image(path: &Path, srgb: Option<bool>) -> Result<ColourImage, TextureError> {
    let img = decode_limited(file_reader(path)?, size_of::<Vec3>() as u64)?;
    colour_image(img, srgb)
}

/// [`read_colour_image`] of an already decoded image.
///
/// # Errors
/// As [`read_colour_image`].
pub fn colour_image(img: DynamicImage, srgb: Option<bool>) -> Result<ColourImage, TextureError> {
    let float = matches!(
        img,
        DynamicImage::ImageRgb32F(_) | DynamicImage::ImageRgba32F(_)
    );
    let srgb = srgb.unwrap_or(!float);
    let mut rgb = img.into_rgb32f();
    let width = rgb.width();
    check_finite(rgb.as_raw(), width, 3)?;
    let mut negative_texels = 0;
    let mut first_negative = None;
    for (i, px) in rgb.pixels_mut().enumerate() {
        if px.0.iter().any(|c| *c < 0.0) {
            negative_texels += 1;
            first_negative.get_or_insert((i as u32 % width, i as u32 / width));
            px.0 = px.0.map(|c| c.max(0.0));
        }
    }
    Ok(ColourImage {
        mip: MipMap::from_rgb32f(rgb, srgb)?,
        float,
        srgb,
        negative_texels,
        first_negative,
    })
}

/// A colour image repeated `tile` times per axis over the surface's uv square, looked up with
/// trilinear mipmapping.
#[derive(Debug, Clone, PartialEq)]
pub struct BitmapTexture {
    /// The linear-RGB pyramid (shared by every texture made from the same file).
    pub mip: Arc<MipMap<Vec3>>,
    /// Repeat count per axis: the image appears `tile.x × tile.y` times over uv ∈ [0, 1]².
    pub tile: Vec2,
}

impl BitmapTexture {
    /// A texture repeating `mip` `tile` times per axis.
    #[must_use]
    pub fn new(mip: impl Into<Arc<MipMap<Vec3>>>, tile: Vec2) -> Self {
        Self {
            mip: mip.into(),
            tile,
        }
    }

    /// Linear RGB at surface coordinates `uv`, filtered over the pixel's `footprint` (in
    /// surface uv units, before tiling) with [`lookup_anisotropic`]. Texture coordinates are
    /// `uv × tile`.
    #[inline]
    #[must_use]
    pub fn eval(&self, uv: Vec2, footprint: &Footprint) -> Vec3 {
        lookup_anisotropic(&self.mip, uv * self.tile, &footprint.tiled(self.tile))
    }
}

crate::key_hash_struct!(BitmapTexture { mip, tile });

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiling_repeats_the_image_and_scales_the_footprint() {
        // 2×1: red, green.
        let mip = MipMap::new(2, 1, vec![Vec3::X, Vec3::Y]).unwrap();
        let t = BitmapTexture::new(mip, Vec2::new(3.0, 1.0));
        // Tile 3 in u: texel centres of the first repeat at u = 1/12 (red) and 3/12 (green),
        // and the same in the third repeat at u = 9/12, 11/12.
        for (u, c) in [
            (1.0, Vec3::X),
            (3.0, Vec3::Y),
            (9.0, Vec3::X),
            (11.0, Vec3::Y),
        ] {
            assert!(
                t.eval(Vec2::new(u / 12.0, 0.5), &Footprint::POINT)
                    .distance(c)
                    < 1e-6,
                "{u}"
            );
        }
        // With a uniform tile (3, 3) a round footprint stays round: 1/6 surface uv is 1/2
        // texture uv, level log2(0.5 · 2) = 0; 1/3 is 1 texture uv, level 1, the 1×1 mean.
        let t = BitmapTexture::new(t.mip.clone(), Vec2::splat(3.0));
        assert!(
            t.eval(Vec2::new(1.0 / 12.0, 0.5), &Footprint::isotropic(1.0 / 6.0))
                .distance(Vec3::X)
                < 1e-6
        );
        let mean = t.eval(Vec2::new(1.0 / 12.0, 0.5), &Footprint::isotropic(1.0 / 3.0));
        assert!(mean.distance(Vec3::new(0.5, 0.5, 0.0)) < 1e-6, "{mean}");
        // With tile (3, 1) the same round footprint is 3× longer in u than in v: filtered
        // along u (probes spread over half the image), so no longer the red texel alone.
        let stretched = BitmapTexture::new(t.mip.clone(), Vec2::new(3.0, 1.0));
        let c = stretched.eval(Vec2::new(1.0 / 12.0, 0.5), &Footprint::isotropic(1.0 / 6.0));
        assert!(
            c.x > 0.6 && c.y > 0.1 && (c.x + c.y - 1.0).abs() < 1e-5,
            "{c}"
        );
    }
}
