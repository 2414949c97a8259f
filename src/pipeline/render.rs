//! `caustic render`'s library half: a render request with its flags already parsed
//! ([`RenderRequest`]) taken through its phases — the scene prepared with the request's
//! overrides ([`RenderRequest::prepare`]), the render job started with the sample range of a
//! shard or `--samples` ([`PreparedRender::start`]: photon maps or the photon cache), the passes
//! under a time budget, target error, adaptive plan or checkpoints, the features and the
//! denoiser of `--denoise`, and the output written as an image, an image with layers or a
//! mergeable `.part` film ([`StartedRender::finish`]). The outcome ([`RenderedImage`]) holds the
//! film and says, in the command's words, what was rendered. The binary parses the flags, wires
//! Ctrl-C to the cancel flag and prints.

use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

pub use super::rendered::RenderedImage;
use super::rendered::reached_spp;
use super::{Prepared, SceneOverrides, prepare};
use crate::Error;
use crate::denoise::DenoiseParams;
use crate::farm::part_meta::settings_hash;
use crate::farm::{PartMeta, Shard};
use crate::render::adaptive::AdaptivePlan;
use crate::render::auto_exposure::{resolve, tonemap_for};
use crate::render::denoised::{FirstHalf, denoise_render};
use crate::render::output::{OutputFormat, write_image};
use crate::render::passes::{CheckpointPlan, PassPlan, render_in_passes};
use crate::render::tonemap::{Display, Tonemap};
use crate::render::{
    Features, Layer, LayerExtras, Region, RenderError, RenderJob, RenderOptions, write_with_extras,
    write_with_layers,
};
use crate::settings::IntegratorKind;

/// Samples per pixel a render under a time budget or a target error may reach when the
/// samples per pixel are not stated (they then only cap it).
pub const BUDGET_SPP_CAP: u32 = 1 << 20;

/// The share of a `--time` budget a denoised render's passes take: the features and the
/// denoiser follow them (on the bath at 800×600 and 8 spp they took 8 % and 9 % of the render).
pub const DENOISED_PASS_SHARE: f64 = 0.9;

/// Why a render request is refused, or what stopped it; each text names the flag (or scene
/// field) and what is valid. Converted into [`Error::Usage`] (and [`Error::Interrupted`]).
#[derive(Debug, thiserror::Error)]
pub enum RenderRefusal {
    /// `--shard` with an output that is not a `.part` film.
    #[error(
        "--shard writes the mergeable film: the output `{}` must end in `.part`, e.g. `-o shard-1.part`",
        .0.display()
    )]
    ShardNeedsPart(PathBuf),
    /// `--shard` malformed, or more shards than samples per pixel.
    #[error(transparent)]
    Shard(#[from] crate::farm::shard::ShardError),
    /// `render.adaptive` with an output or flag that splits the samples (named).
    #[error(
        "--adaptive (render.adaptive) cannot be used with {0}: an adaptive render decides each pixel's samples from all its earlier ones, so it cannot be split into sample ranges and merged; render without --adaptive, or render the whole image adaptively"
    )]
    AdaptiveSplit(&'static str),
    /// `--samples START..END` beyond the render's samples per pixel.
    #[error(
        "--samples {start}..{end}: the render has {spp} samples per pixel, so END must be at most {spp}"
    )]
    SamplesBeyond {
        /// First sample index asked for.
        start: u32,
        /// One past the last sample index asked for.
        end: u32,
        /// The render's samples per pixel.
        spp: u32,
    },
    /// `--denoise` of a render that takes fewer than 2 samples per pixel.
    #[error(
        "--denoise needs at least 2 samples per pixel (it compares two halves of them); this render takes {0}"
    )]
    DenoiseTooFewSamples(u32),
    /// The denoiser refused the render's buffers.
    #[error(transparent)]
    Denoise(#[from] crate::render::denoised::DenoiseRenderError),
    /// Ctrl-C (or SIGTERM): no image written; the text says what the checkpoint kept.
    #[error("{0}")]
    Interrupted(String),
}

