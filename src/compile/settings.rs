//! The one place the scene's settings are resolved, once, in one direction: the stated layers
//! (the file's `render` and `photons` with the command line's applied over them, every field an
//! `Option`) become the [`RenderParams`] the renderer reads. Precedence, highest first:
//!
//! 1. what the command line stated (`--set photons.caustic=…`, `--caustic-photons`, …);
//! 2. the default estimator's own per-pass photon budget, when the scene names no integrator
//!    ([`DefaultEstimator::choose`]): a scene's counts are sized for the `photon` integrator's
//!    single map, not for `path-ppm`'s passes;
//! 3. what the file stated;
//! 4. the defaults ([`RenderSettings::DEFAULTS`], [`PhotonSettings::DEFAULTS`]).
//!
//! The fields whose unset state means something resolve here too: no exposure renders at unit
//! scale (the binary's automatic exposure reads the stated `None` itself), no tone curve is
//! `Linear`, no diffuse limit is `u32::MAX`.

use crate::render_scene::{DefaultEstimator, PhotonParams, RenderParams};
use crate::scene::schema::{
    LightSpec, PhotonFilter, PhotonSettings, RenderSettings, SceneFile, Tonemap,
};
use crate::settings::IntegratorKind;

/// The photon counts the default estimator chooses and the command line may state instead.
const PER_PASS_FIELDS: [&str; 4] = ["caustic", "global", "caustic_gather", "gather"];

/// Resolves `scene`'s settings (the file's with the command line's applied) into the renderer's
/// parameters. `command_line` is the photon layer the command line stated; `lights` the scene's
/// lights (their own `caustic_photons`) and `light_count` the compiled lights' number
/// (emissive shapes share `photons.caustic`); `choose` picks the default estimator for an image
/// of the given width and height when no integrator is named.
pub fn resolve(
    scene: &SceneFile,
    command_line: &PhotonSettings,
    lights: &[LightSpec],
    light_count: usize,
    choose: impl FnOnce(u32, u32) -> (IntegratorKind, DefaultEstimator),
) -> RenderParams {
    let r = scene.render.with_defaults();
    let (width, height) = (value(r.width), value(r.height));
    let (integrator, mut default_estimator) = match r.integrator {
        Some(kind) => (kind, None),
        None => {
            let (kind, why) = choose(width, height);
            (kind, Some(why))
        }
    };
    let mut caustic_per_light: Vec<Option<u32>> =
        lights.iter().map(LightSpec::caustic_photons).collect();
    let mut chosen = PhotonSettings::default();
    if let Some(why) = default_estimator.as_mut()
        && let Some(p) = why.photons
    {
        // The default estimator's own per-pass budget replaces the file's counts and every
        // light's own; counts the command line stated stand, and the summary then says so.
        chosen = PhotonSettings {
            caustic: Some(p.caustic),
            caustic_gather: Some(p.caustic_gather),
            global: Some(p.global),
            ..PhotonSettings::default()
        };
        caustic_per_light.iter_mut().for_each(|c| *c = None);
        if PER_PASS_FIELDS
            .iter()
            .any(|f| command_line.stated().contains(f))
        {
            why.photons = None;
        }
    }
    // Emissive shapes have no budget of their own: they share `photons.caustic` by power.
    caustic_per_light.resize(light_count, None);
    let p = command_line.or(&chosen).or(&scene.photons).with_defaults();
    let photons = PhotonParams {
        global: value(p.global),
        caustic: value(p.caustic),
        caustic_per_light,
        gather: value(p.gather),
        caustic_gather: value(p.caustic_gather),
        max_radius: p.max_radius,
        alpha: value(p.alpha),
        caustic_cone: match value(p.caustic_filter) {
            PhotonFilter::Box => None,
            PhotonFilter::Cone { k } => Some(k),
        },
        min_bounces: value(p.min_bounces),
        final_gather: value(p.final_gather),
        max_bounces: value(p.max_bounces),
        pilot_seed: None,
    };
    let RenderSettings {
        width: _,
        height: _,
        samples_per_pixel,
        max_depth,
        min_contribution,
        light_samples,
        seed,
        background,
        exposure,
        tonemap,
        integrator: _,
        sampler,
        diffuse_depth,
        texture_filter,
        // Read by the render loop from the stated settings (they decide which samples are
        // taken, not what a sample computes).
        target_error: _,
        adaptive: _,
    } = r;
    RenderParams {
        width,
        height,
        samples_per_pixel: value(samples_per_pixel),
        max_depth: value(max_depth),
        min_contribution: value(min_contribution),
        light_samples: value(light_samples),
        seed: value(seed),
        background: value(background).into(),
        exposure: exposure.unwrap_or(1.0),
        tonemap: tonemap.unwrap_or(Tonemap::Linear),
        integrator,
        default_estimator,
        sampler: value(sampler),
        diffuse_depth: diffuse_depth.unwrap_or(u32::MAX),
        texture_filter: value(texture_filter),
        photons,
    }
}

