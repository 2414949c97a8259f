//! `caustic golden`'s library half: a scene rendered batch by batch for the golden test
//! ([`render_scene`]: prepared with the overrides, [`crate::render::golden::render_batches`],
//! its [`GoldenMeta`] with the flags recorded), `update`'s search for the samples per pixel
//! that reach a requested detection floor ([`update_scene`]), and `check`'s render of a scene
//! again with the golden's recorded flags and a fresh seed ([`check_scene`], [`combined`]).
//! The binary finds the scenes, prints and decides the exit code; the verdict's words are
//! [`crate::render::golden::report`]'s.

use std::path::{Path, PathBuf};

use super::flags::{FlagError, StatedFlag};
use super::{SceneOverrides, prepare};
use crate::Error;
use crate::farm::part_meta::settings_hash;
use crate::render::RenderOptions;
use crate::render::golden::floor::{self, DetectSearch, DetectStep, DetectionFloor};
use crate::render::golden::{
    BatchBlocks, GoldenImage, GoldenMeta, PixelEstimates, golden_file_name, render_batches, report,
};
use crate::scene::Diagnostic;

/// Why a golden run is refused; converted into [`Error::Usage`].
#[derive(Debug, thiserror::Error)]
pub enum GoldenRefusal {
    /// A scene of fewer than 2 samples per pixel: no noise estimate.
    #[error(
        "`{path}`: a golden test needs at least 2 samples per pixel to measure the noise, found {spp}; give --spp",
        path = .0.display(),
        spp = .1
    )]
    TooFewSamples(PathBuf, u32),
    /// The golden of a scene is missing or unreadable.
    #[error(
        "{}: {error}; write it with `caustic golden update {} -o {}`",
        scene.display(),
        scene.display(),
        golden_dir.display()
    )]
    Unreadable {
        /// The scene checked.
        scene: PathBuf,
        /// The folder of golden images.
        golden_dir: PathBuf,
        /// Why the golden cannot be read.
        error: crate::render::golden::GoldenError,
    },
    /// A flag recorded in a golden that this caustic cannot apply.
    #[error("`{}`: {}", golden.display(), recorded_words(key, value, reason))]
    Recorded {
        /// The golden file.
        golden: PathBuf,
        /// The recorded flag's name.
        key: String,
        /// Its recorded value.
        value: String,
        /// What is wrong with it.
        reason: FlagError,
    },
}

/// The words of a recorded flag that cannot be applied (after the golden's path).
fn recorded_words(key: &str, value: &str, reason: &FlagError) -> String {
    let again = "run `caustic golden update` again";
    match reason {
        FlagError::Unknown(_) => {
            format!("unknown recorded flag `{key}` (written by a newer caustic?); {again}")
        }
        FlagError::Malformed(_) => {
            format!("its recorded flag `{key}={value}` is malformed; {again}")
        }
        FlagError::NoSuchChoice(_) => {
            format!("its recorded flag `{key}={value}` names no such choice; {again}")
        }
    }
}

impl From<GoldenRefusal> for Error {
    fn from(e: GoldenRefusal) -> Self {
        Error::Usage(e.to_string())
    }
}

/// The overrides that `update` records for `check` to apply again: the `--set`s and every
/// flag but the seed (a check renders with a seed of its own), as `(flag, value)`.
#[must_use]
pub fn record(o: &SceneOverrides) -> Vec<(String, String)> {
    let mut out: Vec<(String, String)> = o.sets.iter().map(|s| ("set".into(), s.clone())).collect();
    for f in o.flags() {
        if !matches!(f, StatedFlag::Seed(_)) {
            out.push((f.name().into(), f.cli_value()));
        }
    }
    out
}

/// The golden's recorded overrides, then the check's own on top (its `--set`s after the
/// golden's, its flags instead of the golden's); the seed is the check's, or the golden's + 1
/// so that the two renders' noise is independent. `path` (the golden file) names errors.
///
/// # Errors
/// [`GoldenRefusal::Recorded`] for a recorded flag that is unknown (the seed included, which
/// `update` never records), malformed or names no such choice.
pub fn combined(
    golden: &GoldenMeta,
    own: &SceneOverrides,
    path: &Path,
) -> Result<SceneOverrides, Error> {
    let mut o = SceneOverrides::default();
    for (key, value) in &golden.overrides {
        if key == "set" {
            o.sets.push(value.clone());
            continue;
        }
        let flag = match key.as_str() {
            "seed" => Err(FlagError::Unknown(key.clone())),
            _ => StatedFlag::parse(key, value),
        };
        let flag = flag.map_err(|reason| GoldenRefusal::Recorded {
            golden: path.to_path_buf(),
            key: key.clone(),
            value: value.clone(),
            reason,
        })?;
        o.state(flag);
    }
    o.sets.extend(own.sets.iter().cloned());
    o.render = own.render.or(&o.render);
    o.photons = own.photons.or(&o.photons);
    o.render.seed = Some(own.render.seed.unwrap_or(golden.seed.wrapping_add(1)));
    Ok(o)
}

