//! glTF 2.0 scenes (Khronos, "glTF 2.0 Specification", 2021) read through the `gltf` crate and
//! mapped onto the scene format: every triangle primitive becomes an [`ObjMesh`], the node
//! hierarchy a tree of `Group`/`Mesh` nodes with transform steps, materials
//! [`MaterialSpec`]s (emissive ones `emission`), punctual lights [`LightSpec`]s and cameras
//! [`CameraSpec`]s. The flattener then compiles them as it compiles a hand-written scene, so an
//! import and its RON twin give the same compiled structures. docs/import.md is the mapping.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use glam::{DAffine3, DMat4, DQuat, DVec3, EulerRot, Vec2, Vec3};
use gltf::json::validation::Validate;

use super::mesh::{Corner, FaceNames, ObjMesh};
use super::mesh_file::MAX_MESH_FILE_BYTES;
use super::mtl::default_material;
use crate::scene::schema::{
    AbsorptionSpec, CameraSpec, CoatSpec, ColorAtDepth, ColorSpec, ConductorSpec, ConductorTint,
    EmissionSpec, LightSpec, MaterialSpec, NodeSpec, RoughnessSpec, ScaleSpec, TextureSpec,
    TransformStep,
};

/// Luminous efficacy of the photometric units glTF's lights are given in (lm/W at 555 nm):
/// radiant intensity (W/sr) = luminous intensity (cd) / 683, irradiance (W/m²) = illuminance
/// (lux) / 683.
pub const LUMENS_PER_WATT: f64 = 683.0;

/// The extensions the import maps (all others in `extensionsUsed` are warned about, and those
/// in `extensionsRequired` refused).
pub const SUPPORTED_EXTENSIONS: [&str; 7] = [
    "KHR_lights_punctual",
    "KHR_materials_emissive_strength",
    "KHR_materials_ior",
    "KHR_materials_transmission",
    "KHR_materials_volume",
    "KHR_materials_clearcoat",
    "KHR_texture_transform",
];

/// Why a glTF file could not be imported: the file, the JSON pointer of the part at fault
/// (`/meshes/3/primitives/0/attributes/NORMAL`), and what is wrong and valid.
#[derive(Debug, thiserror::Error)]
#[error("`{}`{}: {problem}", path.display(), pointer.as_deref().map(|p| format!(" {p}")).unwrap_or_default())]
pub struct GltfError {
    /// The glTF file.
    pub path: PathBuf,
    /// JSON pointer into the file, when the fault is in one part.
    pub pointer: Option<String>,
    /// What is wrong.
    pub problem: String,
}

/// A glTF file's content in the scene format's terms, in the `Gltf` node's space except for
/// lights and cameras, which are in world space (the node's world transform applied).
#[derive(Debug, Default)]
pub struct GltfImport {
    /// Meshes by the key the synthetic `Mesh` nodes name as `file` (`<file>#/meshes/i/primitives/j`).
    pub meshes: Vec<(PathBuf, ObjMesh)>,
    /// The file's scene as nodes (groups with transform steps, meshes).
    pub nodes: Vec<NodeSpec>,
    /// Materials made from the file's, by their synthetic names.
    pub materials: BTreeMap<String, MaterialSpec>,
    /// Textures those materials use, by synthetic name.
    pub textures: BTreeMap<String, TextureSpec>,
    /// The file's punctual lights, in world space.
    pub lights: Vec<LightSpec>,
    /// Perspective cameras, in world space, with the names they answer to (the camera's and
    /// its node's).
    pub cameras: Vec<(Vec<String>, CameraSpec)>,
    /// The file's material names (each once).
    pub material_names: BTreeSet<String>,
    /// Warnings: unknown optional extensions, primitives skipped, parts ignored.
    pub warnings: Vec<String>,
    /// What maps only approximately: one sentence per material.
    pub notes: Vec<String>,
    /// Images embedded in the file, written out for the texture loader; deleted when dropped.
    pub images: Vec<tempfile::TempPath>,
}

