//! Materials and textures of the scene format.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::Rgb;
use super::values::{ExactFloats, ScaleSpec, exact_floats, one, unit_size};

/// A surface material: the report's weighted mix of a diffuse/Phong part, a mirror and a dielectric.
/// See docs/material.md for the exact BSDF.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    /// Albedo of the diffuse part and tint of the mirror and of transmitted light: an RGB triple
    /// with components in [0, 1], or the name of a colour texture.
    #[serde(default = "default_color")]
    pub color: ColorSpec,
    /// Reflectance of the normalised Phong highlight, each in [0, 1].
    #[serde(default)]
    #[serde(deserialize_with = "exact_floats::<_, 3>")]
    pub specular: Rgb,
    /// Phong exponent of the highlight.
    #[serde(default = "default_shininess")]
    pub shininess: f32,
    /// Weight of the diffuse + Phong part. If all three weights are omitted the material is diffuse.
    #[serde(default)]
    pub diffuse: Option<f32>,
    /// Weight of the perfect mirror.
    #[serde(default)]
    pub reflect: Option<f32>,
    /// Weight of the smooth dielectric (Fresnel reflection + refraction).
    #[serde(default)]
    pub transmit: Option<f32>,
    /// Index of refraction of the transmitting part (inside relative to outside).
    #[serde(default = "default_ior")]
    pub ior: f32,
    /// Name of a texture that perturbs the shading normal (a height map, ripples, or noise or
    /// marble with a `depth`).
    #[serde(default)]
    pub bump: Option<String>,
    /// Name of a `NormalMap` texture whose tangent-space normals replace the shading normal
    /// (an alternative to `bump`; the two cannot both be set).
    #[serde(default)]
    pub normal_map: Option<String>,
    /// Microfacet roughness of the mirror and dielectric parts, in [0, 1]: `r`, or `(r_x, r_y)`
    /// along the shading frame's two tangents (anisotropic), or the name of a colour texture
    /// whose mean channel (clamped to [0, 1]) is the isotropic roughness at each hit. GGX with
    /// α = r² (docs/material.md). 0 (the default) is the perfect mirror and the smooth
    /// dielectric.
    #[serde(default)]
    pub roughness: RoughnessSpec,
    /// Makes the mirror part a metal: a preset name (`"chrome"`, `"aluminium"`, `"gold"`,
    /// `"copper"`, `"silver"`: measured complex indices) or an artist's colours
    /// `(f0: (r, g, b), tint: (r, g, b))` (F82-tint; `tint` defaults to white, Schlick). The
    /// metal's colour is its Fresnel reflectance: `color` does not tint it.
    #[serde(default)]
    pub conductor: Option<ConductorSpec>,
    /// Beer–Lambert absorption inside the dielectric part (water, coloured glass): the
    /// coefficient per metre `(σ_r, σ_g, σ_b)`, or the colour left after a depth
    /// `(color: (r, g, b), depth: d)` with colour in (0, 1] and `d` in metres.
    #[serde(default)]
    pub absorption: Option<AbsorptionSpec>,
    /// A smooth clear coat over the diffuse `color` (a glazed tub, plastic, varnish):
    /// `coat: (ior: 1.5)`. The coat reflects its Fresnel reflectance as a mirror and the base
    /// is seen through it (Weidlich & Wilkie 2007, docs/material.md). Not combined with
    /// `reflect`, `transmit`, `roughness`, `conductor` or `specular`; a rough coat is not
    /// implemented.
    #[serde(default)]
    pub coat: Option<CoatSpec>,
    /// The participating medium inside the material's closed surfaces (murky water, smoke):
    /// the name of one of the scene's `media` (docs/media.md). Not with `absorption` (give
    /// the medium's `sigma_a` instead).
    #[serde(default)]
    pub medium: Option<String>,
    /// The volume's rank where volumes overlap or touch (Schmidt & Budge 2002, docs/media.md):
    /// inside two volumes the higher priority's index and medium hold, and the lower one's
    /// surfaces there are not surfaces at all, so a glass of water is modelled with the water
    /// reaching into the glass wall and refracts 1.5 | 1.33 where they meet. Materials that
    /// state a priority take part in this nesting; others are interfaces against air as before.
    #[serde(default)]
    pub priority: Option<i32>,
    /// The surface is no surface: only the boundary of its `medium` (smoke in air, pbrt-v4's
    /// `interface` material). Rays cross it unbent and unreflected. Requires `medium`; takes
    /// no colour, weights, roughness, coat or textures.
    #[serde(default)]
    pub interface: bool,
}

