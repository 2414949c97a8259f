//! The scene file format: serde types shared by RON and TOML, and the JSON Schema derived from them.
//!
//! Every struct rejects unknown fields. Enums are externally tagged: `Pinhole(eye: …)` in RON,
//! `{ Pinhole = { eye = … } }` or `[camera.Pinhole]` in TOML. Vectors are `(x, y, z)` in RON and
//! `[x, y, z]` in TOML; colours are linear RGB.

use std::collections::BTreeMap;

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

pub use crate::settings::{IntegratorKind, SamplerKind, TextureFilter};

/// A point or direction `(x, y, z)` in the scene's units.
pub type Vec3Spec = [f32; 3];
/// A linear RGB triple.
pub type Rgb = [f32; 3];

/// A whole scene file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, rename = "Scene")]
pub struct SceneFile {
    /// Image size, sampling and recursion limits.
    #[serde(default)]
    pub render: RenderSettings,
    /// The viewpoint.
    pub camera: CameraSpec,
    /// Named textures, referenced by name from materials (`color` and `bump`).
    #[serde(default, deserialize_with = "unique_keys")]
    pub textures: BTreeMap<String, TextureSpec>,
    /// Named materials, referenced by name from nodes.
    #[serde(deserialize_with = "unique_keys")]
    pub materials: BTreeMap<String, MaterialSpec>,
    /// Photon-map settings (the `photon` integrator): counts, gathering and filtering.
    #[serde(default)]
    pub photons: PhotonSettings,
    /// Light sources. A scene without lights renders black except for what is emissive.
    #[serde(default)]
    pub lights: Vec<LightSpec>,
    /// The scene graph: a list of nodes forming an implicit root group.
    pub nodes: Vec<NodeSpec>,
}

/// Image and sampling settings (the report's Settings.hpp constants that concern rendering).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct RenderSettings {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Camera samples per pixel, stratified over the pixel area.
    pub samples_per_pixel: u32,
    /// Maximum number of specular bounces (reflection/refraction recursion depth).
    pub max_depth: u32,
    /// A path whose weight (max RGB component) falls below this is not continued.
    pub min_contribution: f32,
    /// Shadow-ray samples per sphere light at each shaded point (soft shadows).
    pub light_samples: u32,
    /// Seed of every random stream; same seed and scene give the same image.
    pub seed: u64,
    /// Radiance seen by rays that leave the scene.
    #[serde(deserialize_with = "exact_floats::<_, 3>")]
    pub background: Rgb,
    /// Linear scale applied to radiance before writing 8-bit images.
    pub exposure: f32,
    /// Light-transport algorithm.
    pub integrator: IntegratorKind,
    /// Where the integrators' random numbers come from.
    pub sampler: SamplerKind,
    /// Path tracing: most diffuse or glossy bounces a path may make (unset: up to `max_depth`);
    /// 0 keeps only direct light and mirror/glass chains (Whitted's light transport).
    #[serde(default)]
    pub diffuse_depth: Option<u32>,
    /// How image textures are filtered.
    pub texture_filter: TextureFilter,
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            width: 640,
            height: 480,
            samples_per_pixel: 4,
            max_depth: 8,
            min_contribution: 0.001,
            light_samples: 1,
            seed: 0,
            background: [0.0; 3],
            exposure: 1.0,
            integrator: IntegratorKind::Whitted,
            sampler: SamplerKind::Sobol,
            diffuse_depth: None,
            texture_filter: TextureFilter::Anisotropic,
        }
    }
}