impl From<RenderRefusal> for Error {
    fn from(e: RenderRefusal) -> Self {
        match e {
            RenderRefusal::Interrupted(text) => Error::Interrupted(text),
            other => Error::Usage(other.to_string()),
        }
    }
}

/// Whether `path` asks for the mergeable film (`.part`).
#[must_use]
pub fn is_part(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("part"))
}

/// Whether `path` is a linear EXR image (no exposure applies).
fn is_exr(path: &Path) -> bool {
    matches!(OutputFormat::for_path(path), Ok(OutputFormat::Exr))
}

/// The shard of `--shard` (`None` without it), after checking that the output is one caustic
/// writes and that a shard writes a `.part` film (`render` and `preview` share the rule).
///
/// # Errors
/// [`RenderRefusal::ShardNeedsPart`], an unknown output extension, or a malformed shard.
pub fn output_shard(output: &Path, shard: Option<&str>) -> Result<Option<Shard>, Error> {
    if !is_part(output) {
        if shard.is_some() {
            return Err(RenderRefusal::ShardNeedsPart(output.to_path_buf()).into());
        }
        OutputFormat::for_path(output)?;
    }
    Ok(shard
        .map(Shard::parse)
        .transpose()
        .map_err(RenderRefusal::from)?)
}

/// A render as `caustic render` asks for it, every flag parsed and checked on its own.
#[derive(Debug, Clone)]
pub struct RenderRequest {
    /// The scene file.
    pub scene: PathBuf,
    /// The command line's overrides of the scene.
    pub overrides: SceneOverrides,
    /// The output: `.png`, `.exr`, or `.part` for the mergeable film of per-pixel sums.
    pub output: PathBuf,
    /// Worker threads (`None`: all cores).
    pub threads: Option<usize>,
    /// The crop to render (`None`: the whole image).
    pub region: Option<Region>,
    /// Render in passes for this long, then write (`--time`).
    pub time: Option<Duration>,
    /// Where the image so far is saved between passes (`--checkpoint`).
    pub checkpoint: Option<PathBuf>,
    /// Time between checkpoints (zero: after every pass).
    pub checkpoint_every: Duration,
    /// The folder of the photon cache (`--photon-cache`).
    pub photon_cache: Option<PathBuf>,
    /// The shard of the samples to render (`--shard`).
    pub shard: Option<Shard>,
    /// The sample indices to render (`--samples`); takes precedence over `shard`.
    pub samples: Option<Range<u32>>,
    /// The layers to write besides the image, each once.
    pub layers: Vec<Layer>,
    /// Denoise the image (`--denoise`): asked for, so refused where it cannot apply.
    pub denoise: bool,
    /// Denoise a `.png` when the render allows it ([`RenderRequest::auto_denoise_refusal`]
    /// says when not): `caustic render`'s default, off with `--no-denoise`. EXR and `.part`
    /// outputs stay the linear estimate (an EXR holds both with `--denoise`).
    pub auto_denoise: bool,
    /// The image is scored against a reference (`--compare`): the default denoising leaves it
    /// the raw estimate, which a golden check expects.
    pub scored: bool,
    /// Linear exposure for 8-bit images (`--exposure`; `render.exposure`).
    pub exposure: Option<f32>,
    /// Stop once the estimated relMSE is at most this (`--target-error`).
    pub target_error: Option<f32>,
    /// Adaptive sampling (`--adaptive`).
    pub adaptive: bool,
    /// Draw progress bars on the terminal.
    pub progress: bool,
}

impl RenderRequest {
    /// The overrides the render compiles with: the command line's, the flags that are scene
    /// fields (`render.exposure`, `render.target_error`, `render.adaptive`), and, for a render
    /// that a budget or a target stops, [`BUDGET_SPP_CAP`] samples per pixel unless stated.
    fn overrides(&self) -> SceneOverrides {
        let mut overrides = self.overrides.clone();
        if let Some(x) = self.exposure {
            overrides.sets.push(format!("render.exposure={x:?}"));
        }
        if let Some(x) = self.target_error {
            overrides.sets.push(format!("render.target_error={x:?}"));
        }
        if self.adaptive {
            overrides.sets.push("render.adaptive=true".into());
        }
        // A budget or a target decides when to stop; the sample count only caps it.
        if (self.time.is_some() || self.target_error.is_some())
            && overrides.render.samples_per_pixel.is_none()
        {
            overrides.render.samples_per_pixel = Some(BUDGET_SPP_CAP);
        }
        overrides
    }

