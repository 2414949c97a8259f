//! The scene keys, derived from the data: [`photon_key`], a 64-bit FNV-1a hash of everything
//! photon tracing reads (the photon cache names its files by it,
//! `integrators::photon::cache`), and [`pixel_key`], the photon key plus every other setting
//! that changes a pixel and the camera (the `.part` films' settings hash, `farm::part_meta`,
//! which refuses to merge parts of different keys). Both are computed beside the compiled scene
//! so that both users import them from below.
//!
//! **Exhaustive by construction.** Every value is fed through [`KeyHash`]
//! (`binfile::key`): structs are destructured with every field named (no `..`), enums matched
//! without a wildcard arm, so a field or variant added later — a new lobe, a light's new
//! parameter, a texture's new field, a new render setting — fails to compile until it is fed or
//! bound to `_` here with the reason it cannot change pixels. Nothing goes through `Debug`.
//!
//! **What the photon key covers.** The primitives (triangles with their normals, uvs and
//! objects; spheres; ellipsoids), which material and light each object has, the materials
//! (every lobe's parameters, texture references, absorption), the textures (their parameters,
//! and the finest level's texels of image textures), the lights, the photon counts and bounce
//! limits, the seed, the sampler and the texture filter, plus [`PHOTON_KEY_VERSION`] and the
//! crate version. Settings that only the estimate reads (`gather`, `caustic_gather`,
//! `max_radius`, `alpha`, `caustic_cone`, `final_gather`), the image size, the samples and the
//! camera are not in it: a cache survives a change of view. A change to the photon tracer
//! itself must bump [`PHOTON_KEY_VERSION`].
//!
//! **What the pixel key adds.** Every render parameter (size, samples, depths, integrator,
//! exposure, tone curve, background, every photon setting) and the camera. Not in it: why the
//! default estimator chose the integrator (a scene naming the chosen integrator renders the
//! same bytes), object and material names, and what is not in the scene at all (the output
//! path, the thread count: the same bytes on any thread count).

use super::camera::Lens;
use super::geometry::{EllipsoidPrim, QuadricPrim, SpherePrim, TriAttrs};
use super::light::distant::DistantLight;
use super::light::environment::{EnvironmentLight, EnvironmentMap};
use super::light::infinite::SceneSphere;
use super::light::quadric::QuadricLight;
use super::light::rect::RectLight;
use super::light::sky::{SkyLight, SkyModel};
use super::light::spot::SpotLight;
use super::light::triangle_mesh::MeshLight;
use super::texture::{Mapping, NoiseTexture};
use super::{
    Camera, Geometry, Interior, Light, ObjectInfo, PhotonParams, RenderParams, RenderScene,
    SurfaceMaterial, Texture,
};
use crate::binfile::{Fnv, KeyHash};
use crate::geometry::quadric::QuadricShape;

/// The bytes every photon key starts with. They are the photon cache's file signature of the
/// day the key was defined; they stay fixed.
const SALT: &[u8; 16] = b"caustic-photons1";

/// The bytes every pixel key starts with.
const PIXEL_SALT: &[u8] = b"caustic-part 1";

/// Version of what the key covers and of the photon tracer: bump it when photon tracing changes
/// so that old cache files miss. (2: the key derived from the data instead of `Debug` text.)
pub const PHOTON_KEY_VERSION: u32 = 2;

/// The photon key of `scene` (module docs for what it covers).
#[must_use]
pub fn photon_key(scene: &RenderScene) -> u64 {
    let RenderScene {
        params,
        camera: _,
        materials,
        textures,
        material_names: _,
        lights,
        // Which lights are at infinity, and the scene's bounding sphere: derived from
        // `lights` and `geometry`.
        infinite_lights: _,
        infinity: _,
        objects,
        geometry,
        media,
        camera_medium,
        // Derived from the materials' interiors and `camera_medium`.
        volumetric: _,
    } = scene;
    let mut h = Fnv::new();
    h.bytes(SALT);
    h.u32(PHOTON_KEY_VERSION);
    h.str(env!("CARGO_PKG_VERSION"));
    photon_params(&mut h, params);
    objects.key_hash(&mut h);
    materials.key_hash(&mut h);
    textures.key_hash(&mut h);
    lights.key_hash(&mut h);
    geometry.key_hash(&mut h);
    // Media change photon paths; a scene without any feeds nothing, so its key is the one it
    // had before media existed.
    if !media.is_empty() || camera_medium.is_some() {
        h.str("media");
        h.u64(media.len() as u64);
        for m in media {
            for v in [m.sigma_a, m.sigma_s] {
                v.to_array().key_hash(&mut h);
            }
            h.u32(m.phase.g.to_bits());
        }
        camera_medium.key_hash(&mut h);
    }
    h.finish()
}