/// Photon-map settings: the report's Settings.hpp photon constants, made explicit. Counts are
/// photons *emitted*; each light gets a share in proportion to its power (equal-flux photons).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct PhotonSettings {
    /// Photons emitted for the global map (diffuse interreflection); 0 builds no global map.
    pub global: u32,
    /// Caustic photons, aimed at objects that reflect or transmit (Jensen's projection maps)
    /// and stored where they land on a diffuse surface after specular bounces only; 0 builds no
    /// caustic map. Shared among the lights in proportion to power, except lights that set
    /// their own `caustic_photons`.
    pub caustic: u32,
    /// Nearest photons per global-map estimate (k).
    pub gather: u32,
    /// Nearest photons per caustic-map estimate (k).
    pub caustic_gather: u32,
    /// Largest radius (scene units) of an estimate's disc; unset: chosen from the scene's size
    /// and the photon count (reported in the summary). For the progressive integrators (`Ppm`,
    /// `PathPpm`): the radius of the first pass.
    #[serde(default)]
    pub max_radius: Option<f32>,
    /// Progressive integrators: the radius shrink of Knaus & Zwicker's schedule,
    /// `r²ᵢ₊₁ = r²ᵢ (i + α)/(i + 1)`, in (0, 1); smaller shrinks faster (less bias, more noise).
    pub alpha: f32,
    /// The kernel of caustic estimates.
    pub caustic_filter: PhotonFilter,
    /// Diffuse bounces a photon must have made before the global map stores it (the report's
    /// MIN_PHOTON_BOUNCE). At least 1: direct light always comes from shadow rays; more than 1
    /// drops the first bounces of indirect light.
    pub min_bounces: u32,
    /// Final-gather rays per camera hit on a diffuse surface (indirect light sampled from the
    /// BSDF and read from the maps where those rays land); 0 reads the global map directly.
    pub final_gather: u32,
    /// Most bounces a photon path makes before it is dropped.
    pub max_bounces: u32,
}

impl Default for PhotonSettings {
    fn default() -> Self {
        Self {
            global: 200_000,
            caustic: 200_000,
            gather: 100,
            caustic_gather: 60,
            max_radius: None,
            alpha: 2.0 / 3.0,
            caustic_filter: PhotonFilter::Cone { k: 1.1 },
            min_bounces: 1,
            final_gather: 16,
            max_bounces: 16,
        }
    }
}

/// The kernel that weighs photons in a density estimate by their distance `d` from the query
/// point, within the disc of radius `r`; each is normalised so a uniform photon density reads
/// its true value (the report's CAUSTIC_SHARPNESS made explicit and energy-preserving).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub enum PhotonFilter {
    /// Every photon counts equally.
    Box,
    /// Jensen's cone filter: weight `1 − d/(k·r)`, normalised by `1 − 2/(3k)`; `k ≥ 1`, smaller
    /// is sharper (1 reaches 0 at the rim).
    Cone {
        /// Cone slope constant (≥ 1).
        k: f32,
    },
}

/// Camera models.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub enum CameraSpec {
    /// A pinhole camera.
    Pinhole {
        /// Eye position.
        #[serde(deserialize_with = "exact_floats::<_, 3>")]
        eye: Vec3Spec,
        /// Point the camera looks at.
        #[serde(deserialize_with = "exact_floats::<_, 3>")]
        look_at: Vec3Spec,
        /// Approximate up direction.
        #[serde(default = "default_up")]
        #[serde(deserialize_with = "exact_floats::<_, 3>")]
        up: Vec3Spec,
        /// Vertical field of view in degrees, in (0, 180).
        fov_y: f32,
    },
}

fn default_up() -> Vec3Spec {
    [0.0, 1.0, 0.0]
}

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
        !matches!(self, TextureSpec::Bitmap { .. })
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

/// Light sources; `power` is the emitted radiant flux in watts per RGB channel.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub enum LightSpec {
    /// An isotropic point light with inverse-square falloff.
    Point {
        /// Position.
        #[serde(deserialize_with = "exact_floats::<_, 3>")]
        position: Vec3Spec,
        /// Total emitted flux (W).
        #[serde(deserialize_with = "exact_floats::<_, 3>")]
        power: Rgb,
        /// Caustic photons this light emits, instead of its power share of
        /// `photons.caustic` (0: none).
        #[serde(default)]
        caustic_photons: Option<u32>,
    },
    /// A spherical area light emitting uniformly from its surface; gives soft shadows.
    Sphere {
        /// Centre.
        #[serde(deserialize_with = "exact_floats::<_, 3>")]
        center: Vec3Spec,
        /// Radius (> 0).
        radius: f32,
        /// Total emitted flux (W).
        #[serde(deserialize_with = "exact_floats::<_, 3>")]
        power: Rgb,
        /// Caustic photons this light emits, instead of its power share of
        /// `photons.caustic` (0: none).
        #[serde(default)]
        caustic_photons: Option<u32>,
    },
}

impl LightSpec {
    /// The light's own caustic photon budget, if it sets one.
    #[must_use]
    pub fn caustic_photons(&self) -> Option<u32> {
        match *self {
            LightSpec::Point {
                caustic_photons, ..
            }
            | LightSpec::Sphere {
                caustic_photons, ..
            } => caustic_photons,
        }
    }
}