    /// Reads, overrides, validates and compiles the scene (again with [`BUDGET_SPP_CAP`] when
    /// the scene's own `render.target_error` decides when to stop), and refuses adaptive
    /// sampling with a split of the samples.
    ///
    /// # Errors
    /// The scene's errors; [`RenderRefusal::AdaptiveSplit`].
    pub fn prepare(&self) -> Result<PreparedRender<'_>, Error> {
        let mut overrides = self.overrides();
        let mut prepared = prepare(&self.scene, &overrides)?;
        let target_error = prepared.scene.render.target_error;
        if target_error.is_some() && overrides.render.samples_per_pixel.is_none() {
            // The scene's own `render.target_error`: compiled again with the cap (rare).
            overrides.render.samples_per_pixel = Some(BUDGET_SPP_CAP);
            prepared = prepare(&self.scene, &overrides)?;
        }
        let adaptive = prepared.scene.render.with_defaults().adaptive == Some(true);
        let spp = prepared.render_scene.params.samples_per_pixel;
        let png = matches!(OutputFormat::for_path(&self.output), Ok(OutputFormat::Png));
        let auto_skipped = (self.auto_denoise && !self.denoise && png)
            .then(|| self.auto_denoise_refusal(adaptive, spp))
            .flatten();
        let denoise = self.denoise || (self.auto_denoise && png && auto_skipped.is_none());
        if adaptive
            && let Some(why) = [
                (is_part(&self.output), "a `.part` output"),
                (self.samples.is_some(), "--samples"),
                (self.shard.is_some(), "--shard"),
                (self.denoise, "--denoise"),
            ]
            .iter()
            .find_map(|&(refused, name)| refused.then_some(name))
        {
            return Err(RenderRefusal::AdaptiveSplit(why).into());
        }
        Ok(PreparedRender {
            request: self,
            prepared,
            target_error,
            adaptive,
            denoise,
            auto_skipped,
        })
    }

    /// Why the default denoising ([`RenderRequest::auto_denoise`]) does not apply to this `.png`
    /// render, or `None` when it does: only the whole frame with every pixel taking the same
    /// samples is denoised by default. A crop keeps the full render's pixels; adaptive sampling
    /// gives its pixels different samples (the denoiser's two halves need the same split for
    /// all); a sample range is one part of a render; light layers add up to the raw image;
    /// checkpoints show the raw passes; `--compare` scores the raw estimate (see
    /// [`RenderRequest::scored`]); fewer than 2 samples per pixel cannot be split in
    /// halves (a render under `--time` or a target error is denoised when it reaches 2:
    /// [`crate::render::passes::PassPlan::halves`]). `spp` is the render's samples per pixel
    /// (the cap of an open-ended render).
    #[must_use]
    pub fn auto_denoise_refusal(&self, adaptive: bool, spp: u32) -> Option<&'static str> {
        [
            (self.region.is_some(), "--region"),
            (adaptive, "adaptive sampling"),
            (
                self.shard.is_some() || self.samples.is_some(),
                "a sample range",
            ),
            (
                self.layers.iter().any(|l| matches!(l, Layer::Part(_))),
                "light layers",
            ),
            (self.checkpoint.is_some(), "--checkpoint"),
            (self.scored, "--compare (it scores the raw estimate)"),
            (spp < 2, "fewer than 2 samples per pixel"),
        ]
        .iter()
        .find_map(|&(skipped, why)| skipped.then_some(why))
    }
}

/// A request whose scene is compiled: [`PreparedRender::start`] begins rendering it.
#[derive(Debug)]
pub struct PreparedRender<'q> {
    request: &'q RenderRequest,
    /// The compiled scene, its warnings and figures.
    pub prepared: Prepared,
    target_error: Option<f32>,
    adaptive: bool,
    /// Whether the image is denoised (asked for, or by default).
    denoise: bool,
    /// Why the default denoising does not apply, when it was on and does not.
    auto_skipped: Option<&'static str>,
}

