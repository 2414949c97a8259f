//! The scene's settings blocks, `render` and `photons`, as they are *stated*: every field an
//! `Option`, `None` when neither the file nor the command line sets it. One struct per block
//! serves both the file and the command line (`pipeline::SceneOverrides` holds a layer of each);
//! layers combine with [`RenderSettings::or`] (the upper layer's stated fields win), and the
//! defaults are one more layer, [`RenderSettings::DEFAULTS`] and [`PhotonSettings::DEFAULTS`],
//! written here and nowhere else. The compiler resolves the layers once
//! (`compile::settings::resolve`: command line, the default estimator's own choice, file,
//! defaults) into the parameters the renderer reads. (Like Tungsten's `PhotonMapSettings`, which
//! parses, validates and knows what was set, in one place.)

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::Rgb;
use super::values::optional_rgb;
use crate::settings::{IntegratorKind, SamplerKind, TextureFilter, Tonemap};

/// Declares, for a settings struct whose fields are all `Option`s, the layering methods: `or`
/// (field-wise `Option::or`), `stated` (the names of the fields set) and `only` (the layer with
/// just the fields a predicate keeps). The field list is checked against the struct by the
/// exhaustive destructuring in `or`: a field missing here is a compiler error.
macro_rules! layered {
    ($name:ident { $($field:ident),+ $(,)? }) => {
        impl $name {
            /// Field-wise: this layer's stated value, else `lower`'s.
            #[must_use]
            pub fn or(&self, lower: &Self) -> Self {
                let Self { $($field),+ } = self;
                Self { $($field: $field.clone().or_else(|| lower.$field.clone())),+ }
            }

            /// The names of the fields this layer states (`Some`), in declaration order.
            #[must_use]
            pub fn stated(&self) -> Vec<&'static str> {
                let mut out = Vec::new();
                $(if self.$field.is_some() {
                    out.push(stringify!($field));
                })+
                out
            }

            /// This layer with only the fields whose name `keep` accepts.
            #[must_use]
            pub fn only(&self, keep: impl Fn(&str) -> bool) -> Self {
                Self { $($field: self.$field.clone().filter(|_| keep(stringify!($field)))),+ }
            }
        }
    };
}

/// Image and sampling settings (the report's Settings.hpp constants that concern rendering).
/// Every field may be left out; the defaults are [`RenderSettings::DEFAULTS`].
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct RenderSettings {
    /// Image width in pixels (default 640).
    pub width: Option<u32>,
    /// Image height in pixels (default 480).
    pub height: Option<u32>,
    /// Camera samples per pixel, stratified over the pixel area (default 4).
    pub samples_per_pixel: Option<u32>,
    /// Maximum number of specular bounces (reflection/refraction recursion depth; default 8).
    pub max_depth: Option<u32>,
    /// A path whose weight (max RGB component) falls below this is not continued (default
    /// 0.001).
    pub min_contribution: Option<f32>,
    /// Shadow-ray samples per sphere light at each shaded point (soft shadows; default 1).
    pub light_samples: Option<u32>,
    /// Seed of every random stream; same seed and scene give the same image (default 0).
    pub seed: Option<u64>,
    /// Radiance seen by rays that leave the scene (default black).
    #[serde(deserialize_with = "optional_rgb")]
    #[schemars(with = "Option<Rgb>")]
    pub background: Option<Rgb>,
    /// Linear scale applied to radiance before writing 8-bit images. Unset: chosen per image
    /// from the rendered film (Reinhard et al. 2002's key: the log-average luminance mapped to
    /// 0.18, lowered so at most 1 % of the pixels clip; the render summary prints it). EXR
    /// output stays linear either way.
    pub exposure: Option<f32>,
    /// Tone-mapping curve for 8-bit images, applied after `exposure`: `Linear` (clip) or `Aces`
    /// (a filmic curve). Unset: `Aces` when the exposure is automatic (unset too), `Linear`
    /// when the scene states an exposure (today's images, byte for byte). EXR output stays
    /// linear.
    pub tonemap: Option<Tonemap>,
    /// Light-transport algorithm. Unset: the default estimator, chosen per scene — `PathPpm`
    /// (path tracing with a progressive caustic photon map, per-pass photon counts and gather
    /// sizes chosen from the image size; see docs/progressive.md) when some object's material
    /// has a mirror or glass part that could focus light onto a diffuse surface, else `Path`
    /// (no photon pass at all). Naming an integrator here or with `--integrator` picks it.
    pub integrator: Option<IntegratorKind>,
    /// Where the integrators' random numbers come from (default `Sobol`).
    pub sampler: Option<SamplerKind>,
    /// Path tracing: most diffuse or glossy bounces a path may make (unset: up to `max_depth`);
    /// 0 keeps only direct light and mirror/glass chains (Whitted's light transport).
    pub diffuse_depth: Option<u32>,
    /// How image textures are filtered (default `Anisotropic`).
    pub texture_filter: Option<TextureFilter>,
    /// Render pass after pass until the estimated relative mean squared error of the image
    /// (from each pixel's sample variance; docs/convergence.md) is at most this, e.g. 0.01;
    /// `--time` and `--spp` still stop it first (without `--spp` the scene's
    /// `samples_per_pixel` gives way to the target). Unset: render every sample.
    pub target_error: Option<f32>,
    /// Adaptive sampling (docs/convergence.md; default false): after a warm-up of uniform
    /// samples, each pixel takes more only while its own estimated relative error is above
    /// `target_error` (unset: 0.002); `samples_per_pixel` caps every pixel. Not with farm shards,
    /// sample ranges or `.part` outputs.
    pub adaptive: Option<bool>,
}

