//! Compiled textures as materials use them: colour sources and height (bump) sources, each
//! evaluated at a surface point with the pixel's footprint there.

use glam::{Vec2, Vec3};

use crate::texture::noise::octaves_for;
use crate::texture::{
    BitmapTexture, Footprint, HeightMap, Marble, Noise, NormalMap, Ripples, perturb_normal,
    perturb_normal_by_gradient,
};

/// Where a procedural texture is evaluated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mapping {
    /// At the world-space position (solid texturing).
    Solid,
    /// At `(u, v, 0)`.
    Uv,
}

/// Fractal noise with a two-colour ramp and a bump depth.
#[derive(Debug, Clone, PartialEq)]
pub struct NoiseTexture {
    /// The seeded noise.
    pub noise: Noise,
    /// Colour at value 0.
    pub low: Vec3,
    /// Colour at value 1.
    pub high: Vec3,
    /// Frequency of the first octave.
    pub frequency: f32,
    /// Octaves summed.
    pub octaves: u32,
    /// Turbulence (Σ|noise|) instead of fBm.
    pub turbulence: bool,
    /// Bump height of value 1, in world units.
    pub depth: f32,
    /// Where it is evaluated.
    pub mapping: Mapping,
}

impl NoiseTexture {
    /// The value in [0, 1] at texture-space point `q` and its gradient with respect to `q`:
    /// turbulence as is, fBm mapped by `½ + ½·fbm`; both clamped to [0, 1] (the gradient is not).
    /// Octaves finer than a footprint `width` (in the units of `q`) are left out (fBm, mean 0)
    /// or replaced by their mean (turbulence).
    fn value_and_gradient(&self, q: Vec3, width: f32, want_gradient: bool) -> (f32, Vec3) {
        let q = q * self.frequency;
        let resolved = octaves_for(width * self.frequency, self.octaves);
        if self.turbulence {
            let (v, g) = if want_gradient {
                self.noise
                    .turbulence_with_gradient_octaves(q, self.octaves, resolved)
            } else {
                (
                    self.noise.turbulence_octaves(q, self.octaves, resolved),
                    Vec3::ZERO,
                )
            };
            (v.clamp(0.0, 1.0), g * self.frequency)
        } else {
            let v = 0.5 + 0.5 * self.noise.fbm_octaves(q, resolved);
            let g = if want_gradient {
                self.noise.fbm_gradient_octaves(q, resolved) * (0.5 * self.frequency)
            } else {
                Vec3::ZERO
            };
            (v.clamp(0.0, 1.0), g)
        }
    }
}

/// A texture ready for lookups.
#[derive(Debug, Clone, PartialEq)]
pub enum Texture {
    /// A mipmapped colour image.
    Bitmap(BitmapTexture),
    /// A mipmapped height image.
    HeightMap(HeightMap),
    /// Marble veins (colour), embossed by `depth` when used as a bump.
    Marble {
        /// The pattern.
        marble: Marble,
        /// Bump height of a vein centre, in world units.
        depth: f32,
        /// Where it is evaluated.
        mapping: Mapping,
    },
    /// Fractal noise.
    Noise(NoiseTexture),
    /// Water ripples over uv.
    Ripple(Ripples),
    /// A tangent-space normal map (used by a material's `normal_map`, never as a colour or a
    /// height).
    NormalMap(NormalMap),
}

/// Where and how large a lookup is: the surface point and its parameterisation, and the pixel's
/// footprint there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lookup {
    /// World-space position.
    pub p: Vec3,
    /// Texture coordinates.
    pub uv: Vec2,
    /// The pixel's footprint in uv units ([`Footprint::POINT`]: sharpest).
    pub footprint: Footprint,
    /// The pixel's footprint width in world units across the ray (0: sharpest), for solid
    /// textures.
    pub width: f32,
}

/// Where a procedural texture is evaluated, and the footprint's width in those units.
#[inline]
fn at(mapping: Mapping, l: &Lookup) -> (Vec3, f32) {
    match mapping {
        Mapping::Solid => (l.p, l.width),
        Mapping::Uv => (Vec3::new(l.uv.x, l.uv.y, 0.0), l.footprint.width()),
    }
}

impl Texture {
    /// Linear RGB colour at `l`. Height-only textures (validated never to be colours) give grey
    /// of their height.
    #[must_use]
    pub fn color(&self, l: &Lookup) -> Vec3 {
        match self {
            Texture::Bitmap(b) => b.eval(l.uv, &l.footprint),
            Texture::Marble {
                marble, mapping, ..
            } => {
                let (q, w) = at(*mapping, l);
                marble.eval_filtered(q, w)
            }
            Texture::Noise(n) => {
                let (q, w) = at(n.mapping, l);
                let (v, _) = n.value_and_gradient(q, w, false);
                n.low.lerp(n.high, v)
            }
            Texture::HeightMap(h) => Vec3::splat(h.height(l.uv, l.footprint.width())),
            Texture::Ripple(r) => Vec3::splat(r.height(l.uv)),
            // Validated never to be a colour: its tangent-space vector remapped to [0, 1].
            Texture::NormalMap(m) => m.tangent_normal(l.uv, &l.footprint) * 0.5 + Vec3::splat(0.5),
        }
    }

    /// The unit normal `n` (outward, with the surface's `dpdu`, `dpdv`) perturbed by this
    /// texture's height field at `l`, or replaced by a normal map's normal in the tangent frame
    /// of `dpdu`, `dpdv`. Bitmaps leave `n` unchanged.
    #[must_use]
    pub fn bump(&self, n: Vec3, dpdu: Vec3, dpdv: Vec3, l: &Lookup) -> Vec3 {
        let by_gradient = |mapping: Mapping, g: Vec3| match mapping {
            Mapping::Solid => perturb_normal_by_gradient(n, g),
            Mapping::Uv => perturb_normal(n, dpdu, dpdv, g.x, g.y),
        };
        match self {
            Texture::HeightMap(h) => h.perturb(n, dpdu, dpdv, l.uv, l.footprint.width()),
            Texture::Ripple(r) => r.perturb(n, dpdu, dpdv, l.uv),
            Texture::Marble {
                marble,
                depth,
                mapping,
            } => {
                if *depth == 0.0 {
                    return n;
                }
                let (q, w) = at(*mapping, l);
                by_gradient(
                    *mapping,
                    marble.vein_weight_gradient_filtered(q, w) * *depth,
                )
            }
            Texture::Noise(t) => {
                if t.depth == 0.0 {
                    return n;
                }
                let (q, w) = at(t.mapping, l);
                let (_, g) = t.value_and_gradient(q, w, true);
                by_gradient(t.mapping, g * t.depth)
            }
            Texture::NormalMap(m) => m.perturb(n, dpdu, dpdv, l.uv, &l.footprint),
            Texture::Bitmap(_) => n,
        }
    }

    /// True if lookups depend on the footprint (image textures), so it is worth computing.
    #[must_use]
    pub fn filtered(&self) -> bool {
        matches!(
            self,
            Texture::Bitmap(_) | Texture::HeightMap(_) | Texture::NormalMap(_)
        )
    }
}