/// Reads a glTF file's bytes (`.gltf` JSON or `.glb`), its buffers and images, and maps it.
/// `xf` is the `Gltf` node's world transform (for lights and cameras); `overrides` maps the
/// file's material names to scene materials, which are used instead of the file's.
///
/// # Errors
/// A [`GltfError`] with the file and JSON pointer.
pub fn import_gltf(
    bytes: &[u8],
    path: &Path,
    xf: DAffine3,
    overrides: &BTreeMap<String, String>,
) -> Result<GltfImport, GltfError> {
    let fail = |pointer: Option<String>, problem: String| GltfError {
        path: path.to_path_buf(),
        pointer,
        problem,
    };
    let gltf = gltf::Gltf::from_slice_without_validation(bytes)
        .map_err(|e| fail(None, format!("not a valid glTF 2.0 file: {e}")))?;
    let root = gltf.document.as_json();
    let required: Vec<&str> = root
        .extensions_required
        .iter()
        .map(String::as_str)
        .filter(|e| !SUPPORTED_EXTENSIONS.contains(e))
        .collect();
    if !required.is_empty() {
        return Err(fail(
            Some("/extensionsRequired".into()),
            format!(
                "the file requires {} which caustic does not implement (it maps {}); re-export without {}",
                list(&required),
                list(&SUPPORTED_EXTENSIONS),
                if required.len() == 1 { "it" } else { "them" }
            ),
        ));
    }
    let mut problems = Vec::new();
    root.validate(root, gltf::json::Path::new, &mut |p, e| {
        problems.push((pointer_of(&p().to_string()), e.to_string()));
    });
    if let Some((pointer, problem)) = problems.into_iter().next() {
        return Err(fail(Some(pointer), format!("invalid glTF: {problem}")));
    }
    let mut out = GltfImport::default();
    let unknown: Vec<&str> = root
        .extensions_used
        .iter()
        .map(String::as_str)
        .filter(|e| !SUPPORTED_EXTENSIONS.contains(e))
        .collect();
    if !unknown.is_empty() {
        out.warnings.push(format!(
            "uses the optional extension{} {}, which caustic ignores",
            if unknown.len() == 1 { "" } else { "s" },
            list(&unknown)
        ));
    }
    let dir = path.parent().unwrap_or(Path::new(""));
    let buffers = read_buffers(&gltf, dir, path)?;
    check_views(&gltf.document, &buffers, path)?;
    let key = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
    let doc = &gltf.document;
    // Meshes: one ObjMesh per triangle primitive, in file order.
    let mut prim_keys: Vec<Vec<Option<PrimKey>>> = Vec::new();
    let mut default_material_of_file = None;
    for mesh in doc.meshes() {
        let mut keys = Vec::new();
        for prim in mesh.primitives() {
            let at = format!("/meshes/{}/primitives/{}", mesh.index(), prim.index());
            if prim.mode() != gltf::mesh::Mode::Triangles {
                out.warnings.push(format!(
                    "{at}: a primitive of mode {:?} is not triangles; it is left out",
                    prim.mode()
                ));
                keys.push(None);
                continue;
            }
            let m = read_primitive(&prim, &buffers, &at).map_err(|(p, e)| fail(Some(p), e))?;
            let k = PathBuf::from(format!("{}#{at}", key.display()));
            out.meshes.push((k.clone(), m));
            if prim.material().index().is_none() {
                default_material_of_file = Some(prim.material());
            }
            keys.push(Some((k, prim.material().index())));
        }
        prim_keys.push(keys);
    }
    // Materials: the file's names (made unique), and the scene's where `overrides` says.
    let file_label = path.file_name().map_or_else(
        || path.display().to_string(),
        |f| f.to_string_lossy().into_owned(),
    );
    let mut names: Vec<String> = Vec::new();
    for mat in doc.materials() {
        let i = mat.index().unwrap_or(0);
        let base = mat
            .name()
            .map_or_else(|| format!("material {i}"), str::to_string);
        let name = if names.contains(&base) {
            format!("{base} ({i})")
        } else {
            base
        };
        out.material_names.insert(name.clone());
        names.push(name);
    }
    let used: BTreeSet<Option<usize>> = prim_keys
        .iter()
        .flatten()
        .flatten()
        .map(|(_, m)| *m)
        .collect();
    // Per glTF material index (None: the default material): the scene material name or the
    // emission that the primitives using it get.
    let mut looks: BTreeMap<Option<usize>, Look> = BTreeMap::new();
    for m in used {
        let (mat, label) = match m {
            Some(i) => match doc.materials().nth(i) {
                Some(mat) => (mat, names[i].clone()),
                None => continue,
            },
            // glTF's default material: white, metallic 1, roughness 1.
            None => match &default_material_of_file {
                Some(mat) => (mat.clone(), "(default material)".to_string()),
                None => continue,
            },
        };
        if let Some(scene_name) = overrides.get(&label) {
            looks.insert(m, Look::Material(scene_name.clone()));
            continue;
        }
        let at = m.map_or_else(
            || "the default material".to_string(),
            |i| format!("/materials/{i}"),
        );
        let synthetic = format!("{file_label}#{label}");
        let mapped = map_material(&mat, &synthetic, &buffers, dir, &mut out)
            .map_err(|e| fail(Some(at.clone()), e))?;
        if !mapped.notes.is_empty() {
            out.notes.push(format!(
                "material `{label}` ({at}) maps approximately: {}",
                mapped.notes.join("; ")
            ));
        }
        let look = match mapped.emission {
            Some(e) => Look::Emission(e),
            None => {
                out.materials.insert(synthetic.clone(), mapped.spec);
                Look::Material(synthetic)
            }
        };
        looks.insert(m, look);
    }
    // Nodes of the default scene (or the first; or every root node if there is no scene).
    let roots: Vec<gltf::Node> = match doc.default_scene().or_else(|| doc.scenes().next()) {
        Some(s) => s.nodes().collect(),
        None => {
            let children: BTreeSet<usize> = doc
                .nodes()
                .flat_map(|n| n.children().map(|c| c.index()).collect::<Vec<_>>())
                .collect();
            doc.nodes()
                .filter(|n| !children.contains(&n.index()))
                .collect()
        }
    };
    let ctx = NodeContext {
        prim_keys: &prim_keys,
        looks: &looks,
    };
    for node in roots {
        if let Some(n) = convert_node(&node, &ctx, DMat4::from(xf), 0, &mut out) {
            out.nodes.push(n);
        }
    }
    Ok(out)
}