/// A smooth dielectric clear coat over a diffuse base.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CoatSpec {
    /// The coat's index of refraction relative to the outside (> 0; 1.5 for a glaze or
    /// acrylic, 1.33 for a film of water).
    #[serde(default = "default_ior")]
    pub ior: f32,
}

/// A microfacet roughness: isotropic, or one value per tangent axis.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(untagged)]
pub enum RoughnessSpec {
    /// The same roughness in every direction, in [0, 1].
    Isotropic(f32),
    /// Roughness along the first and the second tangent, each in [0, 1].
    Anisotropic([f32; 2]),
    /// The name of a colour texture (a greyscale `Bitmap`, `Marble` or `Noise`): the mean of
    /// its three channels at a hit, clamped to [0, 1], is the isotropic roughness there (looked
    /// up with the same footprint filtering as the colour).
    Texture(String),
}

impl Default for RoughnessSpec {
    fn default() -> Self {
        RoughnessSpec::Isotropic(0.0)
    }
}

impl RoughnessSpec {
    /// The constant roughness per tangent axis (`None` for a texture).
    #[must_use]
    pub fn pair(&self) -> Option<[f32; 2]> {
        match self {
            RoughnessSpec::Isotropic(r) => Some([*r, *r]),
            RoughnessSpec::Anisotropic(p) => Some(*p),
            RoughnessSpec::Texture(_) => None,
        }
    }

    /// The name of the roughness texture, if the roughness is one.
    #[must_use]
    pub fn texture(&self) -> Option<&str> {
        match self {
            RoughnessSpec::Texture(t) => Some(t),
            RoughnessSpec::Isotropic(_) | RoughnessSpec::Anisotropic(_) => None,
        }
    }
}

/// The conductor presets' names (the order and spelling of `shading::conductor::ConductorPreset`,
/// which a compile test checks).
pub const CONDUCTOR_PRESETS: [&str; 5] = ["chrome", "aluminium", "gold", "copper", "silver"];

/// A metal's Fresnel reflectance: a named preset or an artist's colours.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(untagged)]
pub enum ConductorSpec {
    /// A measured metal: `"chrome"`, `"aluminium"`, `"gold"`, `"copper"` or `"silver"`.
    Preset(String),
    /// The F82-tint model's colours.
    Tint(ConductorTint),
}

/// The artist's F82-tint conductor (Hoffman 2023): reflectance at normal incidence and its
/// tint near grazing incidence.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ConductorTint {
    /// Reflectance at normal incidence, linear RGB in [0, 1].
    pub f0: Rgb,
    /// Multiplier of Schlick's reflectance at about 82°, linear RGB in [0, 1] (white:
    /// Schlick's approximation).
    #[serde(default = "white")]
    pub tint: Rgb,
}

/// Absorption inside a dielectric, as given: one of two equivalent forms (one σ is stored).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(untagged)]
pub enum AbsorptionSpec {
    /// The absorption coefficient σ per metre, per channel, ≥ 0.
    Coefficient(Rgb),
    /// The colour light keeps after travelling `depth` metres: σ = −ln(color)/depth.
    ColorAtDepth(ColorAtDepth),
}

/// The colour reached at a depth (an easier way to give absorption).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ColorAtDepth {
    /// The fraction of light left per channel, in (0, 1].
    pub color: Rgb,
    /// The depth at which it is left, in metres (> 0).
    pub depth: f32,
}

fn default_color() -> ColorSpec {
    ColorSpec::Rgb([0.8; 3])
}