impl<'q> PreparedRender<'q> {
    /// Whether a time budget or a target error decides when the render stops (its samples per
    /// pixel are then not known in advance).
    fn open_ended(&self) -> bool {
        self.request.time.is_some() || self.target_error.is_some()
    }

    /// Whether the image will be denoised: `--denoise`, or by default where the render allows it.
    #[must_use]
    pub fn denoises(&self) -> bool {
        self.denoise
    }

    /// Why the default denoising does not apply to this `.png` render
    /// ([`RenderRequest::auto_denoise_refusal`]); `None` when it applies, was turned off, was
    /// asked for by `--denoise`, or the output is not a `.png`.
    #[must_use]
    pub fn auto_denoise_skipped(&self) -> Option<&'static str> {
        self.auto_skipped
    }

    /// Resolves the sample range (of `--samples`, else of the shard), and starts the render job
    /// (photon maps traced or read from the cache); `cancel` is the flag the render polls.
    ///
    /// # Errors
    /// [`RenderRefusal::SamplesBeyond`], a shard with more parts than samples,
    /// [`RenderRefusal::DenoiseTooFewSamples`]; [`RenderRefusal::Interrupted`] when cancelled
    /// while tracing photons; the job's errors.
    pub fn start(&self, cancel: Arc<AtomicBool>) -> Result<StartedRender<'_, 'q>, Error> {
        let request = self.request;
        let prepared = &self.prepared;
        // `None`: automatic, chosen from the finished film (`auto_exposure`).
        let stated_exposure = prepared.scene.render.exposure;
        let exposure = prepared.render_scene.params.exposure;
        let tonemap = tonemap_for(stated_exposure, prepared.scene.render.tonemap);
        let spp = prepared.render_scene.params.samples_per_pixel;
        let samples = match &request.samples {
            Some(r) if r.end > spp => {
                return Err(RenderRefusal::SamplesBeyond {
                    start: r.start,
                    end: r.end,
                    spp,
                }
                .into());
            }
            Some(r) => Some(r.clone()),
            None => request
                .shard
                .map(|s| s.samples(spp))
                .transpose()
                .map_err(RenderRefusal::from)?,
        };
        let options = RenderOptions {
            threads: request.threads,
            region: request.region,
            progress: request.progress && request.time.is_none(),
            cancel: Some(cancel),
            photon_cache: request.photon_cache.clone(),
            samples: samples.clone(),
            light_paths: self.denoise || request.layers.iter().any(|l| matches!(l, Layer::Part(_))),
        };
        let taken = samples.clone().unwrap_or(0..spp);
        // `--denoise`: the samples below `split` are the first half-buffer. A render that a
        // time budget or a target error stops keeps its first half at a pass end instead
        // (`PassPlan::halves`), chosen when it stops.
        let split = taken.start + (taken.end - taken.start) / 2;
        if self.denoise && !self.open_ended() && split == taken.start {
            return Err(RenderRefusal::DenoiseTooFewSamples(taken.end - taken.start).into());
        }
        let job = match RenderJob::new(&prepared.render_scene, &options) {
            // Ctrl-C during photon tracing.
            Err(RenderError::Cancelled) => {
                return Err(
                    RenderRefusal::Interrupted("interrupted: no image written".into()).into(),
                );
            }
            other => other?,
        };
        Ok(StartedRender {
            prepared: self,
            job,
            options,
            display: Display { exposure, tonemap },
            stated_exposure,
            tonemap,
            spp,
            samples,
            taken,
            split,
        })
    }
}

/// A render job started: its photon maps are ready; [`StartedRender::finish`] renders.
pub struct StartedRender<'p, 'q> {
    prepared: &'p PreparedRender<'q>,
    job: RenderJob<'p>,
    options: RenderOptions,
    display: Display,
    stated_exposure: Option<f32>,
    tonemap: Tonemap,
    spp: u32,
    samples: Option<Range<u32>>,
    taken: Range<u32>,
    split: u32,
}

