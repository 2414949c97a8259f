//! Tangent-space normal maps: an RGB image whose texels are unit normals in the surface's
//! tangent frame, `(x, y, z)` encoded as `(r, g, b)`, which replace the shading normal.
//!
//! Conventions (those of OpenGL, Blender and Mitsuba 3's `normalmap`): x runs along +u (the
//! image's right), y along the image's *up* (−v here, since v grows downwards), z along the
//! surface normal; `flip_y` reads maps made for the other (DirectX) convention. An 8-bit channel
//! value `c` decodes to `(c − 128)/127` (so 128 is exactly 0 and 255 exactly 1; 0 clamps to −1),
//! a 16-bit one to `(c − 32768)/32767`, a float one to `2c − 1`. The decoded vectors are what the
//! pyramid holds, so filtering over the pixel's footprint (the same anisotropic filtering as the
//! colour textures) averages normals, not encodings. `strength` scales the tangential part
//! (0: the map does nothing, 1: as drawn).
//!
//! Applying a texel `(x, y, z)` to the shading normal `n` with tangents `dpdu`, `dpdv`:
//! `t = normalize(dpdu − (dpdu·n) n)`, `b = ±(n × t)` chosen to point towards decreasing v, and
//! `n' = normalize(s·x·t + s·y·b + z·n)`. A texel with `x = y = 0` (a flat map's 128, 128)
//! returns `n` itself, bit for bit.

use std::path::Path;
use std::sync::Arc;

use glam::{Vec2, Vec3};
use image::DynamicImage;

use super::TextureError;
use super::footprint::{Footprint, lookup_anisotropic};
use super::mipmap::{MipMap, check_finite, decode_limited, file_reader};
use crate::geometry::Frame;

/// A tangent-space normal map repeated `tile` times per axis over the uv square.
#[derive(Debug, Clone, PartialEq)]
pub struct NormalMap {
    /// The decoded tangent-space vectors (not normalised: filtering averages them).
    pub mip: Arc<MipMap<Vec3>>,
    /// Repeat count per axis, as for [`BitmapTexture`](super::BitmapTexture).
    pub tile: Vec2,
    /// Scale of the tangential part (≥ 0).
    pub strength: f32,
    /// The map's green channel points down the image (DirectX convention).
    pub flip_y: bool,
}

/// Reads a normal-map image (PNG, JPEG or EXR by extension) into a pyramid of decoded
/// tangent-space vectors (see the module docs for the decoding), under the texture limits.
///
/// # Errors
/// [`TextureError::Image`] when the file cannot be read or decoded, [`TextureError::TooLarge`]
/// over the limits, [`TextureError::NonFinite`] for NaN or infinite values.
pub fn read_normal_image(path: &Path) -> Result<MipMap<Vec3>, TextureError> {
    let img = decode_limited(file_reader(path)?, size_of::<Vec3>() as u64)?;
    decode_normal_image(img)
}

/// [`read_normal_image`] of an already decoded image.
///
/// # Errors
/// As [`read_normal_image`].
pub fn decode_normal_image(img: DynamicImage) -> Result<MipMap<Vec3>, TextureError> {
    let (w, h) = (img.width(), img.height());
    let decode: fn(f32) -> f32 = match img.color().bytes_per_pixel() / img.color().channel_count() {
        1 => |c| ((c * 255.0).round() - 128.0) / 127.0,
        2 => |c| ((c * 65535.0).round() - 32768.0) / 32767.0,
        _ => |c| 2.0 * c - 1.0,
    };
    let raw = img.into_rgb32f().into_raw();
    check_finite(&raw, w, 3)?;
    let texels = raw
        .chunks_exact(3)
        .map(|c| Vec3::new(c[0], c[1], c[2]).map(|v| decode(v).clamp(-1.0, 1.0)))
        .collect();
    drop(raw);
    MipMap::new(w, h, texels)
}

impl NormalMap {
    /// A normal map of `mip` repeated `tile` times per axis, tangential part scaled by
    /// `strength`, green read downwards with `flip_y`.
    #[must_use]
    pub fn new(mip: impl Into<Arc<MipMap<Vec3>>>, tile: Vec2, strength: f32, flip_y: bool) -> Self {
        Self {
            mip: mip.into(),
            tile,
            strength,
            flip_y,
        }
    }

    /// The filtered tangent-space vector at surface coordinates `uv` over the pixel's
    /// `footprint` (surface uv units, before tiling), `flip_y` applied, not normalised.
    #[inline]
    #[must_use]
    pub fn tangent_normal(&self, uv: Vec2, footprint: &Footprint) -> Vec3 {
        let t = lookup_anisotropic(&self.mip, uv * self.tile, &footprint.tiled(self.tile));
        if self.flip_y {
            Vec3::new(t.x, -t.y, t.z)
        } else {
            t
        }
    }