/// A material colour: a constant or a texture.
#[derive(Debug, Clone, PartialEq, Serialize, JsonSchema)]
#[serde(untagged)]
pub enum ColorSpec {
    /// A constant linear RGB triple, `(r, g, b)`.
    Rgb(Rgb),
    /// The name of a colour texture in `textures`.
    Texture(String),
}

impl<'de> Deserialize<'de> for ColorSpec {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Visit;
        impl<'de> serde::de::Visitor<'de> for Visit {
            type Value = ColorSpec;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str("an RGB triple `(r, g, b)` or the name of a texture")
            }
            fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<ColorSpec, E> {
                Ok(ColorSpec::Texture(v.to_string()))
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(
                self,
                seq: A,
            ) -> Result<ColorSpec, A::Error> {
                ExactFloats::<3>.visit_seq(seq).map(ColorSpec::Rgb)
            }
        }
        d.deserialize_any(Visit)
    }
}

/// A named texture: a colour source, a bump (height) source, or both.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub enum TextureSpec {
    /// A colour image (PNG, JPEG or EXR), repeated over the surface's uv square and mipmapped.
    Bitmap {
        /// Image file, relative to the scene file.
        file: String,
        /// How many times the image repeats over the uv square, per axis (> 0).
        #[serde(default = "unit_size")]
        #[serde(deserialize_with = "exact_floats::<_, 2>")]
        tile: [f32; 2],
        /// Decode the stored values from sRGB to linear. Default: by format, true for 8/16-bit
        /// images (PNG, JPEG: photographs and paintings), false for float images (EXR holds
        /// linear values).
        #[serde(default)]
        srgb: Option<bool>,
    },
    /// A grey image used as a height field for bump mapping: height = `depth` × grey value.
    HeightMap {
        /// Image file, relative to the scene file (colour images are reduced to luma).
        file: String,
        /// Height of white, in world units (may be negative to engrave).
        depth: f32,
        /// Repeats over the uv square, per axis (> 0).
        #[serde(default = "unit_size")]
        #[serde(deserialize_with = "exact_floats::<_, 2>")]
        tile: [f32; 2],
    },
    /// Marble: turbulence-distorted veins between a base and a vein colour; also a bump source
    /// when `depth` is not 0.
    Marble {
        /// Colour of the stone between veins, linear RGB in [0, 1].
        #[serde(deserialize_with = "exact_floats::<_, 3>")]
        base: Rgb,
        /// Colour at the centre of a vein, linear RGB in [0, 1].
        #[serde(deserialize_with = "exact_floats::<_, 3>")]
        vein: Rgb,
        /// Spatial frequency (veins run across x): `f` or per axis `(x, y, z)`, per world unit
        /// (or per uv unit with `mapping: Uv`).
        #[serde(default = "unit_scale")]
        frequency: ScaleSpec,
        /// Octaves of turbulence (0 gives straight veins).
        #[serde(default = "default_octaves")]
        octaves: u32,
        /// How far the turbulence bends the veins (radians of phase).
        #[serde(default = "default_turbulence")]
        turbulence: f32,
        /// Seed of the noise.
        #[serde(default)]
        seed: u64,
        /// Height of a vein's centre when used as `bump`, in world units.
        #[serde(default)]
        depth: f32,
        /// Where the pattern is evaluated.
        #[serde(default)]
        mapping: Mapping,
    },
    /// Fractal gradient noise (fBm, or turbulence) blended between two colours; also a bump
    /// source when `depth` is not 0.
    Noise {
        /// Colour where the noise is lowest, linear RGB in [0, 1].
        #[serde(default)]
        #[serde(deserialize_with = "exact_floats::<_, 3>")]
        low: Rgb,
        /// Colour where the noise is highest, linear RGB in [0, 1].
        #[serde(default = "white")]
        #[serde(deserialize_with = "exact_floats::<_, 3>")]
        high: Rgb,
        /// Frequency of the first octave, per world unit (or per uv unit with `mapping: Uv`).
        #[serde(default = "one")]
        frequency: f32,
        /// Octaves summed, each at twice the frequency and half the amplitude of the last.
        #[serde(default = "default_octaves")]
        octaves: u32,
        /// Sum absolute values (turbulence: billowy, creased) instead of signed ones (fBm).
        #[serde(default)]
        turbulence: bool,
        /// Seed of the noise.
        #[serde(default)]
        seed: u64,
        /// Bump height of the noise's full range when used as `bump`, in world units.
        #[serde(default)]
        depth: f32,
        /// Where the pattern is evaluated.
        #[serde(default)]
        mapping: Mapping,
    },
    /// A tangent-space normal map (RGB: x right, y up the image, z out of the surface; 8-bit 128
    /// is 0), for a material's `normal_map`.
    NormalMap {
        /// Image file, relative to the scene file (read as linear data, never sRGB).
        file: String,
        /// Repeats over the uv square, per axis (> 0).
        #[serde(default = "unit_size")]
        #[serde(deserialize_with = "exact_floats::<_, 2>")]
        tile: [f32; 2],
        /// Scale of the normals' tangential part (finite, ≥ 0; 0 flattens the map, 1 is as
        /// drawn).
        #[serde(default = "one")]
        strength: f32,
        /// The green channel points down the image (maps made for DirectX).
        #[serde(default)]
        flip_y: bool,
    },
    /// Circular water ripples over the uv square, a bump source: the height is
    /// `amplitude · (1 + decay·r) · e^(−decay·r) · cos(frequency · r)` summed over the centres.
    Ripple {
        /// Centres in uv coordinates.
        #[serde(deserialize_with = "vec_of_pairs")]
        centers: Vec<[f32; 2]>,
        /// Angular frequency, radians per uv unit (wavelength 2π/frequency).
        frequency: f32,
        /// Peak height at a centre, in world units.
        amplitude: f32,
        /// Radial decay per uv unit (0: none).
        #[serde(default)]
        decay: f32,
    },
}

