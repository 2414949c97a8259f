//! The scene file format: serde types shared by RON and TOML, and the JSON Schema derived from them.
//!
//! Every struct rejects unknown fields. Enums are externally tagged: `Pinhole(eye: …)` in RON,
//! `{ Pinhole = { eye = … } }` or `[camera.Pinhole]` in TOML. Vectors are `(x, y, z)` in RON and
//! `[x, y, z]` in TOML; colours are linear RGB.

use std::collections::BTreeMap;

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

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
    /// Named materials, referenced by name from nodes.
    #[serde(deserialize_with = "unique_keys")]
    pub materials: BTreeMap<String, MaterialSpec>,
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
        }
    }
}

/// Which light-transport algorithm renders the image.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
pub enum IntegratorKind {
    /// Recursive (Whitted) ray tracing: direct light with shadow rays, mirror and refraction.
    Whitted,
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
    /// Albedo of the diffuse part and tint of the mirror and of transmitted light, each in [0, 1].
    #[serde(default = "default_color")]
    #[serde(deserialize_with = "exact_floats::<_, 3>")]
    pub color: Rgb,
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
}

fn default_color() -> Rgb {
    [0.8; 3]
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
    },
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
    /// A triangle mesh from a Wavefront OBJ file (path relative to the scene file).
    Mesh {
        /// Optional name.
        #[serde(default)]
        name: Option<String>,
        /// Transform steps.
        #[serde(default)]
        transform: Vec<TransformStep>,
        /// Material name.
        material: String,
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
    struct Exact<const N: usize>;
    impl<'de, const N: usize> serde::de::Visitor<'de> for Exact<N> {
        type Value = [f32; N];
        fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
            write!(f, "{N} numbers")
        }
        fn visit_seq<A: serde::de::SeqAccess<'de>>(
            self,
            mut seq: A,
        ) -> Result<Self::Value, A::Error> {
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
    d.deserialize_tuple(N, Exact::<N>)
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

    /// The material a leaf node references (None for groups).
    #[must_use]
    pub fn material(&self) -> Option<&str> {
        match self {
            NodeSpec::Group { .. } => None,
            NodeSpec::Sphere { material, .. }
            | NodeSpec::Cube { material, .. }
            | NodeSpec::Quad { material, .. }
            | NodeSpec::Mesh { material, .. } => Some(material),
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