/// A triangle primitive of a glTF mesh: its key in the mesh cache and its material index
/// (`None`: glTF's default material).
type PrimKey = (PathBuf, Option<usize>);

/// What the primitives of one glTF material get.
#[derive(Debug, Clone)]
enum Look {
    /// A material name (the scene's, or a synthetic one in [`GltfImport::materials`]).
    Material(String),
    /// An emitter (caustic's emitters have no material).
    Emission(EmissionSpec),
}

struct NodeContext<'a> {
    prim_keys: &'a [Vec<Option<PrimKey>>],
    looks: &'a BTreeMap<Option<usize>, Look>,
}

/// The deepest node hierarchy followed (a cycle would otherwise never end; the validator
/// does not look for cycles).
const MAX_DEPTH: usize = 64;

/// A glTF node as a `Group` (its transform as steps) holding its primitives and children;
/// lights and cameras go to `out` in world space (`parent` is the world transform above it).
fn convert_node(
    node: &gltf::Node,
    ctx: &NodeContext,
    parent: DMat4,
    depth: usize,
    out: &mut GltfImport,
) -> Option<NodeSpec> {
    let at = format!("/nodes/{}", node.index());
    if depth > MAX_DEPTH {
        out.warnings.push(format!(
            "{at}: the node hierarchy is deeper than {MAX_DEPTH} levels (a cycle?); the rest is left out"
        ));
        return None;
    }
    let local = DMat4::from_cols_array_2d(&node.transform().matrix().map(|c| c.map(f64::from)));
    let world = parent * local;
    let (t, r, s) = node.transform().decomposed();
    if s.contains(&0.0) || !s.iter().chain(&t).chain(&r).all(|v| v.is_finite()) {
        out.warnings.push(format!(
            "{at}: a zero or non-finite scale or transform; the node and its children are left out"
        ));
        return None;
    }
    let steps = transform_steps(t, r, s);
    if let Some(light) = node.light() {
        light_of(&light, &world, &at, out);
    }
    if let Some(cam) = node.camera() {
        camera_of(&cam, node.name(), &world, &at, out);
    }
    let mut children = Vec::new();
    if let Some(mesh) = node.mesh() {
        for (key, material) in ctx.prim_keys[mesh.index()].iter().flatten() {
            let (material, emission) = match ctx.looks.get(material) {
                Some(Look::Material(m)) => (Some(m.clone()), None),
                Some(Look::Emission(e)) => (None, Some(e.clone())),
                None => continue,
            };
            children.push(NodeSpec::Mesh {
                name: mesh.name().map(str::to_string),
                transform: Vec::new(),
                material,
                materials: BTreeMap::new(),
                file: key.to_string_lossy().into_owned(),
                smooth: true,
                emission,
                mtl: false,
            });
        }
    }
    for child in node.children() {
        if let Some(c) = convert_node(&child, ctx, world, depth + 1, out) {
            children.push(c);
        }
    }
    Some(NodeSpec::Group {
        name: node.name().map(str::to_string),
        transform: steps,
        children,
    })
}

/// A glTF TRS as the scene format's steps (first applied first): scale, the rotation as
/// rotations about x, then y, then z (its intrinsic ZYX Euler angles: R = Rz·Ry·Rx), then the
/// translation.
#[must_use]
pub fn transform_steps(t: [f32; 3], r: [f32; 4], s: [f32; 3]) -> Vec<TransformStep> {
    let q = DQuat::from_xyzw(r[0].into(), r[1].into(), r[2].into(), r[3].into()).normalize();
    let (z, y, x) = q.to_euler(EulerRot::ZYX);
    let mut steps = Vec::new();
    if s != [1.0; 3] {
        steps.push(TransformStep::Scale(ScaleSpec::PerAxis(s)));
    }
    for (angle, make) in [
        (x, TransformStep::RotateX as fn(f32) -> TransformStep),
        (y, TransformStep::RotateY),
        (z, TransformStep::RotateZ),
    ] {
        if angle != 0.0 {
            steps.push(make(angle.to_degrees() as f32));
        }
    }
    if t != [0.0; 3] {
        steps.push(TransformStep::Translate(t[0], t[1], t[2]));
    }
    steps
}