/// The pixel key of `scene`: [`photon_key`], every render parameter and the camera (module
/// docs).
#[must_use]
pub fn pixel_key(scene: &RenderScene) -> u64 {
    let mut h = Fnv::new();
    h.bytes(PIXEL_SALT);
    h.str(env!("CARGO_PKG_VERSION"));
    h.u64(photon_key(scene));
    scene.params.key_hash(&mut h);
    scene.camera.key_hash(&mut h);
    h.finish()
}

/// Feeds the parameters photon tracing reads.
fn photon_params(h: &mut Fnv, params: &RenderParams) {
    let RenderParams {
        width: _,
        height: _,
        samples_per_pixel: _,
        max_depth: _,
        min_contribution: _,
        light_samples: _,
        seed,
        background: _,
        exposure: _,
        tonemap: _,
        integrator: _,
        default_estimator: _,
        sampler,
        diffuse_depth: _,
        texture_filter,
        photons,
    } = params;
    let PhotonParams {
        global,
        caustic,
        caustic_per_light,
        gather: _,
        caustic_gather: _,
        max_radius: _,
        alpha: _,
        caustic_cone: _,
        min_bounces,
        final_gather: _,
        max_bounces,
        pilot_seed,
    } = photons;
    seed.key_hash(h);
    // A pilot seed other than the render's (a golden check's) changes the radius fields; the
    // usual case feeds nothing, so keys are those from before the field existed.
    if let Some(pilot) = pilot_seed.filter(|p| p != seed) {
        h.str("pilot");
        h.u64(pilot);
    }
    sampler.key_hash(h);
    texture_filter.key_hash(h);
    global.key_hash(h);
    caustic.key_hash(h);
    caustic_per_light.key_hash(h);
    min_bounces.key_hash(h);
    max_bounces.key_hash(h);
}

impl KeyHash for RenderParams {
    /// Every parameter but `default_estimator` (why the integrator was chosen: not a setting).
    fn key_hash(&self, h: &mut Fnv) {
        let Self {
            width,
            height,
            samples_per_pixel,
            max_depth,
            min_contribution,
            light_samples,
            seed,
            background,
            exposure,
            tonemap,
            integrator,
            default_estimator: _,
            sampler,
            diffuse_depth,
            texture_filter,
            photons,
        } = self;
        width.key_hash(h);
        height.key_hash(h);
        samples_per_pixel.key_hash(h);
        max_depth.key_hash(h);
        min_contribution.key_hash(h);
        light_samples.key_hash(h);
        seed.key_hash(h);
        background.key_hash(h);
        exposure.key_hash(h);
        tonemap.key_hash(h);
        integrator.key_hash(h);
        sampler.key_hash(h);
        diffuse_depth.key_hash(h);
        texture_filter.key_hash(h);
        photons.key_hash(h);
    }
}

impl KeyHash for PhotonParams {
    /// Every field but `pilot_seed`, which [`photon_key`] feeds (only when it is not the
    /// render's seed).
    fn key_hash(&self, h: &mut Fnv) {
        let Self {
            global,
            caustic,
            caustic_per_light,
            gather,
            caustic_gather,
            max_radius,
            alpha,
            caustic_cone,
            min_bounces,
            final_gather,
            max_bounces,
            pilot_seed: _,
        } = self;
        h.str("PhotonParams");
        global.key_hash(h);
        caustic.key_hash(h);
        caustic_per_light.key_hash(h);
        gather.key_hash(h);
        caustic_gather.key_hash(h);
        max_radius.key_hash(h);
        alpha.key_hash(h);
        caustic_cone.key_hash(h);
        min_bounces.key_hash(h);
        final_gather.key_hash(h);
        max_bounces.key_hash(h);
    }
}

