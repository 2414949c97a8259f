//! Semantic checks of a parsed scene: every problem is reported, not just the first.

mod light;
mod material;
mod media;
mod node;
mod photons;
mod render;

use std::collections::BTreeSet;

use super::diagnostic::{Diagnostic, did_you_mean, quoted_list};
use super::schema::{
    CameraSpec, ColorSpec, EmissionSpec, LightSpec, MaterialSpec, NodeSpec, PhotonFilter,
    PhotonSettings, RenderSettings, SceneFile, TextureSpec, TransformStep,
};

/// Largest accepted image side, in pixels.
pub const MAX_IMAGE_SIDE: u32 = 32_768;
/// Largest accepted image area, in pixels (the film needs 12 bytes per pixel).
pub const MAX_IMAGE_PIXELS: u64 = 100_000_000;
/// Largest accepted samples per pixel.
pub const MAX_SAMPLES_PER_PIXEL: u32 = 1 << 20;
/// Largest accepted recursion depth.
pub const MAX_DEPTH: u32 = 1024;
/// Deepest accepted group nesting.
pub const MAX_NESTING: usize = 64;
/// Most noise octaves accepted (each halves the feature size; 24 reach below f32 precision).
pub const MAX_OCTAVES: u32 = 24;
/// Highest frequency (per world or uv unit) the finest octave of a noise or marble texture may
/// reach: finer detail than a millionth of a unit is never visible, and far beyond it the
/// noise lattice runs out of f32 precision.
pub const MAX_NOISE_FREQUENCY: f32 = 1e6;
/// Largest marble turbulence (radians of phase).
pub const MAX_TURBULENCE: f32 = 1e4;

/// Largest light power, in watts per channel: f32 reaches 3.4e38, and radiance sums over samples,
/// bounces and pixels need headroom; any scene brighter than this renders the same with every
/// power divided by a constant and `render.exposure` multiplied by it.
pub const MAX_LIGHT_POWER: f32 = 1e30;

/// Most photons one map may be given: each emitted photon may be stored a few times (once per
/// diffuse bounce), at 24 bytes each, so this bounds a map to a few GB.
pub const MAX_PHOTONS: u32 = 50_000_000;
/// Most photons one density estimate may gather.
pub const MAX_GATHER: u32 = 10_000;
/// Most final-gather rays per camera hit.
pub const MAX_FINAL_GATHER: u32 = 4096;

/// Most ripple centres per texture.
pub const MAX_RIPPLE_CENTERS: usize = 256;

/// What a material uses a texture for.
#[derive(Clone, Copy, PartialEq, Eq)]
enum TextureUse {
    Color,
    Bump,
    Normal,
}