/// A `KHR_lights_punctual` light as a scene light, photometric units divided by
/// [`LUMENS_PER_WATT`]: a point light's power is 4π × its radiant intensity.
fn light_of(
    light: &gltf::khr_lights_punctual::Light,
    world: &DMat4,
    at: &str,
    out: &mut GltfImport,
) {
    let colour = DVec3::from(light.color().map(f64::from));
    let radiometric = colour * f64::from(light.intensity()) / LUMENS_PER_WATT;
    let rgb = |v: DVec3| v.as_vec3().to_array();
    if radiometric.max_element() <= 0.0 || !radiometric.is_finite() {
        out.warnings.push(format!(
            "{at}: light `{}` has no positive intensity; it is left out",
            light.name().unwrap_or("")
        ));
        return;
    }
    if light.range().is_some() {
        out.warnings.push(format!(
            "{at}: the light's `range` is ignored (caustic's lights fall off with the inverse square everywhere)"
        ));
    }
    let position = world.transform_point3(DVec3::ZERO).as_vec3().to_array();
    let forward = world.transform_vector3(DVec3::NEG_Z).normalize_or_zero();
    match light.kind() {
        gltf::khr_lights_punctual::Kind::Point => out.lights.push(LightSpec::Point {
            position,
            power: rgb(radiometric * 4.0 * std::f64::consts::PI),
            caustic_photons: None,
        }),
        gltf::khr_lights_punctual::Kind::Spot {
            inner_cone_angle,
            outer_cone_angle,
        } => {
            let outer = outer_cone_angle.to_degrees().clamp(1e-3, 180.0);
            out.lights.push(LightSpec::Spot {
                position,
                direction: forward.as_vec3().to_array(),
                intensity: rgb(radiometric),
                inner_angle: inner_cone_angle.to_degrees().clamp(0.0, outer),
                outer_angle: outer,
                caustic_photons: None,
            });
        }
        gltf::khr_lights_punctual::Kind::Directional => out.lights.push(LightSpec::Distant {
            direction: (-forward).as_vec3().to_array(),
            irradiance: rgb(radiometric),
            angular_radius: 0.0,
            caustic_photons: None,
        }),
    }
}

/// A perspective camera as a pinhole at the node's origin looking down its −z, up its +y.
fn camera_of(
    cam: &gltf::Camera,
    node_name: Option<&str>,
    world: &DMat4,
    at: &str,
    out: &mut GltfImport,
) {
    let names: Vec<String> = [cam.name(), node_name]
        .into_iter()
        .flatten()
        .map(str::to_string)
        .collect();
    let gltf::camera::Projection::Perspective(p) = cam.projection() else {
        out.warnings.push(format!(
            "{at}: camera {} is orthographic, which caustic does not model; it cannot be chosen",
            list(&names.iter().map(String::as_str).collect::<Vec<_>>())
        ));
        return;
    };
    let eye = world.transform_point3(DVec3::ZERO);
    let forward = world.transform_vector3(DVec3::NEG_Z).normalize_or_zero();
    let up = world.transform_vector3(DVec3::Y).normalize_or_zero();
    out.cameras.push((
        names,
        CameraSpec::Pinhole {
            eye: eye.as_vec3().to_array(),
            look_at: (eye + forward).as_vec3().to_array(),
            up: up.as_vec3().to_array(),
            fov_y: p.yfov().to_degrees(),
        },
    ));
}

/// A material mapped: the scene material, or the emission the surface gets instead, and what
/// maps only approximately.
struct Mapped {
    spec: MaterialSpec,
    emission: Option<EmissionSpec>,
    notes: Vec<String>,
}