/// A scene rendered for the golden test.
#[derive(Debug)]
pub struct GoldenRun {
    /// Per-pixel means and variances of the mean.
    pub estimates: PixelEstimates,
    /// Each batch's block means.
    pub batches: BatchBlocks,
    /// Each batch's cell means (the structure test).
    pub cells: BatchBlocks,
    /// What the golden records of the render.
    pub meta: GoldenMeta,
    /// The settings hash as if rendered with the golden's seed instead of its own.
    pub hash_at_seed: u64,
    /// How its noise falls with more samples per pixel (for `--detect`).
    pub noise: crate::render::golden::noise_scaling::NoiseScaling,
}

/// What a golden run says on the way, for the command to print.
#[derive(Debug)]
pub enum GoldenNote<'a> {
    /// The scene's warnings (before rendering).
    Warnings(&'a [Diagnostic]),
    /// Samples that were NaN or infinite and were dropped, in the scene named.
    NanSamples(&'a Path, u64),
    /// A line of `update`'s search for the samples per pixel of a detection floor.
    Detect(String),
}

/// Prepares and renders `path` batch by batch in blocks of `block` pixels on `threads`
/// workers; refuses fewer than 2 samples per pixel (no noise estimate). `golden_seed` (a
/// check's) is the golden's seed: the settings hash is also computed as if rendered with it,
/// and the progressive integrators' pilot maps are traced from it, so that golden and check
/// have the same radius field and thus the same expected image (docs/golden.md).
///
/// # Errors
/// The scene's errors, [`GoldenRefusal::TooFewSamples`], the render's errors.
pub fn render_scene(
    path: &Path,
    overrides: &SceneOverrides,
    block: u32,
    threads: Option<usize>,
    golden_seed: Option<u64>,
    note: &mut dyn FnMut(GoldenNote<'_>),
) -> Result<GoldenRun, Error> {
    let mut prepared = prepare(path, overrides)?;
    prepared.render_scene.params.photons.pilot_seed = golden_seed;
    note(GoldenNote::Warnings(&prepared.warnings));
    let p = &prepared.render_scene.params;
    if p.samples_per_pixel < 2 {
        return Err(GoldenRefusal::TooFewSamples(path.to_path_buf(), p.samples_per_pixel).into());
    }
    let hash = settings_hash(&prepared.render_scene);
    let seed = prepared.render_scene.params.seed;
    let hash_at_seed = match golden_seed {
        Some(s) if s != seed => {
            prepared.render_scene.params.seed = s;
            let h = settings_hash(&prepared.render_scene);
            prepared.render_scene.params.seed = seed;
            h
        }
        _ => hash,
    };
    let options = RenderOptions {
        threads,
        ..RenderOptions::default()
    };
    let out = render_batches(&mut prepared.render_scene, &options, block)?;
    if out.output.stats.nan_samples > 0 {
        note(GoldenNote::NanSamples(path, out.output.stats.nan_samples));
    }
    // The settings in effect: the stated ones over their defaults.
    let scene_value =
        serde_json::to_value(prepared.scene.with_default_settings()).unwrap_or_default();
    let meta = GoldenMeta {
        scene: path.display().to_string(),
        overrides: record(overrides),
        settings: report::settings(&scene_value),
        ..GoldenMeta::of(&prepared.render_scene, hash)
    };
    Ok(GoldenRun {
        estimates: PixelEstimates::from_sums(&out.output.sums),
        batches: out.batches,
        cells: out.cells,
        meta,
        hash_at_seed,
        noise: out.noise,
    })
}

/// How `golden update` renders each scene.
#[derive(Debug, Clone)]
pub struct UpdateSettings {
    /// Block side in pixels.
    pub block: u32,
    /// The smallest change to catch (a fraction, e.g. 0.02), if asked for.
    pub detect: Option<f64>,
    /// Most samples per pixel the search for `detect` may choose.
    pub detect_limit: u32,
    /// The checks' false-alarm rate, for the detection floor.
    pub alpha: f64,
    /// Worker threads (`None`: all cores).
    pub threads: Option<usize>,
}

/// A golden written by [`update_scene`].
#[derive(Debug)]
pub struct Updated {
    /// The golden file.
    pub target: PathBuf,
    /// Image width and height in pixels.
    pub size: (u32, u32),
    /// Samples per pixel rendered.
    pub spp: u32,
    /// The integrator's name.
    pub integrator: String,
    /// The smallest changes the golden catches.
    pub floor: DetectionFloor,
}

impl Updated {
    /// The line `update` prints for the scene `path`.
    #[must_use]
    pub fn summary(&self, path: &Path) -> String {
        let (w, h) = self.size;
        format!(
            "{}: {w}×{h}, {} spp, {}: golden written to `{}`; {}",
            path.display(),
            self.spp,
            self.integrator,
            self.target.display(),
            report::describe_floor(&self.floor)
        )
    }
}

/// Renders `path` with `overrides` and writes its golden into `dir`; with a `detect` target,
/// renders again at the samples per pixel the measured noise predicts until the floor is
/// reached (or the limit), keeping the render that reaches it with the fewest samples.
///
/// # Errors
/// [`render_scene`]'s, and the golden's writer's.
pub fn update_scene(
    path: &Path,
    overrides: &SceneOverrides,
    dir: &Path,
    s: &UpdateSettings,
    note: &mut dyn FnMut(GoldenNote<'_>),
) -> Result<Updated, Error> {
    let mut r = render_scene(path, overrides, s.block, s.threads, None, note)?;
    let mut floor = DetectionFloor::of(&r.batches, &r.cells, s.alpha).with_noise(r.noise);
    if let Some(target) = s.detect {
        let (w, h) = (r.estimates.width, r.estimates.height);
        let mut search = DetectSearch::new(target, s.alpha, s.detect_limit);
        while let DetectStep::Render(spp) = search.next(&floor, r.meta.spp, w, h) {
            let scale = &floor.scales[floor.detect_scale(w, h)];
            note(GoldenNote::Detect(format!(
                "{}: {} spp catch a change of {} % over {side}×{side} px (≈ {} % of the image), or a pattern change of ±{} % over {cell}×{cell} px cells, in 95 % of checks; measuring at {spp} spp",
                path.display(),
                r.meta.spp,
                report::number((1000.0 * scale.median).round() / 10.0),
                report::number(100.0 * floor::DETECT_AREA),
                report::number((1000.0 * floor.structure).round() / 10.0),
                side = scale.side,
                cell = floor.cell
            )));
            let mut more = overrides.clone();
            more.render.samples_per_pixel = Some(spp);
            let next = render_scene(path, &more, s.block, s.threads, None, note)?;
            let next_floor =
                DetectionFloor::of(&next.batches, &next.cells, s.alpha).with_noise(next.noise);
            let (was, now) = (
                search.reached(&floor, w, h),
                search.reached(&next_floor, w, h),
            );
            let kept = r.meta.spp;
            if search.keep_new(spp, kept, now) {
                r = next;
                floor = next_floor;
            }
            if search.stop_after(spp, kept, was, now) {
                break;
            }
        }
        if !search.reached(&floor, w, h) {
            note(GoldenNote::Detect(format!(
                "{}: warning: {} spp do not reach a floor of {} % over {side}×{side} px and over the structure test's cells (--detect-limit {})",
                path.display(),
                r.meta.spp,
                report::number(100.0 * target),
                s.detect_limit,
                side = floor.scales[floor.detect_scale(w, h)].side
            )));
        }
    }
    let target = dir.join(golden_file_name(path));
    let updated = Updated {
        target,
        size: (r.estimates.width, r.estimates.height),
        spp: r.meta.spp,
        integrator: r.meta.integrator.clone(),
        floor,
    };
    GoldenImage {
        estimates: r.estimates,
        batches: r.batches,
        cells: r.cells,
        meta: r.meta,
    }
    .write(&updated.target)?;
    Ok(updated)
}

/// Reads the golden of `path` from `golden_dir` and renders the scene again with its recorded
/// flags, a fresh seed and `own` on top ([`combined`]), in the golden's blocks.
///
/// # Errors
/// [`GoldenRefusal::Unreadable`], [`combined`]'s and [`render_scene`]'s.
pub fn check_scene(
    path: &Path,
    golden_dir: &Path,
    own: &SceneOverrides,
    threads: Option<usize>,
    note: &mut dyn FnMut(GoldenNote<'_>),
) -> Result<(GoldenImage, GoldenRun), Error> {
    let golden_path = golden_dir.join(golden_file_name(path));
    let golden = GoldenImage::read(&golden_path).map_err(|error| GoldenRefusal::Unreadable {
        scene: path.to_path_buf(),
        golden_dir: golden_dir.to_path_buf(),
        error,
    })?;
    let overrides = combined(&golden.meta, own, &golden_path)?;
    let block = golden.batches.block;
    let run = render_scene(
        path,
        &overrides,
        block,
        threads,
        Some(golden.meta.seed),
        note,
    )?;
    Ok((golden, run))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::settings::{IntegratorKind, SamplerKind};

    fn meta(overrides: &[(&str, &str)]) -> GoldenMeta {
        GoldenMeta {
            hash: 1,
            seed: 41,
            spp: 8,
            integrator: "Path".into(),
            sampler: "Sobol".into(),
            exposure: 1.0,
            scene: "s.ron".into(),
            overrides: overrides
                .iter()
                .map(|(k, v)| ((*k).to_string(), (*v).to_string()))
                .collect(),
            settings: Vec::new(),
        }
    }

    #[test]
    fn a_check_applies_the_recorded_flags_then_its_own_with_a_fresh_seed() {
        let mut update = SceneOverrides {
            sets: vec!["camera.fov_y=35".into()],
            ..SceneOverrides::default()
        };
        for f in [
            StatedFlag::Width(64),
            StatedFlag::Spp(16),
            StatedFlag::Seed(9),
            StatedFlag::CausticPhotons(500),
            StatedFlag::Integrator(IntegratorKind::PathPpm),
            StatedFlag::Sampler(SamplerKind::Independent),
        ] {
            update.state(f);
        }
        let recorded = record(&update);
        // As `golden update` wrote them before the flags had one list: the seed left out.
        let written: Vec<(&str, &str)> = recorded
            .iter()
            .map(|(k, v)| (k.as_str(), v.as_str()))
            .collect();
        assert_eq!(
            written,
            [
                ("set", "camera.fov_y=35"),
                ("width", "64"),
                ("spp", "16"),
                ("caustic_photons", "500"),
                ("integrator", "path-ppm"),
                ("sampler", "independent"),
            ]
        );
        let mut golden = meta(&[]);
        golden.overrides = recorded;
        let own = SceneOverrides {
            sets: vec!["render.max_depth=3".into()],
            render: crate::scene::schema::RenderSettings {
                width: Some(32),
                ..Default::default()
            },
            ..SceneOverrides::default()
        };
        let o = combined(&golden, &own, Path::new("g")).expect("applies");
        assert_eq!(o.sets, ["camera.fov_y=35", "render.max_depth=3"]);
        assert_eq!(o.render.width, Some(32));
        assert_eq!(o.render.samples_per_pixel, Some(16));
        assert_eq!(o.render.integrator, Some(IntegratorKind::PathPpm));
        assert_eq!(o.render.sampler, Some(SamplerKind::Independent));
        assert_eq!(o.photons.caustic, Some(500));
        assert_eq!(o.render.seed, Some(42));
    }

    #[test]
    fn recorded_flags_that_cannot_apply_name_the_golden_and_the_fix() {
        let text = |o: &[(&str, &str)]| {
            combined(
                &meta(o),
                &SceneOverrides::default(),
                Path::new("g/s.golden"),
            )
            .map(|_| ())
            .map_err(|e| e.to_string())
        };
        assert_eq!(
            text(&[("spp", "many")]),
            Err("error: `g/s.golden`: its recorded flag `spp=many` is malformed; run `caustic golden update` again".into())
        );
        assert_eq!(
            text(&[("integrator", "bdpt")]),
            Err("error: `g/s.golden`: its recorded flag `integrator=bdpt` names no such choice; run `caustic golden update` again".into())
        );
        // `update` never records the seed: a recorded one is as unknown as any other name.
        for key in ["seed", "tile"] {
            assert_eq!(
                text(&[(key, "3")]),
                Err(format!(
                    "error: `g/s.golden`: unknown recorded flag `{key}` (written by a newer caustic?); run `caustic golden update` again"
                ))
            );
        }
    }
}