/// Checks a scene and returns all errors and warnings (errors first keep the file order).
#[must_use]
pub fn validate(scene: &SceneFile) -> Vec<Diagnostic> {
    let mut v = Validator {
        out: Vec::new(),
        used: BTreeSet::new(),
        used_textures: BTreeSet::new(),
        scene,
    };
    v.render(&scene.render.with_defaults());
    v.photons(&scene.photons.with_defaults());
    v.camera(&scene.camera);
    for (name, t) in &scene.textures {
        v.texture(&format!("textures.{name}"), t);
    }
    for (name, m) in &scene.materials {
        v.material(&format!("materials.{name}"), m);
        v.material_volume(&format!("materials.{name}"), m);
    }
    v.media(scene);
    if scene.lights.is_empty() && !scene.nodes.iter().any(has_emission) {
        v.out.push(
            Diagnostic::warning(
                "lights",
                "the scene has no lights, so only the background will be visible",
            )
            .with_help("add e.g. `Point(position: (0, 5, 0), power: (100, 100, 100))`"),
        );
    }
    for (i, l) in scene.lights.iter().enumerate() {
        v.light(&format!("lights[{i}]"), l);
        if let Some(n) = l.caustic_photons() {
            v.photon_count(&format!("lights[{i}].caustic_photons"), n);
        }
    }
    v.environments(scene);
    v.caustic_map_total(scene);
    if scene.nodes.is_empty() {
        v.out.push(Diagnostic::error(
            "nodes",
            "the scene has no nodes, so there is nothing to render",
        ));
    }
    for (i, n) in scene.nodes.iter().enumerate() {
        v.node(&format!("nodes[{i}]"), n, 1);
    }
    // Unused materials are worth a warning only in a scene that is otherwise valid.
    let dangling_refs = v.out.iter().any(Diagnostic::is_error);
    for name in scene.materials.keys() {
        if !dangling_refs && !v.used.contains(name.as_str()) {
            v.out.push(Diagnostic::warning(
                format!("materials.{name}"),
                format!("material `{name}` is never used"),
            ));
        }
    }
    // A texture counts as used when some material refers to it, used or not: the material's
    // own warning already says it is unused.
    for name in scene.textures.keys() {
        if !dangling_refs && !v.used_textures.contains(name.as_str()) {
            v.out.push(Diagnostic::warning(
                format!("textures.{name}"),
                format!("texture `{name}` is never used, so it is not loaded"),
            ));
        }
    }
    v.out
}

struct Validator<'a> {
    out: Vec<Diagnostic>,
    used: BTreeSet<&'a str>,
    used_textures: BTreeSet<&'a str>,
    scene: &'a SceneFile,
}

impl<'a> Validator<'a> {
    pub(super) fn err(&mut self, path: &str, msg: String) {
        self.out.push(Diagnostic::error(path, msg));
    }

    pub(super) fn finite(&mut self, path: &str, v: f32) -> bool {
        if v.is_finite() {
            return true;
        }
        self.err(path, format!("must be a finite number, found {v}"));
        false
    }

    pub(super) fn finite3(&mut self, path: &str, v: [f32; 3]) -> bool {
        if v.iter().all(|x| x.is_finite()) {
            return true;
        }
        self.err(
            path,
            format!("must have finite components, found {}", fmt3(v)),
        );
        false
    }

    pub(super) fn positive(&mut self, path: &str, v: f32, what: &str) {
        if self.finite(path, v) && v <= 0.0 {
            self.err(path, format!("{what} must be greater than 0, found {v}"));
        }
    }

    pub(super) fn range(&mut self, path: &str, v: f32, lo: f32, hi: f32) {
        if self.finite(path, v) && !(lo..=hi).contains(&v) {
            self.err(path, format!("must be within [{lo}, {hi}], found {v}"));
        }
    }

    pub(super) fn unit_rgb(&mut self, path: &str, v: [f32; 3], what: &str) {
        if self.finite3(path, v) && v.iter().any(|c| !(0.0..=1.0).contains(c)) {
            self.out.push(
                Diagnostic::error(
                    path,
                    format!("{what} components must be within [0, 1], found {}", fmt3(v)),
                )
                .with_help(
                    "a reflectance above 1 would create energy; scale the light's power instead",
                ),
            );
        }
    }
}

/// Formats a triple as `(x, y, z)`.
#[must_use]
pub fn fmt3(v: [f32; 3]) -> String {
    format!("({}, {}, {})", v[0], v[1], v[2])
}

/// True when `n` or a node below it carries `emission`.
fn has_emission(n: &NodeSpec) -> bool {
    match n {
        NodeSpec::Group { children, .. } => children.iter().any(has_emission),
        NodeSpec::Sphere { .. }
        | NodeSpec::Cube { .. }
        | NodeSpec::Quad { .. }
        | NodeSpec::Disc { .. }
        | NodeSpec::Cylinder { .. }
        | NodeSpec::Mesh { .. } => n.emission().is_some(),
        // Its emissive materials and punctual lights are known only once the file is read.
        NodeSpec::Gltf { .. } => true,
    }
}
