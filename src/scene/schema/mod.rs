//! The scene file format: serde types shared by RON and TOML, and the JSON Schema derived from them.
//!
//! Every struct rejects unknown fields. Enums are externally tagged: `Pinhole(eye: …)` in RON,
//! `{ Pinhole = { eye = … } }` or `[camera.Pinhole]` in TOML. Vectors are `(x, y, z)` in RON and
//! `[x, y, z]` in TOML; colours are linear RGB.

use std::collections::BTreeMap;

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

pub use crate::settings::{IntegratorKind, SamplerKind, TextureFilter, Tonemap};

mod light;
mod material;
mod node;
mod values;

pub use light::*;
pub use material::{
    AbsorptionSpec, CONDUCTOR_PRESETS, CoatSpec, ColorAtDepth, ColorSpec, ConductorSpec,
    ConductorTint, Mapping, MaterialSpec, RoughnessSpec, TextureSpec,
};
pub use node::{NodeSpec, TransformStep};
pub use values::ScaleSpec;
use values::{exact_floats, unique_keys};

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
    /// Linear scale applied to radiance before writing 8-bit images. Unset: chosen per image
    /// from the rendered film (Reinhard et al. 2002's key: the log-average luminance mapped to
    /// 0.18, lowered so at most 1 % of the pixels clip; the render summary prints it). EXR
    /// output stays linear either way.
    #[serde(default)]
    pub exposure: Option<f32>,
    /// Tone-mapping curve for 8-bit images, applied after `exposure`: `Linear` (clip) or `Aces`
    /// (a filmic curve). Unset: `Aces` when the exposure is automatic (unset too), `Linear`
    /// when the scene states an exposure (today's images, byte for byte). EXR output stays
    /// linear.
    #[serde(default)]
    pub tonemap: Option<Tonemap>,
    /// Light-transport algorithm. Unset: the default estimator, chosen per scene — `PathPpm`
    /// (path tracing with a progressive caustic photon map, per-pass photon counts and gather
    /// sizes chosen from the image size; see docs/progressive.md) when some object's material
    /// has a mirror or glass part that could focus light onto a diffuse surface, else `Path`
    /// (no photon pass at all). Naming an integrator here or with `--integrator` picks it.
    #[serde(default)]
    pub integrator: Option<IntegratorKind>,
    /// Where the integrators' random numbers come from.
    pub sampler: SamplerKind,
    /// Path tracing: most diffuse or glossy bounces a path may make (unset: up to `max_depth`);
    /// 0 keeps only direct light and mirror/glass chains (Whitted's light transport).
    #[serde(default)]
    pub diffuse_depth: Option<u32>,
    /// How image textures are filtered.
    pub texture_filter: TextureFilter,
    /// Render pass after pass until the estimated relative mean squared error of the image
    /// (from each pixel's sample variance; docs/convergence.md) is at most this, e.g. 0.01;
    /// `--time` and `--spp` still stop it first (without `--spp` the scene's
    /// `samples_per_pixel` gives way to the target). Unset: render every sample.
    #[serde(default)]
    pub target_error: Option<f32>,
    /// Adaptive sampling (docs/convergence.md): after 8 uniform samples per pixel, each pixel
    /// takes more only while its own estimated relative error is above `target_error` (unset:
    /// 0.002); `samples_per_pixel` caps every pixel. Not with farm shards or `.part` outputs.
    #[serde(default)]
    pub adaptive: bool,
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
            exposure: None,
            tonemap: None,
            integrator: None,
            sampler: SamplerKind::Sobol,
            diffuse_depth: None,
            texture_filter: TextureFilter::Anisotropic,
            target_error: None,
            adaptive: false,
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
    /// Most bounces a photon path makes before it is dropped: a safety net (Russian roulette
    /// ends paths without bias); the summary says what a cut path would have stored.
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
            max_bounces: 256,
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
    /// A thin-lens camera (depth of field): the pinhole's view through a lens disc of radius
    /// `aperture_radius` — or `f / (2 N)` for the f-number `N = f_number`, with the focal
    /// length `f = (sensor_height / 2) / tan(fov_y / 2)` — focused on the plane
    /// `focus_distance` along the view direction. Give exactly one of `aperture_radius` and
    /// `f_number`.
    ThinLens {
        /// Eye position (the lens centre).
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
        /// Lens radius in scene units (≥ 0; 0 is a pinhole).
        #[serde(default)]
        aperture_radius: Option<f32>,
        /// f-number N (> 0): the aperture radius is `f / (2N)`.
        #[serde(default)]
        f_number: Option<f32>,
        /// Sensor height in scene units for `f_number` (default 0.024: a full-frame sensor in
        /// metres).
        #[serde(default = "default_sensor_height")]
        sensor_height: f32,
        /// Distance from the lens to the plane in focus, along the view direction (> 0).
        focus_distance: f32,
    },
}

impl CameraSpec {
    /// The view every camera model shares: `(eye, look_at, up, fov_y)`.
    #[must_use]
    pub fn view(&self) -> (Vec3Spec, Vec3Spec, Vec3Spec, f32) {
        match *self {
            CameraSpec::Pinhole {
                eye,
                look_at,
                up,
                fov_y,
            }
            | CameraSpec::ThinLens {
                eye,
                look_at,
                up,
                fov_y,
                ..
            } => (eye, look_at, up, fov_y),
        }
    }

    /// The lens as `(aperture radius, focus distance)` in scene units: `None` for a pinhole.
    /// An f-number becomes the radius `f / (2N)` with `f = (sensor_height/2) / tan(fov_y/2)`.
    #[must_use]
    pub fn lens(&self) -> Option<(f32, f32)> {
        match *self {
            CameraSpec::Pinhole { .. } => None,
            CameraSpec::ThinLens {
                fov_y,
                aperture_radius,
                f_number,
                sensor_height,
                focus_distance,
                ..
            } => {
                let radius = match (aperture_radius, f_number) {
                    (Some(r), _) => r,
                    (None, Some(n)) => {
                        let f = 0.5 * sensor_height / (0.5 * fov_y.to_radians()).tan();
                        f / (2.0 * n)
                    }
                    (None, None) => 0.0,
                };
                Some((radius, focus_distance))
            }
        }
    }
}

fn default_sensor_height() -> f32 {
    0.024
}

fn default_up() -> Vec3Spec {
    [0.0, 1.0, 0.0]
}

/// The JSON Schema of the scene format, pretty-printed (what `caustic schema` prints).
#[must_use]
pub fn json_schema() -> String {
    let schema = schemars::schema_for!(SceneFile);
    let mut s = serde_json::to_string_pretty(&schema).unwrap_or_default();
    s.push('\n');
    s
}
