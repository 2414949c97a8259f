//! The flat, world-space, immutable scene that integrators render: produced only by `compile`.

pub mod camera;
pub mod geometry;
pub mod hash;
pub mod interaction;
pub mod light;
pub mod light_sampler;
pub mod material;
pub mod medium;
pub mod participating;
pub mod surface;
pub mod texture;

pub use camera::Camera;
pub use geometry::{Geometry, Hit, PrimRef};
pub use interaction::{EmitterHit, Interaction, SurfaceHit};
pub use light::{EmissionSample, Light, LightSample};
pub use light_sampler::LightSampler;
pub use material::{Shading, ShadingPoint, SurfaceMaterial};
pub use medium::{Interior, Medium};
pub use participating::HomogeneousMedium;
pub use surface::{SurfaceParams, SurfacePoint};
pub use texture::Texture;

use glam::Vec3;

use crate::sampling::SamplerKind;
pub use crate::settings::{IntegratorKind, TextureFilter, Tonemap};
use crate::shading::LobeFlags;

/// The smallest camera spread, as a fraction of a pixel's angular size: the spread of one
/// sample at 64 samples per pixel and above ([`RenderScene::pixel_spread`]), and the footprint
/// bump and normal maps are always looked up at.
pub const MIN_SPREAD_FRACTION: f32 = 0.125;

/// Rendering parameters after command-line overrides.
#[derive(Debug, Clone, PartialEq)]
pub struct RenderParams {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Camera samples per pixel.
    pub samples_per_pixel: u32,
    /// Maximum specular recursion depth.
    pub max_depth: u32,
    /// Paths with a smaller weight are not continued.
    pub min_contribution: f32,
    /// Shadow samples per sphere light per shaded point.
    pub light_samples: u32,
    /// Seed of all random streams.
    pub seed: u64,
    /// Radiance of rays leaving the scene.
    pub background: Vec3,
    /// Radiance scale applied when writing 8-bit images.
    pub exposure: f32,
    /// Tone-mapping curve for 8-bit images, after `exposure`.
    pub tonemap: Tonemap,
    /// Which integrator renders the image (the scene's or the command line's, else the default
    /// estimator's choice).
    pub integrator: IntegratorKind,
    /// Why `integrator` was chosen when the scene and command line named none (`None`: named).
    pub default_estimator: Option<DefaultEstimator>,
    /// Where integrators draw random numbers from.
    pub sampler: SamplerKind,
    /// Path tracing: most non-delta bounces per path (`u32::MAX`: only `max_depth` limits).
    pub diffuse_depth: u32,
    /// How image textures are filtered.
    pub texture_filter: TextureFilter,
    /// Photon-map settings (the `photon` integrator).
    pub photons: PhotonParams,
}

/// The photon budget of one pass of the default estimator.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PassPhotons {
    /// Caustic photons emitted per pass.
    pub caustic: u32,
    /// Nearest photons that set the initial radius `R(x)` (about that many photons per disc at
    /// the first pass, where the pilot map's density holds; later passes shrink the disc).
    pub caustic_gather: u32,
    /// Photons emitted per pass for the global map: 0, no global map. The path tracer carries
    /// all diffuse interreflection itself, without the global map's blur (the local bias of the
    /// issue's `ppm` row); only the caustic paths, which it finds by chance, come from photons.
    pub global: u32,
}

/// How the default estimator was chosen for a scene that names no integrator (kept in
/// `RenderParams::default_estimator` for the summary line; chosen by
/// `compile::default_estimator`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DefaultEstimator {
    /// Objects whose material has a mirror or glass part or is near-specular.
    pub specular_casters: usize,
    /// The per-pass photon budget chosen (`None` when the choice is `path`, or when the command
    /// line stated the counts, which then stand as given).
    pub photons: Option<PassPhotons>,
}

