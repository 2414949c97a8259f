//! The pixel's footprint on a surface in uv space, and anisotropic filtering over it.

use glam::Vec2;

use super::mipmap::{MipMap, Texel};

/// Most trilinear probes one anisotropic lookup takes; footprints longer than this many times
/// their width are blurred across (as GPUs do at 16× anisotropic filtering).
pub const MAX_ANISOTROPY: f32 = 16.0;

/// A pixel's footprint on the surface, in the surface's uv units: an ellipse-like region with
/// a long axis `major` (a uv vector spanning the whole footprint) and a width `minor` across it.
/// A footprint seen head-on has `|major| ≈ minor`; at grazing angles `major` is long.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Footprint {
    /// The long axis, as a uv vector from one end of the footprint to the other.
    pub major: Vec2,
    /// The width across the long axis, in uv units.
    pub minor: f32,
}

impl Footprint {
    /// A point: the sharpest lookups (level 0).
    pub const POINT: Self = Self {
        major: Vec2::ZERO,
        minor: 0.0,
    };

    /// A round footprint `width` across.
    #[must_use]
    pub fn isotropic(width: f32) -> Self {
        Self {
            major: Vec2::new(width, 0.0),
            minor: width,
        }
    }

    /// The footprint's largest extent: what an isotropic (trilinear) filter must cover to avoid
    /// aliasing.
    #[inline]
    #[must_use]
    pub fn width(&self) -> f32 {
        self.major.length().max(self.minor)
    }

    /// The footprint shrunk (or grown) uniformly by `s` ≥ 0 about its centre.
    #[inline]
    #[must_use]
    pub fn scaled(&self, s: f32) -> Self {
        Self {
            major: self.major * s,
            minor: self.minor * s,
        }
    }

    /// The footprint in the coordinates of a texture repeated `tile` times per axis: both of
    /// its axes (`major` and the width across it) are scaled per axis, and the longer of the
    /// two becomes the new long axis (a non-uniform tile can turn a footprint's short side into
    /// its long one).
    #[inline]
    #[must_use]
    pub fn tiled(&self, tile: Vec2) -> Self {
        let len = self.major.length();
        if !(len > 0.0) {
            return Self {
                major: Vec2::new(self.minor * tile.x.abs(), 0.0),
                minor: self.minor * tile.abs().min_element(),
            };
        }
        let a = self.major * tile;
        let b = self.major.perp() * (self.minor / len) * tile;
        let (long, short) = if a.length_squared() >= b.length_squared() {
            (a, b)
        } else {
            (b, a)
        };
        let long_len = long.length();
        Self {
            major: long,
            minor: if long_len > 0.0 {
                long.perp_dot(short).abs() / long_len
            } else {
                0.0
            },
        }
    }
}

/// `mip` filtered over `footprint` (in texture uv) around `uv`: up to [`MAX_ANISOTROPY`]
/// trilinear lookups spread along the long axis, each at the level of the footprint's width,
/// averaged. Sharp along the short axis where a single trilinear lookup would blur the whole
/// footprint to its longest extent; one trilinear lookup when the footprint is round. Lookups
/// never allocate.
#[must_use]
pub fn lookup_anisotropic<T: Texel>(mip: &MipMap<T>, uv: Vec2, footprint: &Footprint) -> T {
    let len = footprint.major.length();
    if !(len > footprint.minor) || !len.is_finite() {
        return mip.lookup(uv, footprint.width());
    }
    let minor = footprint.minor.max(len / MAX_ANISOTROPY);
    let n = (len / minor).ceil().clamp(1.0, MAX_ANISOTROPY) as u32;
    if n == 1 {
        return mip.lookup(uv, len);
    }
    let mut sum = T::default();
    for i in 0..n {
        let s = (i as f32 + 0.5) / n as f32 - 0.5;
        sum = sum + mip.lookup(uv + footprint.major * s, minor);
    }
    sum * (1.0 / n as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Vertical stripes one texel wide: 0, 1, 0, 1, … across x; constant down y.
    fn stripes() -> MipMap<f32> {
        let (w, h) = (64u32, 64u32);
        let texels = (0..w * h).map(|i| (i % w % 2) as f32).collect();
        MipMap::new(w, h, texels).unwrap()
    }

    #[test]
    fn round_footprints_are_one_trilinear_lookup() {
        let m = stripes();
        let uv = Vec2::new(0.3, 0.6);
        for w in [0.0, 1.0 / 64.0, 0.1, 2.0] {
            assert_eq!(
                lookup_anisotropic(&m, uv, &Footprint::isotropic(w)),
                m.lookup(uv, w)
            );
        }
        assert_eq!(
            lookup_anisotropic(&m, uv, &Footprint::POINT),
            m.lookup(uv, 0.0)
        );
        // Non-finite footprints fall back to a plain lookup (level 0 for NaN).
        let nan = Footprint {
            major: Vec2::NAN,
            minor: f32::NAN,
        };
        assert!(lookup_anisotropic(&m, uv, &nan).is_finite());
    }

    #[test]
    fn a_footprint_long_across_fine_stripes_averages_them_but_stays_sharp_along_them() {
        let m = stripes();
        // Long across the stripes (x), thin along them: the average of 0 and 1.
        let across = Footprint {
            major: Vec2::new(16.0 / 64.0, 0.0),
            minor: 1.0 / 64.0,
        };
        let v = lookup_anisotropic(&m, Vec2::new(0.5, 0.5), &across);
        assert!((v - 0.5).abs() < 0.05, "{v}");
        // Long along the stripes (y), thin across them: the texel itself (level 0) is kept,
        // where a trilinear lookup of the same extent would have blurred it to the mean.
        let along = Footprint {
            major: Vec2::new(0.0, 16.0 / 64.0),
            minor: 0.5 / 64.0,
        };
        let uv = Vec2::new(1.5 / 64.0, 0.5);
        let v = lookup_anisotropic(&m, uv, &along);
        assert!((v - 1.0).abs() < 1e-5, "{v}");
        let blurred = m.lookup(uv, along.width());
        assert!((blurred - 0.5).abs() < 0.05, "{blurred}");
    }

    #[test]
    fn tiling_scales_the_footprint_per_axis() {
        // Uniform tiling scales everything.
        let f = Footprint {
            major: Vec2::new(0.1, 0.2),
            minor: 0.05,
        }
        .tiled(Vec2::splat(4.0));
        assert!(f.major.distance(Vec2::new(0.4, 0.8)) < 1e-6 && (f.minor - 0.2).abs() < 1e-6);
        // A round footprint under tile (1, 16) becomes long in v and stays thin in u.
        let f = Footprint::isotropic(0.01).tiled(Vec2::new(1.0, 16.0));
        assert!((f.major.length() - 0.16).abs() < 1e-6, "{f:?}");
        assert!(f.major.x.abs() < 1e-7, "{f:?}");
        assert!((f.minor - 0.01).abs() < 1e-6, "{f:?}");
        // Area is scaled by the tile's determinant: |major| · minor.
        let g = Footprint {
            major: Vec2::new(0.03, 0.04),
            minor: 0.01,
        };
        let t = g.tiled(Vec2::new(3.0, 0.5));
        let area = |f: &Footprint| f.major.length() * f.minor;
        assert!((area(&t) - area(&g) * 1.5).abs() < 1e-7, "{t:?}");
        assert_eq!(
            Footprint::POINT.tiled(Vec2::new(2.0, 3.0)),
            Footprint::POINT
        );
    }
}