layered!(RenderSettings {
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
    sampler,
    diffuse_depth,
    texture_filter,
    target_error,
    adaptive,
});

impl RenderSettings {
    /// The defaults, the lowest layer. The fields left `None` mean something when unset (an
    /// automatic exposure, the tone curve that goes with it, the default estimator, no diffuse
    /// limit, no error target), which the resolve step states.
    pub const DEFAULTS: Self = Self {
        width: Some(640),
        height: Some(480),
        samples_per_pixel: Some(4),
        max_depth: Some(8),
        min_contribution: Some(0.001),
        light_samples: Some(1),
        seed: Some(0),
        background: Some([0.0; 3]),
        exposure: None,
        tonemap: None,
        integrator: None,
        sampler: Some(SamplerKind::Sobol),
        diffuse_depth: None,
        texture_filter: Some(TextureFilter::Anisotropic),
        target_error: None,
        adaptive: Some(false),
    };

    /// This layer over the defaults: every field that has a default is `Some`.
    #[must_use]
    pub fn with_defaults(&self) -> Self {
        self.or(&Self::DEFAULTS)
    }
}

/// Photon-map settings: the report's Settings.hpp photon constants, made explicit. Counts are
/// photons *emitted*; each light gets a share in proportion to its power (equal-flux photons).
/// Every field may be left out; the defaults are [`PhotonSettings::DEFAULTS`].
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct PhotonSettings {
    /// Photons emitted for the global map (diffuse interreflection); 0 builds no global map
    /// (default 200 000).
    pub global: Option<u32>,
    /// Caustic photons, aimed at objects that reflect or transmit (Jensen's projection maps)
    /// and stored where they land on a diffuse surface after specular bounces only; 0 builds no
    /// caustic map. Shared among the lights in proportion to power, except lights that set
    /// their own `caustic_photons` (default 200 000). The default estimator (no integrator
    /// named) chooses its own per-pass count unless the command line states one.
    pub caustic: Option<u32>,
    /// Nearest photons per global-map estimate (k; default 100).
    pub gather: Option<u32>,
    /// Nearest photons per caustic-map estimate (k; default 60).
    pub caustic_gather: Option<u32>,
    /// Largest radius (scene units) of an estimate's disc; unset: chosen from the scene's size
    /// and the photon count (reported in the summary). For the progressive integrators (`Ppm`,
    /// `PathPpm`): the radius of the first pass.
    pub max_radius: Option<f32>,
    /// Progressive integrators: the radius shrink of Knaus & Zwicker's schedule,
    /// `r²ᵢ₊₁ = r²ᵢ (i + α)/(i + 1)`, in (0, 1); smaller shrinks faster (less bias, more noise)
    /// (default 2/3).
    pub alpha: Option<f32>,
    /// The kernel of caustic estimates (default `Cone(k: 1.1)`).
    pub caustic_filter: Option<PhotonFilter>,
    /// Diffuse bounces a photon must have made before the global map stores it (the report's
    /// MIN_PHOTON_BOUNCE). At least 1: direct light always comes from shadow rays; more than 1
    /// drops the first bounces of indirect light (default 1).
    pub min_bounces: Option<u32>,
    /// Final-gather rays per camera hit on a diffuse surface (indirect light sampled from the
    /// BSDF and read from the maps where those rays land); 0 reads the global map directly
    /// (default 16).
    pub final_gather: Option<u32>,
    /// Most bounces a photon path makes before it is dropped: a safety net (Russian roulette
    /// ends paths without bias); the summary says what a cut path would have stored (default
    /// 256).
    pub max_bounces: Option<u32>,
}

layered!(PhotonSettings {
    global,
    caustic,
    gather,
    caustic_gather,
    max_radius,
    alpha,
    caustic_filter,
    min_bounces,
    final_gather,
    max_bounces,
});

impl PhotonSettings {
    /// The defaults, the lowest layer; `max_radius` unset means "chosen from the scene's size".
    pub const DEFAULTS: Self = Self {
        global: Some(200_000),
        caustic: Some(200_000),
        gather: Some(100),
        caustic_gather: Some(60),
        max_radius: None,
        alpha: Some(2.0 / 3.0),
        caustic_filter: Some(PhotonFilter::Cone { k: 1.1 }),
        min_bounces: Some(1),
        final_gather: Some(16),
        max_bounces: Some(256),
    };