/// A glTF material as a scene material (docs/import.md's table).
fn map_material(
    mat: &gltf::Material,
    synthetic: &str,
    buffers: &[Vec<u8>],
    dir: &Path,
    out: &mut GltfImport,
) -> Result<Mapped, String> {
    let mut spec = default_material();
    let mut notes: Vec<String> = Vec::new();
    let pbr = mat.pbr_metallic_roughness();
    let [r, g, b, _] = pbr.base_color_factor();
    let base = [r, g, b].map(|c| c.clamp(0.0, 1.0));
    let metallic = pbr.metallic_factor().clamp(0.0, 1.0);
    let roughness = pbr.roughness_factor().clamp(0.0, 1.0);
    spec.color = ColorSpec::Rgb(base);
    if let Some(info) = pbr.base_color_texture() {
        let name = format!("{synthetic} baseColorTexture");
        let file = image_file(&info.texture(), buffers, dir, out)?;
        let tile = texture_tile(info.texture_transform(), &mut notes);
        if info.tex_coord() != 0 {
            notes.push("the base colour texture reads TEXCOORD_0 (caustic has one uv set)".into());
        }
        out.textures.insert(
            name.clone(),
            TextureSpec::Bitmap {
                file,
                tile,
                srgb: Some(true),
            },
        );
        if base != [1.0; 3] {
            notes.push(
                "the base colour factor is not multiplied into the base colour texture".into(),
            );
        }
        if metallic > 0.0 {
            notes.push("a metal's reflectance is the base colour factor, not the texture".into());
        }
        spec.color = ColorSpec::Texture(name);
    }
    if pbr.metallic_roughness_texture().is_some() {
        notes.push("the metallic-roughness texture is not read (its factors are used)".into());
    }
    if let Some(n) = mat.normal_texture() {
        let name = format!("{synthetic} normalTexture");
        let file = image_file(&n.texture(), buffers, dir, out)?;
        out.textures.insert(
            name.clone(),
            TextureSpec::NormalMap {
                file,
                tile: [1.0, 1.0],
                strength: n.scale().max(0.0),
                flip_y: false,
            },
        );
        spec.normal_map = Some(name);
    }
    if mat.occlusion_texture().is_some() {
        notes.push("the occlusion texture is ignored (caustic traces the occlusion)".into());
    }
    if !matches!(mat.alpha_mode(), gltf::material::AlphaMode::Opaque) {
        notes.push("alpha (MASK/BLEND) is ignored: the surface is opaque".into());
    }
    let transmission = mat
        .transmission()
        .map_or(0.0, |t| t.transmission_factor().clamp(0.0, 1.0));
    if mat
        .transmission()
        .is_some_and(|t| t.transmission_texture().is_some())
    {
        notes.push("the transmission texture is not read".into());
    }
    spec.ior = mat
        .ior()
        .filter(|i| i.is_finite() && *i >= 1.0)
        .unwrap_or(1.5);
    let clearcoat = mat
        .extension_value("KHR_materials_clearcoat")
        .and_then(|v| v.get("clearcoatFactor"))
        .and_then(serde_json::Value::as_f64)
        .unwrap_or(0.0);
    let dielectric = 1.0 - metallic;
    if metallic > 0.0 {
        spec.conductor = Some(ConductorSpec::Tint(ConductorTint {
            f0: base,
            tint: [1.0; 3],
        }));
        spec.reflect = Some(metallic);
    }
    if transmission > 0.0 {
        spec.transmit = Some(dielectric * transmission);
        if let Some(v) = mat.volume() {
            let d = v.attenuation_distance();
            let c = v.attenuation_color().map(|c| c.clamp(1e-6, 1.0));
            if d.is_finite() && d > 0.0 && c != [1.0; 3] {
                spec.absorption = Some(AbsorptionSpec::ColorAtDepth(ColorAtDepth {
                    color: c,
                    depth: d,
                }));
            }
        }
    }
    let diffuse = dielectric * (1.0 - transmission);
    if metallic > 0.0 || transmission > 0.0 {
        spec.diffuse = Some(diffuse);
        if roughness > 0.0 {
            spec.roughness = RoughnessSpec::Isotropic(roughness);
        }
        if diffuse > 0.0 {
            notes.push("the diffuse part has no dielectric specular layer".into());
        }
        if clearcoat > 0.0 {
            notes.push(
                "the clearcoat is dropped (caustic's coat goes over a diffuse base only)".into(),
            );
        }
    } else if clearcoat > 0.0 || roughness == 0.0 {
        // A smooth coat of ior 1.5 is glTF's dielectric F0 = 0.04 over the diffuse base.
        let ior = if clearcoat > 0.0 { 1.5 } else { spec.ior };
        spec.coat = Some(CoatSpec { ior });
        if clearcoat > 0.0 && clearcoat < 1.0 {
            notes.push(format!("the clearcoat factor {clearcoat} is taken as 1"));
        }
        if clearcoat > 0.0 && roughness > 0.0 {
            notes.push("the base's specular roughness is dropped under the clearcoat".into());
        }
    } else {
        notes.push(format!(
            "a rough non-metal (roughness {roughness}) is diffuse: its dielectric specular layer (F0 = 0.04) is left out"
        ));
    }
    let strength = mat.emissive_strength().unwrap_or(1.0);
    let e = mat.emissive_factor().map(|c| (c * strength).max(0.0));
    let emission = (e.iter().any(|c| *c > 0.0) && e.iter().all(|c| c.is_finite())).then(|| {
        notes.push(
            "an emitter: the light it reflects is dropped (caustic's emitters absorb)".into(),
        );
        if mat.emissive_texture().is_some() {
            notes.push("the emissive texture is not read (its factor is the radiance)".into());
        }
        EmissionSpec {
            radiance: e,
            two_sided: mat.double_sided(),
        }
    });
    Ok(Mapped {
        spec,
        emission,
        notes,
    })
}