/// A field of a layer over its defaults, where every field with a default is `Some` (a unit test
/// of the schema checks `DEFAULTS`, and that the enums' `Default` is what `DEFAULTS` states);
/// the type's default would only stand in for a field left out of `DEFAULTS`.
fn value<T: Default>(field: Option<T>) -> T {
    field.unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render_scene::PassPhotons;

    fn scene(text: &str) -> SceneFile {
        let source = format!(
            "(render: {text}, camera: Pinhole(eye: (0, 0, 1), look_at: (0, 0, 0), fov_y: 40), \
             materials: {{}}, nodes: [])"
        );
        crate::scene::load::SourceFile::new(std::path::Path::new("settings.ron"), source)
            .and_then(|f| f.parse())
            .expect("parses")
    }

    fn default_estimator(w: u32, h: u32) -> (IntegratorKind, DefaultEstimator) {
        let why = DefaultEstimator {
            specular_casters: 1,
            photons: Some(PassPhotons::for_image(w, h)),
        };
        (IntegratorKind::PathPpm, why)
    }

    #[test]
    fn unset_fields_take_the_documented_defaults() {
        let p = resolve(
            &scene("(integrator: Path)"),
            &PhotonSettings::default(),
            &[],
            1,
            |_, _| unreachable!("the integrator is named"),
        );
        // The values the schema's documentation states.
        assert_eq!((p.width, p.height, p.samples_per_pixel), (640, 480, 4));
        assert_eq!((p.max_depth, p.light_samples, p.seed), (8, 1, 0));
        assert_eq!(p.min_contribution, 0.001);
        assert_eq!((p.exposure, p.tonemap), (1.0, Tonemap::Linear));
        assert_eq!(p.diffuse_depth, u32::MAX);
        let q = &p.photons;
        assert_eq!(
            (q.global, q.caustic, q.gather, q.caustic_gather),
            (200_000, 200_000, 100, 60)
        );
        assert_eq!((q.max_radius, q.caustic_cone), (None, Some(1.1)));
        assert_eq!((q.min_bounces, q.final_gather, q.max_bounces), (1, 16, 256));
        assert_eq!(q.alpha, 2.0 / 3.0);
        assert_eq!(q.caustic_per_light, [None]);
    }

    #[test]
    fn the_default_estimators_budget_beats_the_file_but_not_the_command_line() {
        let mut s = scene("(width: 256, height: 256)");
        s.photons.caustic = Some(123);
        s.photons.gather = Some(77);
        let file_only = resolve(&s, &PhotonSettings::default(), &[], 0, default_estimator);
        // 256 × 256 × 0.3 per pixel, rounded to a thousand (docs/progressive.md).
        assert_eq!(file_only.photons.caustic, 20_000);
        assert_eq!(file_only.photons.caustic_gather, 10);
        assert_eq!(file_only.photons.global, 0);
        assert_eq!(file_only.photons.gather, 77);
        assert!(
            file_only
                .default_estimator
                .and_then(|d| d.photons)
                .is_some()
        );

        let cli = PhotonSettings {
            caustic: Some(5000),
            ..PhotonSettings::default()
        };
        s.photons.caustic = Some(5000);
        let stated = resolve(&s, &cli, &[], 0, default_estimator);
        assert_eq!(stated.photons.caustic, 5000);
        assert_eq!(stated.photons.caustic_gather, 10);
        assert!(
            stated
                .default_estimator
                .is_some_and(|d| d.photons.is_none())
        );

        s.render.integrator = Some(IntegratorKind::Photon);
        let named = resolve(&s, &PhotonSettings::default(), &[], 2, |_, _| {
            unreachable!("the integrator is named")
        });
        assert_eq!(named.photons.caustic, 5000);
        assert_eq!(named.photons.global, 200_000);
        assert_eq!(named.photons.caustic_per_light, [None, None]);
    }
}