/// A node of the scene graph. Transforms apply in list order (the first one first), and a
/// group's transform applies after its children's.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub enum NodeSpec {
    /// A transformed collection of nodes.
    Group {
        /// Optional name, shown in diagnostics and `debug-pixel`.
        #[serde(default)]
        name: Option<String>,
        /// Transform steps.
        #[serde(default)]
        transform: Vec<TransformStep>,
        /// Child nodes.
        #[serde(default)]
        children: Vec<NodeSpec>,
    },
    /// A sphere (an ellipsoid under non-uniform scale).
    Sphere {
        /// Optional name.
        #[serde(default)]
        name: Option<String>,
        /// Transform steps.
        #[serde(default)]
        transform: Vec<TransformStep>,
        /// Material name.
        material: String,
        /// Centre in object space.
        #[serde(default)]
        #[serde(deserialize_with = "exact_floats::<_, 3>")]
        center: Vec3Spec,
        /// Radius in object space (> 0).
        #[serde(default = "one")]
        radius: f32,
    },
    /// An axis-aligned cube centred on the origin in object space.
    Cube {
        /// Optional name.
        #[serde(default)]
        name: Option<String>,
        /// Transform steps.
        #[serde(default)]
        transform: Vec<TransformStep>,
        /// Material name.
        material: String,
        /// Edge length in object space (> 0).
        #[serde(default = "one")]
        size: f32,
    },
    /// A bounded rectangle in the object's xy plane, centred on the origin, facing +z.
    Quad {
        /// Optional name.
        #[serde(default)]
        name: Option<String>,
        /// Transform steps.
        #[serde(default)]
        transform: Vec<TransformStep>,
        /// Material name.
        material: String,
        /// Width (x) and height (y) in object space (> 0).
        #[serde(default = "unit_size")]
        #[serde(deserialize_with = "exact_floats::<_, 2>")]
        size: [f32; 2],
    },
    /// A triangle mesh from a Wavefront OBJ file (path relative to the scene file), with one
    /// material or one per OBJ group.
    Mesh {
        /// Optional name.
        #[serde(default)]
        name: Option<String>,
        /// Transform steps.
        #[serde(default)]
        transform: Vec<TransformStep>,
        /// Material name: of every face, or with `materials` of the faces it does not map.
        /// Required unless `materials` maps every face of the file.
        #[serde(default)]
        material: Option<String>,
        /// Materials by the file's names: each key is a group (`g` or `o`) or a `usemtl` name
        /// of the OBJ file, each value a material name. A face takes the material of its
        /// `usemtl` name if that is a key, else of its group, else `material`. A key the file
        /// does not use is an error (a typo would otherwise go unnoticed).
        #[serde(
            default,
            skip_serializing_if = "BTreeMap::is_empty",
            deserialize_with = "unique_keys"
        )]
        materials: BTreeMap<String, String>,
        /// OBJ file, relative to the scene file.
        file: String,
        /// Interpolate the file's vertex normals when it has them.
        #[serde(default = "yes")]
        smooth: bool,
    },
}

fn one() -> f32 {
    1.0
}
fn unit_size() -> [f32; 2] {
    [1.0, 1.0]
}
fn yes() -> bool {
    true
}

/// One step of a node's transform.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub enum TransformStep {
    /// Translation by (x, y, z).
    Translate(f32, f32, f32),
    /// Rotation about the x axis, in degrees (right-handed).
    RotateX(f32),
    /// Rotation about the y axis, in degrees.
    RotateY(f32),
    /// Rotation about the z axis, in degrees.
    RotateZ(f32),
    /// Uniform scale `Scale(s)` or per-axis scale `Scale((x, y, z))`.
    Scale(ScaleSpec),
}

/// A uniform or per-axis scale factor.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(
    untagged,
    expecting = "a scale factor `s` or a per-axis triple `(x, y, z)`"
)]
pub enum ScaleSpec {
    /// The same factor on every axis.
    Uniform(f32),
    /// One factor per axis.
    PerAxis(Vec3Spec),
}

impl ScaleSpec {
    /// The factor per axis.
    #[must_use]
    pub fn factors(&self) -> Vec3Spec {
        match *self {
            ScaleSpec::Uniform(s) => [s; 3],
            ScaleSpec::PerAxis(v) => v,
        }
    }
}