/// Where a procedural (noise or marble) texture is evaluated.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
pub enum Mapping {
    /// At the world-space position: a solid texture, continuous across faces and edges.
    #[default]
    Solid,
    /// At `(u, v, 0)` of the surface's texture coordinates: follows the surface like an image.
    Uv,
}

impl TextureSpec {
    /// The texture's kind as written in the file.
    #[must_use]
    pub fn kind(&self) -> &'static str {
        match self {
            TextureSpec::Bitmap { .. } => "Bitmap",
            TextureSpec::HeightMap { .. } => "HeightMap",
            TextureSpec::Marble { .. } => "Marble",
            TextureSpec::Noise { .. } => "Noise",
            TextureSpec::Ripple { .. } => "Ripple",
            TextureSpec::NormalMap { .. } => "NormalMap",
        }
    }

    /// True if the texture can give a material its colour.
    #[must_use]
    pub fn gives_color(&self) -> bool {
        matches!(
            self,
            TextureSpec::Bitmap { .. } | TextureSpec::Marble { .. } | TextureSpec::Noise { .. }
        )
    }

    /// True if the texture can perturb normals (is a height source).
    #[must_use]
    pub fn gives_bump(&self) -> bool {
        !matches!(
            self,
            TextureSpec::Bitmap { .. } | TextureSpec::NormalMap { .. }
        )
    }

    /// True if the texture is a tangent-space normal map.
    #[must_use]
    pub fn gives_normals(&self) -> bool {
        matches!(self, TextureSpec::NormalMap { .. })
    }
}

fn unit_scale() -> ScaleSpec {
    ScaleSpec::Uniform(1.0)
}
fn default_octaves() -> u32 {
    5
}
fn default_turbulence() -> f32 {
    4.0
}
fn white() -> Rgb {
    [1.0; 3]
}

/// Deserialises a list of `(u, v)` pairs, each with exactly two numbers.
fn vec_of_pairs<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Vec<[f32; 2]>, D::Error> {
    struct Pair([f32; 2]);
    impl<'de> Deserialize<'de> for Pair {
        fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
            exact_floats::<_, 2>(d).map(Pair)
        }
    }
    let v: Vec<Pair> = Deserialize::deserialize(d)?;
    Ok(v.into_iter().map(|p| p.0).collect())
}
fn default_shininess() -> f32 {
    32.0
}
fn default_ior() -> f32 {
    1.5
}
