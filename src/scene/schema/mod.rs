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
mod medium;
mod node;
mod settings;
mod values;

pub use light::*;
pub use material::{
    AbsorptionSpec, CONDUCTOR_PRESETS, CoatSpec, ColorAtDepth, ColorSpec, ConductorSpec,
    ConductorTint, Mapping, MaterialSpec, RoughnessSpec, TextureSpec,
};
pub use medium::MediumSpec;
pub use node::{NodeSpec, TransformStep};
pub use settings::{PhotonFilter, PhotonSettings, RenderSettings};
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
    /// Named participating media (docs/media.md), referenced by name from a material's
    /// `medium` (inside its closed surfaces) and from the scene's `medium`.
    #[serde(default, deserialize_with = "unique_keys")]
    pub media: BTreeMap<String, MediumSpec>,
    /// The medium around every object, where the camera and the lights are (fog, steam):
    /// the name of one of `media`. Unset: clear air.
    #[serde(default)]
    pub medium: Option<String>,
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