/// Photon-map settings after command-line overrides (see the scene schema's `photons`).
#[derive(Debug, Clone, PartialEq)]
pub struct PhotonParams {
    /// Photons emitted for the global map, shared among lights by power.
    pub global: u32,
    /// Caustic photons shared by power among the lights without their own budget.
    pub caustic: u32,
    /// Per light (parallel to `RenderScene::lights`): its own caustic photon count, if set.
    pub caustic_per_light: Vec<Option<u32>>,
    /// k of global-map estimates.
    pub gather: u32,
    /// k of caustic-map estimates.
    pub caustic_gather: u32,
    /// Largest estimate radius (scene units); `None`: chosen per map from the scene's size.
    /// Progressive integrators: the first pass's radius.
    pub max_radius: Option<f32>,
    /// Progressive integrators: Knaus & Zwicker's radius shrink α, in (0, 1).
    pub alpha: f32,
    /// Cone-filter constant of caustic estimates; `None`: box filter.
    pub caustic_cone: Option<f32>,
    /// Diffuse bounces before the global map stores a photon (≥ 1).
    pub min_bounces: u32,
    /// Final-gather rays per camera hit (0: read the global map directly).
    pub final_gather: u32,
    /// Most bounces of a photon path.
    pub max_bounces: u32,
    /// Seed of the progressive integrators' pilot maps, which set the radius field `R(x)` of
    /// every pass (`integrators::photon::passes`); `None`: the render's seed. A `golden check`
    /// renders with another seed than its golden but the golden's pilot seed, so that both
    /// renders have the same expected image (the same blur), not only the same settings
    /// (docs/golden.md). Not a scene setting.
    pub pilot_seed: Option<u64>,
}

/// A named scene object, for diagnostics and ray-tree dumps.
#[derive(Debug, Clone, PartialEq)]
pub struct ObjectInfo {
    /// Name from the file, or `kind#index` when unnamed.
    pub name: String,
    /// Material index, or `None` for light emitters.
    pub material: Option<u32>,
    /// Index of the light this object emits as, if it is an emitter.
    pub light: Option<u32>,
    /// The body this object is a part of, when it is not a whole body itself: the material
    /// groups of one mesh are objects of their own (one material each) but one surface, and
    /// name the mesh's first group object here. Thin-wall tests take a query point's whole
    /// body as its receiver ([`RenderScene::body_of`]).
    pub body: Option<u32>,
}

/// Everything an integrator needs, resolved to indices.
#[derive(Debug)]
pub struct RenderScene {
    /// Image and sampling parameters.
    pub params: RenderParams,
    /// The camera.
    pub camera: Camera,
    /// Materials, indexed by `ObjectInfo::material`.
    pub materials: Vec<SurfaceMaterial>,
    /// Textures the materials use, indexed by `SurfaceMaterial::{color_texture, bump}`.
    pub textures: Vec<Texture>,
    /// Material names, parallel to `materials`.
    pub material_names: Vec<String>,
    /// Lights.
    pub lights: Vec<Light>,
    /// The lights at infinity (indices into `lights`, in list order) that rays escaping the
    /// scene loop over ([`RenderScene::lights_escaped`]).
    pub infinite_lights: Vec<u32>,
    /// The first light that fills the sky (environment) and its object: what ray trees record
    /// escaping rays against ([`RenderScene::escape_record`]).
    pub infinity: Option<light::escape::InfinityRef>,
    /// Objects, indexed by the `object` of each primitive.
    pub objects: Vec<ObjectInfo>,
    /// Primitives and their BVH.
    pub geometry: Geometry,
    /// Participating media, indexed by [`Interior::medium`] and `camera_medium`.
    pub media: Vec<HomogeneousMedium>,
    /// The medium around every object (fog), where cameras and lights are.
    pub camera_medium: Option<u32>,
    /// Some material states a medium, a priority or an interface, or the scene a medium:
    /// paths carry the volume stack and sample media ([`Medium`]); false keeps every
    /// integrator on its path without media (the same bytes as before media existed).
    pub volumetric: bool,
}

impl RenderScene {
    /// The body object `object` is a part of: [`ObjectInfo::body`], or the object itself.
    #[inline]
    #[must_use]
    pub fn body_of(&self, object: u32) -> u32 {
        self.objects
            .get(object as usize)
            .and_then(|o| o.body)
            .unwrap_or(object)
    }

    /// True if object `object` lets no light through (no transmitting lobe, or an emitter).
    #[inline]
    #[must_use]
    pub fn is_opaque(&self, object: u32) -> bool {
        self.objects[object as usize].material.is_none_or(|m| {
            !self.materials[m as usize]
                .bsdf
                .flags()
                .contains(LobeFlags::TRANSMISSION)
        })
    }

    /// The angle one camera sample's footprint subtends: the pixel's angular size, shrunk by
    /// `1/√spp` (down to [`MIN_SPREAD_FRACTION`]) since samples are spread over the pixel. The
    /// ray cones that size texture footprints start from this.
    #[must_use]
    pub fn pixel_spread(&self) -> f32 {
        let pixel = 2.0 * self.camera.up.length() / self.params.height.max(1) as f32;
        pixel
            * (1.0 / (self.params.samples_per_pixel.max(1) as f32).sqrt()).max(MIN_SPREAD_FRACTION)
    }
}