impl KeyHash for ObjectInfo {
    /// The object's material and light (its name changes no pixel), and its body when it is
    /// part of one (only then: objects that are whole bodies keep the key they had before
    /// bodies existed).
    fn key_hash(&self, h: &mut Fnv) {
        let Self {
            name: _,
            material,
            light,
            body,
        } = self;
        material.key_hash(h);
        light.key_hash(h);
        if let Some(b) = body {
            b.key_hash(h);
        }
    }
}

impl KeyHash for SurfaceMaterial {
    /// Every field; the interior only when it states a medium, priority or interface (its
    /// other fields derive from the BSDF and absorption), so materials without those keep the
    /// key they had before media existed.
    fn key_hash(&self, h: &mut Fnv) {
        let Self {
            bsdf,
            color_texture,
            bump,
            normal_map,
            roughness_texture,
            conductor,
            filtered,
            absorption,
            interior,
        } = self;
        h.str("SurfaceMaterial");
        bsdf.key_hash(h);
        color_texture.key_hash(h);
        bump.key_hash(h);
        normal_map.key_hash(h);
        roughness_texture.key_hash(h);
        conductor.key_hash(h);
        filtered.key_hash(h);
        absorption.key_hash(h);
        let Interior {
            encloses: _,
            priority,
            medium,
            interface,
            ior: _,
        } = interior;
        if priority.is_some() || medium.is_some() || *interface {
            h.str("interior");
            priority.map(|p| p as u32).key_hash(h);
            medium.key_hash(h);
            interface.key_hash(h);
        }
    }
}

impl KeyHash for Texture {
    fn key_hash(&self, h: &mut Fnv) {
        match self {
            Texture::Bitmap(t) => t.key_hash(h),
            Texture::HeightMap(t) => t.key_hash(h),
            Texture::Marble {
                marble,
                depth,
                mapping,
            } => {
                h.str("Marble");
                marble.key_hash(h);
                depth.key_hash(h);
                mapping.key_hash(h);
            }
            Texture::Noise(t) => t.key_hash(h),
            Texture::Ripple(t) => t.key_hash(h),
            Texture::NormalMap(t) => t.key_hash(h),
        }
    }
}

crate::key_hash_struct!(NoiseTexture {
    noise,
    low,
    high,
    frequency,
    octaves,
    turbulence,
    depth,
    mapping,
});

impl KeyHash for Mapping {
    fn key_hash(&self, h: &mut Fnv) {
        h.str(match self {
            Mapping::Solid => "Solid",
            Mapping::Uv => "Uv",
        });
    }
}

impl KeyHash for Light {
    fn key_hash(&self, h: &mut Fnv) {
        match self {
            Light::Point {
                position,
                intensity,
            } => {
                h.str("Point");
                position.key_hash(h);
                intensity.key_hash(h);
            }
            Light::Sphere {
                center,
                radius,
                radiance,
            } => {
                h.str("Sphere");
                center.key_hash(h);
                radius.key_hash(h);
                radiance.key_hash(h);
            }
            Light::Rect(l) => l.key_hash(h),
            Light::Mesh(l) => l.key_hash(h),
            Light::Spot(l) => l.key_hash(h),
            Light::Distant(l) => l.key_hash(h),
            Light::Environment(l) => l.key_hash(h),
            Light::Sky(l) => l.key_hash(h),
            Light::Quadric(l) => l.key_hash(h),
        }
    }
}