/// The tile of a `KHR_texture_transform` (its scale); offset and rotation are noted as ignored.
fn texture_tile(t: Option<gltf::texture::TextureTransform>, notes: &mut Vec<String>) -> [f32; 2] {
    let Some(t) = t else {
        return [1.0, 1.0];
    };
    if t.offset() != [0.0, 0.0] || t.rotation() != 0.0 {
        notes.push("a texture transform's offset and rotation are ignored".into());
    }
    let s = t.scale();
    if s.iter().all(|v| v.is_finite() && *v > 0.0) {
        s
    } else {
        [1.0, 1.0]
    }
}

/// The path of a texture's image for the loader: a file beside the glTF, or an embedded image
/// written to a temporary file that lives as long as the import.
fn image_file(
    texture: &gltf::Texture,
    buffers: &[Vec<u8>],
    dir: &Path,
    out: &mut GltfImport,
) -> Result<String, String> {
    let image = texture.source();
    let at = format!("/images/{}", image.index());
    let (bytes, mime) = match image.source() {
        gltf::image::Source::Uri { uri, mime_type } => {
            if let Some(data) = uri.strip_prefix("data:") {
                (
                    decode_data_uri(data).map_err(|e| format!("{at}: {e}"))?,
                    mime_type.map(str::to_string),
                )
            } else {
                return Ok(dir.join(percent_decode(uri)).to_string_lossy().into_owned());
            }
        }
        gltf::image::Source::View { view, mime_type } => {
            let data = &buffers[view.buffer().index()];
            let bytes = data
                .get(view.offset()..view.offset() + view.length())
                .ok_or_else(|| format!("{at}: its buffer view lies outside its buffer"))?;
            (bytes.to_vec(), Some(mime_type.to_string()))
        }
    };
    let suffix = match mime.as_deref() {
        Some("image/jpeg") => ".jpg",
        _ => ".png",
    };
    let mut file = tempfile::Builder::new()
        .prefix("caustic-gltf-")
        .suffix(suffix)
        .tempfile()
        .map_err(|e| format!("{at}: cannot write the embedded image out: {e}"))?;
    std::io::Write::write_all(&mut file, &bytes)
        .map_err(|e| format!("{at}: cannot write the embedded image out: {e}"))?;
    let path = file.into_temp_path();
    let name = path.to_string_lossy().into_owned();
    out.images.push(path);
    Ok(name)
}

/// Every buffer's bytes: the GLB's binary chunk, a `data:` URI, or a file beside the glTF
/// (a regular file within [`MAX_MESH_FILE_BYTES`]), each at least its declared length.
fn read_buffers(gltf: &gltf::Gltf, dir: &Path, path: &Path) -> Result<Vec<Vec<u8>>, GltfError> {
    let mut out = Vec::new();
    for buffer in gltf.document.buffers() {
        let at = format!("/buffers/{}", buffer.index());
        let fail = |problem: String| GltfError {
            path: path.to_path_buf(),
            pointer: Some(at.clone()),
            problem,
        };
        let data = match buffer.source() {
            gltf::buffer::Source::Bin => gltf.blob.clone().ok_or_else(|| {
                fail("refers to the GLB binary chunk, but the file has none".into())
            })?,
            gltf::buffer::Source::Uri(uri) => {
                if let Some(data) = uri.strip_prefix("data:") {
                    decode_data_uri(data).map_err(fail)?
                } else {
                    let file = dir.join(percent_decode(uri));
                    read_bounded(&file).map_err(|e| fail(format!("`{}`: {e}", file.display())))?
                }
            }
        };
        if data.len() < buffer.length() {
            return Err(fail(format!(
                "holds {} bytes, but its byteLength is {}",
                data.len(),
                buffer.length()
            )));
        }
        out.push(data);
    }
    Ok(out)
}

/// A regular file's bytes, at most [`MAX_MESH_FILE_BYTES`].
fn read_bounded(file: &Path) -> Result<Vec<u8>, String> {
    let meta = std::fs::metadata(file).map_err(|e| e.to_string())?;
    if !meta.is_file() {
        return Err("not a regular file".into());
    }
    if meta.len() > MAX_MESH_FILE_BYTES {
        return Err(format!(
            "larger than the {MAX_MESH_FILE_BYTES} bytes caustic reads"
        ));
    }
    std::fs::read(file).map_err(|e| e.to_string())
}