    /// The shading normal `n` (unit, outward) replaced by the map's normal at `uv`, in the
    /// tangent frame of `dpdu`, `dpdv` (see [`apply_tangent_normal`]).
    #[must_use]
    pub fn perturb(
        &self,
        n: Vec3,
        dpdu: Vec3,
        dpdv: Vec3,
        uv: Vec2,
        footprint: &Footprint,
    ) -> Vec3 {
        apply_tangent_normal(
            n,
            dpdu,
            dpdv,
            self.tangent_normal(uv, footprint),
            self.strength,
        )
    }
}

/// The unit normal `n` replaced by the tangent-space vector `t` (x along `dpdu`, y towards
/// decreasing v, z along `n`), its tangential part scaled by `strength`: see the module docs.
/// `n` itself (bit-identical) when the tangential part is 0; a frame from
/// [`Frame::from_normal`] when `dpdu` is degenerate; `n` for a non-finite result or one that
/// does not face `n`'s side.
#[must_use]
pub fn apply_tangent_normal(n: Vec3, dpdu: Vec3, dpdv: Vec3, t: Vec3, strength: f32) -> Vec3 {
    let (x, y) = (t.x * strength, t.y * strength);
    if x == 0.0 && y == 0.0 {
        return n;
    }
    let tu = dpdu - n * n.dot(dpdu);
    let (tu, mut tb) = match tu.try_normalize() {
        Some(tu) => (tu, n.cross(tu)),
        None => {
            let f = Frame::from_normal(n);
            (f.s, f.t)
        }
    };
    // Image up is towards decreasing v.
    if tb.dot(dpdv) > 0.0 {
        tb = -tb;
    }
    let out = (tu * x + tb * y + n * t.z).normalize();
    if out.is_finite() && out.dot(n) > 0.0 {
        out
    } else {
        n
    }
}

crate::key_hash_struct!(NormalMap {
    mip,
    tile,
    strength,
    flip_y
});

#[cfg(test)]
mod tests {
    use super::*;

    fn encoded(rgb: [u8; 3]) -> MipMap<Vec3> {
        let img = image::RgbImage::from_pixel(4, 4, image::Rgb(rgb));
        decode_normal_image(DynamicImage::ImageRgb8(img)).expect("decodes")
    }

    #[test]
    fn eight_bit_decoding_is_exact_at_128_and_255() {
        let m = encoded([128, 255, 255]);
        assert_eq!(m.texel(0, 0, 0), Vec3::new(0.0, 1.0, 1.0));
        let m = encoded([0, 1, 128]);
        assert_eq!(m.texel(0, 0, 0), Vec3::new(-1.0, -1.0, 0.0));
    }

    #[test]
    fn a_flat_map_leaves_the_normal_bit_identical_at_any_footprint() {
        let map = NormalMap::new(encoded([128, 128, 255]), Vec2::new(3.0, 2.0), 1.0, false);
        let n = Vec3::new(0.3, 0.1, 0.9).normalize();
        for f in [
            Footprint::POINT,
            Footprint::isotropic(0.1),
            Footprint::isotropic(3.0),
        ] {
            let got = map.perturb(n, Vec3::X, Vec3::Y, Vec2::new(0.37, 0.81), &f);
            assert_eq!(got, n);
        }
    }

    #[test]
    fn a_tilted_texel_tilts_by_its_angle_towards_u_and_image_up() {
        // On the plane z = 0 with u along +x and v along −y (image up = +y): the texel
        // (sin α, 0, cos α) tilts the normal by α towards +x, (0, sin α, cos α) towards +y.
        let a = 20f32.to_radians();
        let n = Vec3::Z;
        let m = apply_tangent_normal(n, Vec3::X, -Vec3::Y, Vec3::new(a.sin(), 0.0, a.cos()), 1.0);
        assert!(m.distance(Vec3::new(a.sin(), 0.0, a.cos())) < 1e-6, "{m}");
        let m = apply_tangent_normal(n, Vec3::X, -Vec3::Y, Vec3::new(0.0, a.sin(), a.cos()), 1.0);
        assert!(m.distance(Vec3::new(0.0, a.sin(), a.cos())) < 1e-6, "{m}");
        // With v along +y, image up is −y.
        let m = apply_tangent_normal(n, Vec3::X, Vec3::Y, Vec3::new(0.0, a.sin(), a.cos()), 1.0);
        assert!(m.distance(Vec3::new(0.0, -a.sin(), a.cos())) < 1e-6, "{m}");
        // Strength 0 changes nothing; strength 2 doubles the tangent of the tilt.
        let t = Vec3::new(a.sin(), 0.0, a.cos());
        assert_eq!(apply_tangent_normal(n, Vec3::X, Vec3::Y, t, 0.0), n);
        let m = apply_tangent_normal(n, Vec3::X, Vec3::Y, t, 2.0);
        assert!((m.x / m.z - 2.0 * a.tan()).abs() < 1e-5, "{m}");
        // flip_y reads green downwards.
        let map = NormalMap::new(encoded([128, 255, 128]), Vec2::ONE, 1.0, true);
        assert_eq!(
            map.tangent_normal(Vec2::splat(0.5), &Footprint::POINT),
            Vec3::new(0.0, -1.0, 0.0)
        );
    }
}
