//! The scene hash shared by the photon-map cache and the `.part` films: [`photon_key`], a 64-bit
//! FNV-1a hash of everything photon tracing reads, computed beside the compiled scene so that
//! both the photon cache (`integrators::photon::cache`, which names its files by it) and the
//! farm's settings hash (`farm::part_meta`, which adds the camera and the other render
//! parameters) import it from below.
//!
//! **What it covers.** The primitives (triangles with their normals, uvs and objects; spheres;
//! ellipsoids), which material and light each object has, the materials (BSDF values, texture
//! and bump references), the textures (their parameters, and the level-0 texels of image
//! textures: photons look textures up with a zero footprint), the lights, the photon counts and
//! bounce limits, the seed, the sampler and the texture filter, plus [`PHOTON_KEY_VERSION`] and
//! the crate version. Settings that only the estimate reads (`gather`, `caustic_gather`,
//! `max_radius`, `caustic_cone`, `final_gather`) are not in it. The struct fields are
//! destructured exhaustively, so a field added later fails to compile here until it is put in
//! the key or declared irrelevant. A change to the photon tracer itself must bump
//! [`PHOTON_KEY_VERSION`].

use super::geometry::{EllipsoidPrim, SpherePrim, TriAttrs};
use super::{Geometry, ObjectInfo, PhotonParams, RenderParams, RenderScene, Texture};
use crate::binfile::Fnv;

/// The bytes every key starts with. They are the photon cache's file signature of the day the
/// key was defined; they stay fixed (changing them changes every key, and so every cache file
/// name and `.part` settings hash).
const SALT: &[u8; 16] = b"caustic-photons1";

/// Version of what the key covers and of the photon tracer: bump it when photon tracing changes
/// so that old cache files miss.
pub const PHOTON_KEY_VERSION: u32 = 1;

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
        infinite_lights: _,
        infinity: _,
        objects,
        geometry,
    } = scene;
    let mut h = Fnv::new();
    h.bytes(SALT);
    h.u32(PHOTON_KEY_VERSION);
    h.bytes(env!("CARGO_PKG_VERSION").as_bytes());
    hash_params(&mut h, params);
    h.u64(objects.len() as u64);
    for o in objects {
        let ObjectInfo {
            name: _,
            material,
            light,
        } = o;
        h.debug("o", &(material, light));
    }
    h.debug("materials", materials);
    h.u64(textures.len() as u64);
    for t in textures {
        hash_texture(&mut h, t);
    }
    h.debug("lights", lights);
    hash_geometry(&mut h, geometry);
    h.finish()
}

/// Feeds the parameters photon tracing reads.
fn hash_params(h: &mut Fnv, params: &RenderParams) {
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
    } = photons;
    h.debug(
        "params",
        &(
            seed,
            sampler,
            texture_filter,
            global,
            caustic,
            caustic_per_light,
            min_bounces,
            max_bounces,
        ),
    );
}

/// Feeds a texture: its parameters, and the level-0 texels of image textures.
fn hash_texture(h: &mut Fnv, t: &Texture) {
    match t {
        Texture::Bitmap(b) => {
            h.debug("bitmap", &b.tile);
            let (w, hh) = (b.mip.width(), b.mip.height());
            h.u32(w);
            h.u32(hh);
            for y in 0..i64::from(hh) {
                for x in 0..i64::from(w) {
                    h.vec3(b.mip.texel(0, x, y));
                }
            }
        }
        Texture::HeightMap(m) => {
            h.debug("heightmap", &(m.depth, m.tile));
            let (w, hh) = (m.mip.width(), m.mip.height());
            h.u32(w);
            h.u32(hh);
            for y in 0..i64::from(hh) {
                for x in 0..i64::from(w) {
                    h.f32(m.mip.texel(0, x, y));
                }
            }
        }
        other => h.debug("texture", other),
    }
}

/// Feeds every primitive and its attributes (not the acceleration structures built from them).
fn hash_geometry(h: &mut Fnv, g: &Geometry) {
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
    } = g;
    // Discs and cylinders (after the scene key of scenes without them, which stays as it was).
    if !quadrics.is_empty() {
        h.bytes(b"quadrics");
        h.debug("quadrics", quadrics);
    }
    h.bytes(b"triangles");
    h.u64(triangles.len() as u64);
    for (t, a) in triangles.iter().zip(tri_attrs) {
        for v in t {
            h.vec3(*v);
        }
        let TriAttrs {
            object,
            normals,
            uvs,
        } = a;
        h.u32(*object);
        match normals {
            Some(n) => {
                h.u32(1);
                for v in n {
                    h.vec3(*v);
                }
            }
            None => h.u32(0),
        }
        for uv in uvs {
            h.f32(uv.x);
            h.f32(uv.y);
        }
    }
    h.bytes(b"spheres");
    h.u64(spheres.len() as u64);
    for s in spheres {
        let SpherePrim {
            center,
            radius,
            object,
        } = s;
        h.vec3(*center);
        h.f32(*radius);
        h.u32(*object);
    }
    h.u64(ellipsoids.len() as u64);
    for e in ellipsoids {
        let EllipsoidPrim {
            object_from_world,
            world_from_object,
            normal_to_world,
            object,
        } = e;
        h.debug(
            "e",
            &(
                object_from_world,
                world_from_object,
                normal_to_world,
                object,
            ),
        );
    }
}