/// What a render did on the way, as it happens, for the command to print.
#[derive(Debug)]
pub enum RenderNote {
    /// The features (albedo, normal, depth) were traced in this time.
    FeaturesTraced(Duration),
    /// The image was denoised in this time.
    Denoised(Duration),
    /// The image was not denoised after all: a time budget or target error stopped the render
    /// before 2 samples per pixel (the text says so); the raw image is written.
    NotDenoised(String),
    /// The checkpoint file could not be removed after the final image was written.
    CheckpointKept(PathBuf, std::io::Error),
}

impl<'p> StartedRender<'p, '_> {
    /// Why the default estimator was chosen (`None` when the scene or the command line named
    /// the integrator), e.g. `path: no specular caster, no photon pass`.
    #[must_use]
    pub fn default_estimator(&self) -> Option<String> {
        let p = &self.prepared.prepared.render_scene.params;
        p.default_estimator
            .as_ref()
            .map(|why| why.describe(p.integrator))
    }

    /// The photon maps' summary line, for an integrator that keeps photon maps.
    #[must_use]
    pub fn photon_maps_summary(&self) -> Option<String> {
        self.job
            .integrator()
            .photon_maps()
            .map(|m| m.summary.to_string())
    }

    /// The `--photon-cache` folder when the integrator keeps no photon maps to cache (the
    /// cache is then ignored).
    #[must_use]
    pub fn ignored_photon_cache(&self) -> Option<&Path> {
        self.prepared
            .request
            .photon_cache
            .as_deref()
            .filter(|_| self.job.integrator().photon_maps().is_none())
    }

    /// The integrator rendering.
    #[must_use]
    pub fn integrator(&self) -> IntegratorKind {
        self.prepared.prepared.render_scene.params.integrator
    }

    /// Renders (the first half apart for `--denoise`), traces the features and denoises when
    /// asked, and writes the output: the `.part` film with its [`PartMeta`], the image with its
    /// layers and features, or the image; then removes the checkpoint. `note` hears of each
    /// step that took time as it ends.
    ///
    /// # Errors
    /// [`RenderRefusal::Interrupted`] when the cancel flag was raised (no output written; the
    /// text names the checkpoint kept); the render's, denoiser's and writers' errors.
    pub fn finish(mut self, note: &mut dyn FnMut(RenderNote)) -> Result<RenderedImage, Error> {
        let request = self.prepared.request;
        let scene = &self.prepared.prepared.render_scene;
        let (spp, taken, split) = (self.spp, self.taken.clone(), self.split);
        let output = &request.output;
        let plan = PassPlan {
            checkpoint: request.checkpoint.as_deref().map(|path| CheckpointPlan {
                path,
                every: request.checkpoint_every,
                display: self.display,
                auto_exposure: self.stated_exposure.is_none(),
            }),
            // Denoised, the features and the denoiser come after the passes: they get the
            // budget's last tenth (docs/denoise.md measures what they take).
            time_budget: request.time.map(|t| {
                if self.prepared.denoise {
                    t.mul_f64(DENOISED_PASS_SHARE)
                } else {
                    t
                }
            }),
            progress: request.progress,
            target_error: self.prepared.target_error.map(f64::from),
            adaptive: self
                .prepared
                .adaptive
                .then(|| AdaptivePlan::new(self.prepared.target_error.map(f64::from), spp)),
            halves: self.prepared.denoise && self.prepared.open_ended(),
        };
        let first_half = if self.prepared.denoise && !plan.halves {
            match self.job.render_pass(split - taken.start) {
                Err(RenderError::Cancelled) => {
                    return Err(
                        RenderRefusal::Interrupted("interrupted: no image written".into()).into(),
                    );
                }
                other => other?,
            }
            Some(FirstHalf {
                sums: self.job.sums().clone(),
                parts: self.job.parts().map(<[_]>::to_vec),
            })
        } else {
            None
        };
        let mut outcome = render_in_passes(self.job, &plan);
        let saved = outcome.checkpoint_spp;
        // An open-ended render (a time budget or a target error) took the samples that fitted:
        // the features follow those, and its first half is the pass end the passes kept.
        let (first_half, taken, split) = if self.prepared.open_ended() {
            let reached = outcome
                .result
                .as_ref()
                .map_or(0, |out| reached_spp(out) as u32);
            let taken = taken.start..taken.start + reached;
            match outcome.first_half.take() {
                Some((n, half)) => (Some(half), taken.clone(), taken.start + n),
                None => {
                    if plan.halves && outcome.result.is_ok() {
                        note(RenderNote::NotDenoised(format!(
                            "the render stopped at {reached} sample per pixel; the denoiser compares two halves of at least 2"
                        )));
                    }
                    (None, taken.clone(), taken.start + reached / 2)
                }
            }
        } else {
            (first_half, taken, split)
        };
        let interrupted = || {
            let kept = match (&request.checkpoint, saved) {
                (Some(cp), Some(n)) => format!(
                    " to `{}`; `{}` holds the last complete checkpoint ({n} of {spp} samples per pixel)",
                    output.display(),
                    cp.display()
                ),
                _ => String::new(),
            };
            Error::from(RenderRefusal::Interrupted(format!(
                "interrupted: no image written{kept}"
            )))
        };
        let out = match outcome.result {
            Err(RenderError::Cancelled) => return Err(interrupted()),
            other => other?,
        };
        let cancel = self.options.cancel.as_deref();
        // A signal that came after the last tile still means "stop": the output is not written.
        if cancel.is_some_and(|c| c.load(Ordering::SeqCst)) {
            return Err(interrupted());
        }
        let trace_features = first_half.is_some() || request.layers.iter().any(|l| l.is_feature());
        let features = if trace_features {
            let started = Instant::now();
            let traced = Features::trace(
                scene,
                request.region,
                taken.clone(),
                split,
                request.threads,
                cancel,
            );
            let f = match traced {
                Err(RenderError::Cancelled) => return Err(interrupted()),
                other => other?,
            };
            note(RenderNote::FeaturesTraced(started.elapsed()));
            Some(f)
        } else {
            None
        };
        let denoised = match (&first_half, &features) {
            (Some(first), Some(f)) => {
                let started = Instant::now();
                let film = denoise_render(
                    &out.sums,
                    out.parts.as_deref(),
                    first,
                    f,
                    &DenoiseParams::default(),
                    request.threads,
                )
                .map_err(RenderRefusal::from)?;
                note(RenderNote::Denoised(started.elapsed()));
                Some(film)
            }
            _ => None,
        };
        // The display of 8-bit outputs: the stated exposure, else the finished film's own.
        let (display, auto) = resolve(
            denoised.as_ref().unwrap_or(&out.film),
            self.stated_exposure,
            self.tonemap,
        );
        let part = is_part(output);
        let auto = auto.filter(|_| !part && !is_exr(output));
        if part {
            let first_sample = self.samples.as_ref().map_or(0, |r| r.start);
            let end = first_sample + reached_spp(&out) as u32;
            let meta = PartMeta {
                // NaN: automatic (`merge` then chooses it from the merged film).
                exposure: self.stated_exposure.unwrap_or(f32::NAN),
                scene: request.scene.display().to_string(),
                shard: request.shard.map(|s| s.to_string()),
                seconds: out.stats.elapsed.as_secs_f64(),
                ..PartMeta::of(
                    scene,
                    settings_hash(scene),
                    first_sample..end,
                    spp,
                    request.region,
                )
            };
            out.sums.write(output, &meta.to_text())?;
        } else if features.is_some() || denoised.is_some() {
            let extras = LayerExtras {
                features: features.as_ref(),
                denoised: denoised.as_ref(),
            };
            write_with_extras(
                &out.sums,
                out.parts.as_deref(),
                extras,
                &request.layers,
                output,
                display,
            )?;
        } else if !request.layers.is_empty() {
            write_with_layers(
                &out.sums,
                out.parts.as_deref(),
                &request.layers,
                output,
                display,
            )?;
        } else {
            write_image(&out.film, output, display)?;
        }
        if let (Some(cp), Some(_)) = (&request.checkpoint, saved)
            && let Err(e) = std::fs::remove_file(cp)
        {
            note(RenderNote::CheckpointKept(cp.clone(), e));
        }
        let p = &scene.params;
        Ok(RenderedImage {
            output: output.clone(),
            out,
            denoised,
            display,
            auto_exposure: auto,
            error: outcome.error,
            target_error: self.prepared.target_error,
            adaptive: self.prepared.adaptive,
            samples: self.samples,
            spp,
            integrator: p.integrator,
            default_estimator: p.default_estimator.is_some(),
            sampler: p.sampler,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::render;
    use crate::scene::schema::RenderSettings;

    /// A crate user's render through the request's phases writes the very bytes of the plain
    /// [`render`] written by [`write_image`], and says so in the command's words.
    #[test]
    fn a_request_renders_the_plain_render_and_names_it() {
        let dir = tempfile::tempdir().expect("temp dir");
        let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell.ron");
        let overrides = SceneOverrides {
            render: RenderSettings {
                width: Some(8),
                height: Some(6),
                samples_per_pixel: Some(2),
                integrator: Some(IntegratorKind::Path),
                ..RenderSettings::default()
            },
            ..SceneOverrides::default()
        };
        let request = RenderRequest {
            scene: scene.clone(),
            overrides: overrides.clone(),
            output: dir.path().join("a.exr"),
            threads: Some(1),
            region: None,
            time: None,
            checkpoint: None,
            checkpoint_every: Duration::ZERO,
            photon_cache: None,
            shard: None,
            samples: None,
            layers: Vec::new(),
            denoise: false,
            auto_denoise: false,
            scored: false,
            exposure: None,
            target_error: None,
            adaptive: false,
            progress: false,
        };
        let prepared = request.prepare().expect("prepares");
        let started = prepared
            .start(Arc::new(AtomicBool::new(false)))
            .expect("starts");
        assert_eq!(started.default_estimator(), None);
        assert_eq!(started.photon_maps_summary(), None);
        let done = started
            .finish(&mut |note| panic!("nothing to note: {note:?}"))
            .expect("renders");
        let plain = prepare(&scene, &overrides).expect("prepares");
        let options = RenderOptions {
            threads: Some(1),
            ..RenderOptions::default()
        };
        let out = render(&plain.render_scene, &options).expect("renders");
        let b = dir.path().join("b.exr");
        write_image(&out.film, &b, plain.render_scene.params.exposure).expect("writes");
        let read = |p: &Path| std::fs::read(p).expect("read");
        assert_eq!(read(&request.output), read(&b));
        assert_eq!(done.reached_spp(), 2);
        let summary = done.summary();
        let expected = format!(
            "{}: 8×6, 2 spp, Path integrator, Sobol sampler, ",
            request.output.display()
        );
        assert!(summary.starts_with(&expected), "{summary}");
        assert!(summary.ends_with(", 1 thread)"), "{summary}");
        assert_eq!(done.adaptive_summary(), None);
        assert_eq!(done.target_error_summary(), None);
        assert!(done.auto_exposure.is_none(), "EXR output stays linear");
    }

    #[test]
    fn refusals_name_the_flag_and_what_is_valid() {
        let out = Path::new("x.png");
        let e = output_shard(out, Some("1/2")).expect_err("a shard writes a .part");
        assert_eq!(
            e.to_string(),
            "error: --shard writes the mergeable film: the output `x.png` must end in `.part`, e.g. `-o shard-1.part`"
        );
        assert_eq!(e.exit_code(), 2);
        assert!(is_part(Path::new("s.PART")) && !is_part(out));
        assert_eq!(
            output_shard(Path::new("s.part"), Some("2/3")).expect("parses"),
            Some(Shard { index: 2, count: 3 })
        );
        let interrupted = Error::from(RenderRefusal::Interrupted("interrupted".into()));
        assert_eq!(interrupted.exit_code(), 130);
    }
}
