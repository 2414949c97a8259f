//! Tiled colour textures from images.

use std::sync::Arc;

use glam::{Vec2, Vec3};

use super::footprint::{Footprint, lookup_anisotropic};
use super::mipmap::MipMap;

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
