//! Scene-graph nodes and their transforms.

use std::collections::BTreeMap;

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::values::{ScaleSpec, exact_floats, one, unique_keys, unit_size, yes};
use super::{EmissionSpec, Vec3Spec};

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
        /// Material name (required unless the node has `emission`).
        #[serde(default)]
        material: Option<String>,
        /// Light the shape emits, making it an area light without a material.
        #[serde(default)]
        emission: Option<EmissionSpec>,
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
        /// Material name (required unless the node has `emission`).
        #[serde(default)]
        material: Option<String>,
        /// Light the shape emits, making it an area light without a material.
        #[serde(default)]
        emission: Option<EmissionSpec>,
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
        /// Material name (required unless the node has `emission`).
        #[serde(default)]
        material: Option<String>,
        /// Light the shape emits, making it an area light without a material.
        #[serde(default)]
        emission: Option<EmissionSpec>,
        /// Width (x) and height (y) in object space (> 0).
        #[serde(default = "unit_size")]
        #[serde(deserialize_with = "exact_floats::<_, 2>")]
        size: [f32; 2],
    },
    /// A disc in the object's xy plane, centred on the origin, facing +z (analytic, like the
    /// sphere; Mitsuba 3's `disk`).
    Disc {
        /// Optional name.
        #[serde(default)]
        name: Option<String>,
        /// Transform steps.
        #[serde(default)]
        transform: Vec<TransformStep>,
        /// Material name (required unless the node has `emission`).
        #[serde(default)]
        material: Option<String>,
        /// Light the shape emits, making it an area light without a material.
        #[serde(default)]
        emission: Option<EmissionSpec>,
        /// Radius in object space (> 0).
        #[serde(default = "one")]
        radius: f32,
    },
    /// A cylinder about the object's z axis, centred on the origin (z from −height/2 to
    /// height/2), analytic, open at both ends like Mitsuba 3's `cylinder` unless `caps` closes
    /// them with two discs. Its normal points outwards.
    Cylinder {
        /// Optional name.
        #[serde(default)]
        name: Option<String>,
        /// Transform steps.
        #[serde(default)]
        transform: Vec<TransformStep>,
        /// Material name (required unless the node has `emission`).
        #[serde(default)]
        material: Option<String>,
        /// Light the side emits, making it an area light without a material (no caps then).
        #[serde(default)]
        emission: Option<EmissionSpec>,
        /// Radius in object space (> 0).
        #[serde(default = "one")]
        radius: f32,
        /// Height along z in object space (> 0).
        #[serde(default = "one")]
        height: f32,
        /// Close both ends with discs of the same material (default: open, as Mitsuba's).
        #[serde(default)]
        caps: bool,
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
        /// Light every face emits, making the mesh an area light without a material.
        #[serde(default)]
        emission: Option<EmissionSpec>,
        /// Take the materials of the OBJ file's `usemtl` names from its `.mtl` library
        /// (`mtllib`): `Kd`, `Ks`/`Ns`, `d`, `Ni` and `map_Kd` (docs/import.md). A name that
        /// `materials` maps keeps the scene's material.
        #[serde(default, skip_serializing_if = "std::ops::Not::not")]
        mtl: bool,
    },
    /// A glTF 2.0 scene (`.gltf` with its buffers and images, or `.glb`) imported as a
    /// subtree: every triangle primitive of its default scene under the file's node
    /// transforms, its materials mapped onto caustic's (emissive ones as area lights), and its
    /// `KHR_lights_punctual` lights; docs/import.md says what maps to what.
    Gltf {
        /// Optional name.
        #[serde(default)]
        name: Option<String>,
        /// Transform steps, applied after the file's own node transforms.
        #[serde(default)]
        transform: Vec<TransformStep>,
        /// The `.gltf` or `.glb` file, relative to the scene file.
        file: String,
        /// Scene materials replacing the file's, by the file's material name
        /// (`{"Glass": "my_glass"}`). A key the file does not use is an error.
        #[serde(
            default,
            skip_serializing_if = "BTreeMap::is_empty",
            deserialize_with = "unique_keys"
        )]
        materials: BTreeMap<String, String>,
        /// Render from the file's perspective camera of this name (the camera's or its node's)
        /// instead of the scene's `camera`.
        #[serde(default)]
        camera: Option<String>,
        /// Import the file's `KHR_lights_punctual` lights (point, spot, directional).
        #[serde(default = "yes")]
        lights: bool,
    },
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

impl NodeSpec {
    /// The node's kind as written in the file.
    #[must_use]
    pub fn kind(&self) -> &'static str {
        match self {
            NodeSpec::Group { .. } => "Group",
            NodeSpec::Sphere { .. } => "Sphere",
            NodeSpec::Cube { .. } => "Cube",
            NodeSpec::Quad { .. } => "Quad",
            NodeSpec::Disc { .. } => "Disc",
            NodeSpec::Cylinder { .. } => "Cylinder",
            NodeSpec::Mesh { .. } => "Mesh",
            NodeSpec::Gltf { .. } => "Gltf",
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
            | NodeSpec::Disc { transform, .. }
            | NodeSpec::Cylinder { transform, .. }
            | NodeSpec::Mesh { transform, .. }
            | NodeSpec::Gltf { transform, .. } => transform,
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
            | NodeSpec::Disc { name, .. }
            | NodeSpec::Cylinder { name, .. }
            | NodeSpec::Mesh { name, .. }
            | NodeSpec::Gltf { name, .. } => name.as_deref(),
        }
    }

    /// The material a leaf node references (None for groups, emissive shapes, a mesh that
    /// gives only `materials`, and glTF imports).
    #[must_use]
    pub fn material(&self) -> Option<&str> {
        match self {
            NodeSpec::Group { .. } | NodeSpec::Gltf { .. } => None,
            NodeSpec::Sphere { material, .. }
            | NodeSpec::Cube { material, .. }
            | NodeSpec::Quad { material, .. }
            | NodeSpec::Disc { material, .. }
            | NodeSpec::Cylinder { material, .. }
            | NodeSpec::Mesh { material, .. } => material.as_deref(),
        }
    }

    /// The light a leaf node emits (None for groups, non-emissive shapes and glTF imports,
    /// whose emissive materials make their own).
    #[must_use]
    pub fn emission(&self) -> Option<&EmissionSpec> {
        match self {
            NodeSpec::Group { .. } | NodeSpec::Gltf { .. } => None,
            NodeSpec::Sphere { emission, .. }
            | NodeSpec::Cube { emission, .. }
            | NodeSpec::Quad { emission, .. }
            | NodeSpec::Disc { emission, .. }
            | NodeSpec::Cylinder { emission, .. }
            | NodeSpec::Mesh { emission, .. } => emission.as_ref(),
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
