//! The only bridge between the file format and rendering: turns a validated [`SceneFile`] into a
//! flat [`RenderScene`] (world-space primitives, resolved indices, BVH), keeping only what the
//! scene uses.

pub mod default_estimator;
pub mod gltf;
mod gltf_node;
pub mod lights;
mod materials;
mod media;
pub mod mesh;
mod mesh_data;
pub mod mesh_file;
pub mod mtl;
mod nodes;
pub mod ply;
pub mod polygon;
pub mod settings;

use std::path::Path;
use std::time::{Duration, Instant};

// The validator's bound on a volumetric scene's materials is the one the volume stack holds.
use crate::render_scene::medium::MAX_VOLUMETRIC_MATERIALS;

use crate::accel::BvhStats;
use crate::geometry::quadric::QuadricShape;
use crate::render_scene::geometry::GeometryBuilder;
use crate::render_scene::{Camera, DefaultEstimator, RenderScene};
use crate::scene::Diagnostic;
use crate::scene::schema::{self, LightSpec, SceneFile};

/// Counts and timings of a compilation, for `--stats`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CompileStats {
    /// Triangles kept.
    pub triangles: usize,
    /// Zero-area triangles dropped.
    pub degenerate_triangles: usize,
    /// Spheres (similarity-transformed).
    pub spheres: usize,
    /// Ellipsoids (spheres under non-uniform scale).
    pub ellipsoids: usize,
    /// Discs (`Disc` nodes, and cylinders' caps).
    pub discs: usize,
    /// Open cylinder walls (`Cylinder` nodes).
    pub cylinders: usize,
    /// Materials kept (used by some node).
    pub materials: usize,
    /// Lights.
    pub lights: usize,
    /// Distinct OBJ files loaded.
    pub meshes_loaded: usize,
    /// Textures kept (used by some kept material).
    pub textures: usize,
    /// Image files decoded for textures.
    pub images_loaded: usize,
    /// Time to load meshes and flatten the node tree.
    pub flatten_time: Duration,
    /// Time to build the BVH and reorder primitives.
    pub bvh_time: Duration,
    /// BVH shape.
    pub bvh: BvhStats,
    /// Warnings found while compiling (e.g. a sphere light compiled as a point light), with the
    /// field paths they concern; the pipeline locates them in the file.
    pub warnings: Vec<Diagnostic>,
}

/// Compiles a validated scene. Asset paths resolve against `base_dir`. Returns all asset errors.
/// The scene's settings are taken as stated in the file ([`compile_with`] for settings stated on
/// the command line).
pub fn compile(
    scene: &SceneFile,
    base_dir: &Path,
) -> Result<(RenderScene, CompileStats), Vec<Diagnostic>> {
    compile_with(scene, &schema::PhotonSettings::default(), base_dir)
}

/// [`compile`], where `command_line` is the photon settings the command line stated (already
/// applied to `scene`): they win over the default estimator's own per-pass counts, which the
/// file's do not ([`settings::resolve`]).
pub fn compile_with(
    scene: &SceneFile,
    command_line: &schema::PhotonSettings,
    base_dir: &Path,
) -> Result<(RenderScene, CompileStats), Vec<Diagnostic>> {
    let t0 = Instant::now();
    let mut stats = CompileStats::default();
    let mut materials = materials::MaterialTable::default();
    let mut objects = Vec::new();
    let mut builder = GeometryBuilder::default();
    let mut errors = Vec::new();
    let mut flattener = nodes::Flattener {
        scene,
        base_dir,
        materials: &mut materials,
        objects: &mut objects,
        builder: &mut builder,
        meshes: mesh::MeshCache::default(),
        errors: &mut errors,
        warnings: &mut stats.warnings,
        degenerate: 0,
        emitters: Vec::new(),
        camera: None,
        imported_lights: Vec::new(),
    };
    for (i, node) in scene.nodes.iter().enumerate() {
        flattener.node(&format!("nodes[{i}]"), node, glam::DAffine3::IDENTITY);
    }
    stats.degenerate_triangles = flattener.degenerate;
    stats.meshes_loaded = flattener.meshes.len();
    let emitters = std::mem::take(&mut flattener.emitters);
    // A glTF import's camera (chosen by name) and punctual lights join the scene's.
    let camera_spec = flattener
        .camera
        .take()
        .unwrap_or_else(|| scene.camera.clone());
    let all_lights: Vec<LightSpec> = (scene.lights.iter().cloned())
        .chain(std::mem::take(&mut flattener.imported_lights))
        .collect();
    if !errors.is_empty() {
        return Err(errors);
    }
    let eye = camera_spec.view().0.into();
    let lights::Compiled {
        lights,
        infinite_lights,
        infinity,
    } = lights::compile_lights(
        &all_lights,
        &emitters,
        lights::Targets {
            builder: &mut builder,
            objects: &mut objects,
            errors: &mut errors,
            warnings: &mut stats.warnings,
        },
        eye,
        base_dir,
    );
    if !errors.is_empty() {
        return Err(errors);
    }
    stats.flatten_time = t0.elapsed();
    stats.triangles = builder.triangles.len();
    stats.spheres = builder.spheres.len();
    stats.ellipsoids = builder.ellipsoids.len();
    for q in &builder.quadrics {
        match q.shape {
            QuadricShape::Disc => stats.discs += 1,
            QuadricShape::Cylinder => stats.cylinders += 1,
        }
    }
    stats.materials = materials.list.len();
    stats.textures = materials.textures.list.len();
    stats.images_loaded = materials.textures.images_loaded;
    stats.warnings.append(&mut materials.textures.warnings);
    stats.lights = lights.len();

    let t1 = Instant::now();
    let geometry = builder.build();
    stats.bvh_time = t1.elapsed();
    stats.bvh = geometry.bvh.stats();

    let params = settings::resolve(
        scene,
        command_line,
        &all_lights,
        lights.len(),
        |width, height| {
            DefaultEstimator::choose(
                &objects,
                |m| materials.list.get(m).map(|(_, m)| m),
                width,
                height,
            )
        },
    );
    let (eye, look_at, up, fov_y) = camera_spec.view();
    let camera = Camera::pinhole(
        eye.into(),
        look_at.into(),
        up.into(),
        fov_y,
        params.width as f32 / params.height as f32,
    );
    let camera = match camera_spec.lens() {
        Some((radius, focus_distance)) => camera.with_thin_lens(radius, focus_distance),
        None => camera,
    };
    let textures = std::mem::take(&mut materials.textures.list);
    let (media, camera_medium) = media::compile_media(scene);
    let volumetric = camera_medium.is_some()
        || materials.list.iter().any(|(_, m)| {
            m.interior.priority.is_some() || m.interior.medium.is_some() || m.interior.interface
        });
    if volumetric && materials.list.len() > MAX_VOLUMETRIC_MATERIALS {
        // Counted here, not in validation: imported (glTF, .mtl) materials count too.
        return Err(vec![Diagnostic::error(
            "materials",
            format!(
                "a scene with media, priorities or interfaces may have at most {MAX_VOLUMETRIC_MATERIALS} materials, imported ones included; this one has {}",
                materials.list.len()
            ),
        )]);
    }
    let (material_names, materials) = materials.list.into_iter().unzip();
    Ok((
        RenderScene {
            params,
            camera,
            materials,
            textures,
            material_names,
            lights,
            infinite_lights,
            infinity,
            objects,
            geometry,
            media,
            camera_medium,
            volumetric,
        },
        stats,
    ))
}