/// Deserialises a map, rejecting a key given twice (RON maps would otherwise keep the last one).
fn unique_keys<'de, D: serde::Deserializer<'de>, V: Deserialize<'de>>(
    d: D,
) -> Result<BTreeMap<String, V>, D::Error> {
    struct Unique<V>(std::marker::PhantomData<V>);
    impl<'de, V: Deserialize<'de>> serde::de::Visitor<'de> for Unique<V> {
        type Value = BTreeMap<String, V>;
        fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
            f.write_str("a map of names to definitions")
        }
        fn visit_map<A: serde::de::MapAccess<'de>>(
            self,
            mut map: A,
        ) -> Result<Self::Value, A::Error> {
            let mut out = BTreeMap::new();
            while let Some(key) = map.next_key::<String>()? {
                if out.contains_key(&key) {
                    return Err(serde::de::Error::custom(format!(
                        "`{key}` is defined twice"
                    )));
                }
                let value = map.next_value()?;
                out.insert(key, value);
            }
            Ok(out)
        }
    }
    d.deserialize_map(Unique(std::marker::PhantomData))
}

/// Deserialises exactly `N` numbers, rejecting longer lists (TOML arrays would otherwise be
/// silently truncated to their first `N` items).
fn exact_floats<'de, D: serde::Deserializer<'de>, const N: usize>(
    d: D,
) -> Result<[f32; N], D::Error> {
    d.deserialize_tuple(N, ExactFloats::<N>)
}

/// Visitor for exactly `N` numbers.
struct ExactFloats<const N: usize>;

impl<'de, const N: usize> serde::de::Visitor<'de> for ExactFloats<N> {
    type Value = [f32; N];
    fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{N} numbers")
    }
    fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
        let mut out = [0.0f32; N];
        for (i, slot) in out.iter_mut().enumerate() {
            *slot = seq
                .next_element()?
                .ok_or_else(|| serde::de::Error::invalid_length(i, &self))?;
        }
        let mut extra = 0;
        while seq.next_element::<serde::de::IgnoredAny>()?.is_some() {
            extra += 1;
        }
        if extra > 0 {
            return Err(serde::de::Error::invalid_length(N + extra, &self));
        }
        Ok(out)
    }
}

impl NodeSpec {
    /// The node's kind as written in the file.
    #[must_use]
    pub fn kind(&self) -> &'static str {
        match self {
            NodeSpec::Group { .. } => "Group",
            NodeSpec::Sphere { .. } => "Sphere",
            NodeSpec::Cube { .. } => "Cube",
            NodeSpec::Quad { .. } => "Quad",
            NodeSpec::Mesh { .. } => "Mesh",
        }
    }

    /// The node's transform steps.
    #[must_use]
    pub fn transform(&self) -> &[TransformStep] {
        match self {
            NodeSpec::Group { transform, .. }
            | NodeSpec::Sphere { transform, .. }
            | NodeSpec::Cube { transform, .. }
            | NodeSpec::Quad { transform, .. }
            | NodeSpec::Mesh { transform, .. } => transform,
        }
    }

    /// The node's optional name.
    #[must_use]
    pub fn name(&self) -> Option<&str> {
        match self {
            NodeSpec::Group { name, .. }
            | NodeSpec::Sphere { name, .. }
            | NodeSpec::Cube { name, .. }
            | NodeSpec::Quad { name, .. }
            | NodeSpec::Mesh { name, .. } => name.as_deref(),
        }
    }

    /// The material a leaf node references (None for groups, and for a mesh that gives only
    /// `materials`).
    #[must_use]
    pub fn material(&self) -> Option<&str> {
        match self {
            NodeSpec::Group { .. } => None,
            NodeSpec::Sphere { material, .. }
            | NodeSpec::Cube { material, .. }
            | NodeSpec::Quad { material, .. } => Some(material),
            NodeSpec::Mesh { material, .. } => material.as_deref(),
        }
    }

    /// The materials a mesh maps its OBJ groups and `usemtl` names to (None for other nodes).
    #[must_use]
    pub fn group_materials(&self) -> Option<&BTreeMap<String, String>> {
        match self {
            NodeSpec::Mesh { materials, .. } => Some(materials),
            _ => None,
        }
    }
}

/// The JSON Schema of the scene format, pretty-printed (what `caustic schema` prints).
#[must_use]
pub fn json_schema() -> String {
    let schema = schemars::schema_for!(SceneFile);
    let mut s = serde_json::to_string_pretty(&schema).unwrap_or_default();
    s.push('\n');
    s
}