impl KeyHash for SkyLight {
    fn key_hash(&self, h: &mut Fnv) {
        let SkyLight {
            model,
            k,
            ground,
            map,
        } = self;
        let SkyModel {
            sun,
            turbidity,
            zenith: (y_z, x_z, yc_z),
            coefficients,
        } = model;
        h.str("Sky");
        sun.key_hash(h);
        turbidity.key_hash(h);
        y_z.key_hash(h);
        x_z.key_hash(h);
        yc_z.key_hash(h);
        coefficients.key_hash(h);
        k.key_hash(h);
        ground.key_hash(h);
        map.key_hash(h);
    }
}

crate::key_hash_struct!(RectLight {
    corner,
    edge_u,
    edge_v,
    normal,
    area,
    radiance,
    two_sided,
    is_rectangle,
});

impl KeyHash for MeshLight {
    /// The mesh, its radiance and sidedness. Its private triangle-choice table is derived from
    /// the positions; it cannot be named outside `light/triangle_mesh.rs`, so this is the one
    /// destructuring with `..` (a field added there must be added here by hand).
    fn key_hash(&self, h: &mut Fnv) {
        let MeshLight {
            positions,
            triangles,
            radiance,
            two_sided,
            area,
            ..
        } = self;
        h.str("MeshLight");
        positions.key_hash(h);
        h.u64(triangles.len() as u64);
        for t in triangles {
            t.key_hash(h);
        }
        radiance.key_hash(h);
        two_sided.key_hash(h);
        area.key_hash(h);
    }
}

crate::key_hash_struct!(SpotLight {
    position,
    axis,
    intensity,
    cos_inner,
    cos_outer,
});

crate::key_hash_struct!(DistantLight {
    to_light,
    irradiance,
    one_minus_cos,
    radiance,
    scene,
});

crate::key_hash_struct!(SceneSphere { center, radius });

crate::key_hash_struct!(EnvironmentLight {
    map,
    rotation,
    scene
});

impl KeyHash for EnvironmentMap {
    fn key_hash(&self, h: &mut Fnv) {
        match self {
            EnvironmentMap::Constant(radiance) => {
                h.str("Constant");
                radiance.key_hash(h);
            }
            EnvironmentMap::Image {
                width,
                height,
                texels,
                // Derived from the texels.
                distribution: _,
            } => {
                h.str("Image");
                width.key_hash(h);
                height.key_hash(h);
                texels.key_hash(h);
            }
        }
    }
}

crate::key_hash_struct!(Camera {
    eye,
    forward,
    right,
    up,
    lens
});

impl KeyHash for Lens {
    fn key_hash(&self, h: &mut Fnv) {
        match self {
            Lens::Pinhole => h.str("Pinhole"),
            Lens::Thin {
                radius,
                focus_distance,
            } => {
                h.str("Thin");
                radius.key_hash(h);
                focus_distance.key_hash(h);
            }
        }
    }
}

impl KeyHash for Geometry {
    /// Every primitive and its attributes (not the acceleration structures built from them).
    fn key_hash(&self, h: &mut Fnv) {
        let Geometry {
            bvh: _,
            slots: _,
            tri_packs: _,
            has_quadrics: _,
            quadric_packs: _,
            triangles,
            tri_attrs,
            spheres,
            ellipsoids,
            quadrics,
        } = self;
        triangles.key_hash(h);
        tri_attrs.key_hash(h);
        spheres.key_hash(h);
        ellipsoids.key_hash(h);
        quadrics.key_hash(h);
    }
}

crate::key_hash_struct!(TriAttrs {
    object,
    normals,
    uvs
});

crate::key_hash_struct!(SpherePrim {
    center,
    radius,
    object
});

crate::key_hash_struct!(QuadricPrim {
    shape,
    object_from_world,
    world_from_object,
    normal_to_world,
    object,
});

crate::key_hash_struct!(QuadricLight {
    shape,
    world_from_object,
    object_from_world,
    normal_to_world,
    radiance,
    two_sided,
    area,
});

impl KeyHash for QuadricShape {
    fn key_hash(&self, h: &mut Fnv) {
        h.str(match self {
            QuadricShape::Disc => "Disc",
            QuadricShape::Cylinder => "Cylinder",
        });
    }
}

crate::key_hash_struct!(EllipsoidPrim {
    object_from_world,
    world_from_object,
    normal_to_world,
    object,
});