    /// This layer over the defaults: every field that has a default is `Some`.
    #[must_use]
    pub fn with_defaults(&self) -> Self {
        self.or(&Self::DEFAULTS)
    }
}

impl super::SceneFile {
    /// The scene with its `render` and `photons` blocks over their defaults: what is written
    /// where the settings in effect must show (a farm job's scene, a golden file's settings, the
    /// tree `--set` edits, so that `photons.caustic_filter.k` exists to be set).
    #[must_use]
    pub fn with_default_settings(&self) -> Self {
        Self {
            render: self.render.with_defaults(),
            photons: self.photons.with_defaults(),
            ..self.clone()
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

/// The value an unset `render.sampler` resolves to, as [`RenderSettings::DEFAULTS`] states it
/// (a unit test checks they agree).
impl Default for SamplerKind {
    fn default() -> Self {
        SamplerKind::Sobol
    }
}

/// The value an unset `render.texture_filter` resolves to, as [`RenderSettings::DEFAULTS`]
/// states it (a unit test checks they agree).
impl Default for TextureFilter {
    fn default() -> Self {
        TextureFilter::Anisotropic
    }
}

/// The value an unset `photons.caustic_filter` resolves to, as [`PhotonSettings::DEFAULTS`]
/// states it (a unit test checks they agree).
impl Default for PhotonFilter {
    fn default() -> Self {
        PhotonFilter::Cone { k: 1.1 }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_defaults_set_every_field_that_has_one() {
        // The fields whose unset state means something (see `DEFAULTS`) and nothing else.
        let unset = |s: Vec<&str>, all: &[&'static str]| -> Vec<&'static str> {
            all.iter().copied().filter(|f| !s.contains(f)).collect()
        };
        let render_all = RenderSettings {
            width: Some(1),
            height: Some(1),
            samples_per_pixel: Some(1),
            max_depth: Some(1),
            min_contribution: Some(0.0),
            light_samples: Some(1),
            seed: Some(1),
            background: Some([0.0; 3]),
            exposure: Some(1.0),
            tonemap: Some(Tonemap::Linear),
            integrator: Some(IntegratorKind::Path),
            sampler: Some(SamplerKind::Sobol),
            diffuse_depth: Some(1),
            texture_filter: Some(TextureFilter::Anisotropic),
            target_error: Some(0.1),
            adaptive: Some(true),
        }
        .stated();
        assert_eq!(render_all.len(), 16);
        assert_eq!(
            unset(RenderSettings::DEFAULTS.stated(), &render_all),
            [
                "exposure",
                "tonemap",
                "integrator",
                "diffuse_depth",
                "target_error"
            ]
        );
        assert_eq!(PhotonSettings::DEFAULTS.stated().len(), 9);
        assert_eq!(
            RenderSettings::DEFAULTS.sampler,
            Some(SamplerKind::default())
        );
        assert_eq!(
            RenderSettings::DEFAULTS.texture_filter,
            Some(TextureFilter::default())
        );
        assert_eq!(
            PhotonSettings::DEFAULTS.caustic_filter,
            Some(PhotonFilter::default())
        );
        assert_eq!(PhotonSettings::DEFAULTS.max_radius, None);
    }

    #[test]
    fn the_upper_layer_wins_field_by_field() {
        let file = PhotonSettings {
            caustic: Some(5),
            gather: Some(7),
            ..Default::default()
        };
        let cli = PhotonSettings {
            caustic: Some(9),
            ..Default::default()
        };
        let r = cli.or(&file).with_defaults();
        assert_eq!(
            (r.caustic, r.gather, r.global),
            (Some(9), Some(7), Some(200_000))
        );
        assert_eq!(cli.or(&file).stated(), ["caustic", "gather"]);
        assert_eq!(r.only(|f| f == "gather").stated(), ["gather"]);
    }

    #[test]
    fn an_unset_block_reads_as_all_none_and_a_set_field_as_some() {
        let ron = ron::Options::default()
            .with_default_extension(ron::extensions::Extensions::IMPLICIT_SOME);
        let r: RenderSettings = ron
            .from_str("(width: 32, background: (1, 2, 3))")
            .expect("ron");
        assert_eq!(r.width, Some(32));
        assert_eq!(r.background, Some([1.0, 2.0, 3.0]));
        assert_eq!(r.stated(), ["width", "background"]);
        let p: PhotonSettings = toml::from_str("caustic = 10").expect("toml");
        assert_eq!(p.stated(), ["caustic"]);
        assert!(
            ron.from_str::<RenderSettings>("(background: (1, 2, 3, 4))")
                .is_err()
        );
    }
}