/// Checks that every buffer view lies in its buffer and every accessor in its view, so the
/// crate's readers never index past the data.
fn check_views(doc: &gltf::Document, buffers: &[Vec<u8>], path: &Path) -> Result<(), GltfError> {
    let fail = |pointer: String, problem: String| GltfError {
        path: path.to_path_buf(),
        pointer: Some(pointer),
        problem,
    };
    for v in doc.views() {
        let len = buffers[v.buffer().index()].len();
        if v.offset()
            .checked_add(v.length())
            .is_none_or(|end| end > len)
        {
            return Err(fail(
                format!("/bufferViews/{}", v.index()),
                format!(
                    "bytes {}..{} lie outside buffer {} ({len} bytes)",
                    v.offset(),
                    v.offset().saturating_add(v.length()),
                    v.buffer().index()
                ),
            ));
        }
    }
    for a in doc.accessors() {
        let at = format!("/accessors/{}", a.index());
        if let Some(v) = a.view() {
            let stride = v.stride().unwrap_or(a.size());
            let need = (a.count() > 0).then(|| {
                a.offset()
                    .saturating_add(stride.saturating_mul(a.count() - 1))
                    .saturating_add(a.size())
            });
            if need.is_some_and(|n| n > v.length()) || stride < a.size() && v.stride().is_some() {
                return Err(fail(
                    at,
                    format!(
                        "{} elements of {} bytes (stride {stride}) from offset {} do not fit in buffer view {} ({} bytes)",
                        a.count(),
                        a.size(),
                        a.offset(),
                        v.index(),
                        v.length()
                    ),
                ));
            }
        }
        if let Some(s) = a.sparse() {
            let (iv, vv) = (s.indices().view(), s.values().view());
            let isize = match s.indices().index_type() {
                gltf::accessor::sparse::IndexType::U8 => 1,
                gltf::accessor::sparse::IndexType::U16 => 2,
                gltf::accessor::sparse::IndexType::U32 => 4,
            };
            let fits = |off: usize, size: usize, len: usize| {
                off.saturating_add(size.saturating_mul(s.count())) <= len
            };
            if !fits(s.indices().offset(), isize, iv.length())
                || !fits(s.values().offset(), a.size(), vv.length())
            {
                return Err(fail(
                    format!("{at}/sparse"),
                    "the sparse indices or values do not fit in their buffer views".into(),
                ));
            }
        }
    }
    Ok(())
}

/// One triangle primitive as a mesh: positions, normals, uv0, indices checked.
fn read_primitive(
    prim: &gltf::Primitive,
    buffers: &[Vec<u8>],
    at: &str,
) -> Result<ObjMesh, (String, String)> {
    let reader = prim.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
    let mut mesh = ObjMesh::default();
    let positions = reader.read_positions().ok_or_else(|| {
        (
            format!("{at}/attributes"),
            "a triangle primitive needs a POSITION attribute".to_string(),
        )
    })?;
    mesh.positions = positions.map(Vec3::from).collect();
    if let Some(i) = mesh.positions.iter().position(|p| !p.is_finite()) {
        return Err((
            format!("{at}/attributes/POSITION"),
            format!("vertex {i} has a non-finite coordinate"),
        ));
    }
    let n = mesh.positions.len();
    if let Some(normals) = reader.read_normals() {
        mesh.normals = normals.map(Vec3::from).collect();
        if mesh.normals.len() != n {
            return Err((
                format!("{at}/attributes/NORMAL"),
                format!("{} normals for {n} positions", mesh.normals.len()),
            ));
        }
    }
    if let Some(uvs) = reader.read_tex_coords(0) {
        // glTF's uv origin is the image's top-left, as the renderer's.
        mesh.uvs = uvs.into_f32().map(Vec2::from).collect();
        if mesh.uvs.len() != n {
            return Err((
                format!("{at}/attributes/TEXCOORD_0"),
                format!("{} texture coordinates for {n} positions", mesh.uvs.len()),
            ));
        }
    }
    let indices: Vec<u32> = match reader.read_indices() {
        Some(i) => i.into_u32().collect(),
        None => (0..n as u32).collect(),
    };
    if !indices.len().is_multiple_of(3) {
        return Err((
            format!("{at}/indices"),
            format!("{} indices do not make whole triangles", indices.len()),
        ));
    }
    if let Some(bad) = indices.iter().find(|&&i| i as usize >= n) {
        return Err((
            format!("{at}/indices"),
            format!("index {bad} is past the {n} vertices"),
        ));
    }
    let (has_n, has_t) = (!mesh.normals.is_empty(), !mesh.uvs.is_empty());
    mesh.triangles = indices
        .chunks_exact(3)
        .map(|t| {
            [t[0], t[1], t[2]].map(|i| Corner {
                p: i,
                n: has_n.then_some(i),
                t: has_t.then_some(i),
            })
        })
        .collect();
    mesh.triangle_names = vec![FaceNames::default(); mesh.triangles.len()];
    Ok(mesh)
}

/// The bytes of a `data:` URI's payload (after `data:`): base64 (`;base64,`) only.
fn decode_data_uri(data: &str) -> Result<Vec<u8>, String> {
    let Some((_, payload)) = data.split_once(";base64,") else {
        return Err("a data URI that is not base64".into());
    };
    base64_decode(payload).ok_or_else(|| "a data URI with invalid base64".into())
}

/// Standard base64 (RFC 4648 §4), padding optional; `None` on any other character.
fn base64_decode(s: &str) -> Option<Vec<u8>> {
    let value = |c: u8| -> Option<u32> {
        Some(match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' => 62,
            b'/' => 63,
            _ => return None,
        } as u32)
    };
    let bytes: Vec<u8> = s.bytes().filter(|b| !b.is_ascii_whitespace()).collect();
    let trimmed = bytes
        .strip_suffix(b"==")
        .or_else(|| bytes.strip_suffix(b"="))
        .unwrap_or(&bytes);
    let mut out = Vec::with_capacity(trimmed.len() * 3 / 4);
    for chunk in trimmed.chunks(4) {
        let mut acc = 0u32;
        for (i, c) in chunk.iter().enumerate() {
            acc |= value(*c)? << (18 - 6 * i);
        }
        let n = match chunk.len() {
            4 => 3,
            3 => 2,
            2 => 1,
            _ => return None,
        };
        out.extend(&acc.to_be_bytes()[1..1 + n]);
    }
    Some(out)
}

/// A relative URI's `%XX` escapes decoded (other characters kept).
fn percent_decode(uri: &str) -> String {
    let b = uri.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%'
            && let Some(v) = b
                .get(i + 1..i + 3)
                .and_then(|h| std::str::from_utf8(h).ok())
                .and_then(|h| u8::from_str_radix(h, 16).ok())
        {
            out.push(v);
            i += 3;
            continue;
        }
        out.push(b[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// A JSON pointer from the crate's path (`meshes[3].primitives[0].attributes["NORMAL"]`).
fn pointer_of(path: &str) -> String {
    let mut out = String::new();
    for part in path.split(['.', '[']) {
        let part = part.trim_end_matches(']').trim_matches('"');
        if !part.is_empty() {
            out.push('/');
            out.push_str(part);
        }
    }
    if out.is_empty() { "/".into() } else { out }
}

/// `` `a`, `b` and `c` ``.
fn list(items: &[&str]) -> String {
    let quoted: Vec<String> = items.iter().map(|s| format!("`{s}`")).collect();
    match quoted.as_slice() {
        [] => String::new(),
        [one] => one.clone(),
        [rest @ .., last] => format!("{} and {last}", rest.join(", ")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn trs_becomes_steps_that_compose_to_the_same_matrix() {
        let q = DQuat::from_euler(EulerRot::YXZ, 0.7, -0.4, 1.9).as_quat();
        let (t, r, s) = ([1.0, -2.0, 0.5], q.to_array(), [2.0, 0.5, 3.0]);
        let steps = transform_steps(t, r, s);
        let got = super::super::nodes::transform_of(&steps);
        let want = DAffine3::from_scale_rotation_translation(
            Vec3::from(s).as_dvec3(),
            DQuat::from_xyzw(r[0].into(), r[1].into(), r[2].into(), r[3].into()),
            Vec3::from(t).as_dvec3(),
        );
        for p in [DVec3::X, DVec3::Y, DVec3::Z, DVec3::new(0.3, -1.0, 2.0)] {
            let (a, b) = (got.transform_point3(p), want.transform_point3(p));
            assert!((a - b).length() < 1e-5, "{p}: {a} vs {b}");
        }
    }

    #[test]
    fn pointers_base64_and_uris() {
        assert_eq!(
            pointer_of("meshes[3].primitives[0].attributes[\"NORMAL\"]"),
            "/meshes/3/primitives/0/attributes/NORMAL"
        );
        assert_eq!(base64_decode("aGVsbG8="), Some(b"hello".to_vec()));
        assert_eq!(base64_decode("aGVsbG8h"), Some(b"hello!".to_vec()));
        assert_eq!(base64_decode("aGk"), Some(b"hi".to_vec()));
        assert_eq!(base64_decode("a$"), None);
        assert_eq!(percent_decode("my%20room.bin"), "my room.bin");
        assert_eq!(list(&["a", "b", "c"]), "`a`, `b` and `c`");
    }
}
