//! `caustic render`: render a scene to an image, in passes (checkpoints, time budgets), with
//! Ctrl-C handling and atomic output.

use std::io::IsTerminal;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use clap::Args;

use caustic::Error;
use caustic::farm::part_meta::settings_hash;
use caustic::farm::{PartMeta, Shard};
use caustic::pipeline::prepare;
use caustic::render::auto_exposure::{resolve, tonemap_for};
use caustic::render::output::{OutputFormat, write_image};
use caustic::render::passes::{CheckpointPlan, PassPlan, render_in_passes};
use caustic::render::tonemap::Display;
use caustic::render::{Layer, Region, RenderError, RenderJob, RenderOptions, write_with_layers};
use caustic::render::{LayerExtras, write_with_extras};

use super::same_file::same_file;
use super::{SceneArgs, count, layers_flag, print_warnings};

/// Samples per pixel a `--time` render may reach when `--spp` is not given.
pub(super) const BUDGET_SPP_CAP: u32 = 1 << 20;

/// Arguments of `caustic render`.
#[derive(Args)]
pub struct RenderArgs {
    #[command(flatten)]
    pub(super) scene: SceneArgs,
    /// Output image (.png, .exr, or .part for the mergeable film of per-pixel sums); default:
    /// the scene's name with .png in the current directory.
    #[arg(short, long)]
    pub(super) output: Option<PathBuf>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub(super) threads: Option<usize>,
    /// Render only the crop X,Y,W,H (pixels from the top-left); its pixels equal the full render's.
    #[arg(long, value_name = "X,Y,W,H")]
    pub(super) region: Option<String>,
    /// No progress bar and no warnings.
    #[arg(short, long)]
    pub(super) quiet: bool,
    /// Print scene and BVH statistics.
    #[arg(long)]
    pub(super) stats: bool,
    /// Render for this long (e.g. `30s`, `2m`, `1.5h`, or seconds), in passes of samples per
    /// pixel, then write the image; the summary says how many samples per pixel it reached.
    /// `--spp`, if given, still caps the samples.
    #[arg(long, value_name = "DURATION", value_parser = parse_duration)]
    pub(super) time: Option<Duration>,
    /// Render in passes of samples per pixel and save the image so far to FILE (.png or .exr,
    /// not the output) after a pass once `--checkpoint-every` seconds have passed since the last
    /// save. Ctrl-C
    /// leaves the last complete checkpoint there; it is removed once the final image is written.
    /// The final image is the same, bit for bit, as without checkpoints.
    #[arg(long, value_name = "FILE")]
    pub(super) checkpoint: Option<PathBuf>,
    /// After writing the image, compare it with this reference (PNG or EXR; for a `--region`
    /// render the reference may be the whole image or the crop) and print RMSE, relMSE, mean
    /// absolute error and bias.
    #[arg(long, value_name = "REF")]
    pub(super) compare: Option<PathBuf>,
    /// With `--compare`: a golden-image check: exit with code 3 (the image is still written)
    /// when the RMSE against the reference is above this.
    #[arg(long, value_name = "RMSE", requires = "compare", value_parser = parse_max_rmse)]
    pub(super) max_rmse: Option<f64>,
    /// Time between checkpoints: seconds, or with a unit (`90s`, `5m`); 0: after every pass.
    #[arg(
        long,
        value_name = "DURATION",
        default_value = "30",
        requires = "checkpoint",
        value_parser = parse_seconds
    )]
    pub(super) checkpoint_every: Duration,
    /// Keep the photon maps in this folder and reuse them while only the camera, the image
    /// size or the samples change (photon integrator; a corrupt file is rebuilt).
    #[arg(long, value_name = "DIR")]
    pub(super) photon_cache: Option<PathBuf>,
    /// Render only shard I of N (numbered from 1): the sample indices ⌊(I−1)·S/N⌋ to
    /// ⌊I·S/N⌋ − 1 of every pixel (S: samples per pixel), into the mergeable film (the output
    /// must end in `.part`). `caustic merge` joins the shards into the image of one render.
    #[arg(long, value_name = "I/N", conflicts_with = "compare")]
    pub(super) shard: Option<String>,
    /// Render only the sample indices START to END − 1 of every pixel (of the render's
    /// samples per pixel): with a `.part` output, a shard of your own choosing; as an image,
    /// what merging such parts gives.
    #[arg(long, value_name = "START..END", conflicts_with_all = ["compare", "shard"], value_parser = parse_samples)]
    pub(super) samples: Option<Range<u32>>,
    /// Also write these layers, comma-separated: specular (emitters and background seen
    /// directly or through mirrors and glass), direct (light after one diffuse or glossy
    /// bounce), caustic (light through mirrors or glass onto a diffuse surface), indirect (two
    /// or more bounces), variance (of each pixel's mean), samples (per pixel); `all` for every
    /// one. The four light kinds add up to the image. An `.exr` output holds them as channels
    /// beside the image; a `.png` output gets each light kind as a picture of its own beside
    /// it, tone-mapped like the image (`-o out.png --layers direct,caustic` also writes
    /// `out.direct.png` and `out.caustic.png`; variance and samples need an `.exr`).
    #[arg(long, value_name = "LIST", value_delimiter = ',', value_parser = parse_layers)]
    pub(super) layers: Vec<Vec<Layer>>,
    /// Denoise the image (docs/denoise.md): a feature-guided filter that keeps caustics. The
    /// render is taken in two halves of its samples per pixel (at least 2) and albedo, normal
    /// and depth are traced beside it. A `.png` output is the denoised image; an `.exr` holds
    /// the denoised image and the noisy one as the `noisy` layer. Not with `--time` (the
    /// halves need the samples per pixel in advance) or a `.part` output.
    #[arg(long, conflicts_with_all = ["time", "shard"])]
    pub(super) denoise: bool,
    /// Linear scale of radiance for 8-bit images (`render.exposure`). Unset, and not in the
    /// scene: chosen from the rendered image (Reinhard et al.'s key 0.18 over the log-average
    /// luminance, lowered so at most 1 % of the pixels clip); the summary prints it. EXR and
    /// `.part` outputs stay linear.
    #[arg(long, value_name = "X", value_parser = parse_positive)]
    pub(super) exposure: Option<f32>,
    /// Render pass after pass until the estimated relMSE of the image (from each pixel's
    /// sample variance) is at most X, e.g. `0.01` (`render.target_error`); `--time` and
    /// `--spp`, if given, still stop it first. The summary states the estimate reached.
    #[arg(long, value_name = "X", value_parser = parse_positive)]
    pub(super) target_error: Option<f32>,
    /// Adaptive sampling (`render.adaptive`): after 8 uniform samples per pixel each pixel takes
    /// more only while its estimated error is above `--target-error` (unset: 0.002); `--spp`
    /// caps every pixel. Not with `--shard`, `--samples`, `--denoise` or a `.part` output.
    #[arg(long)]
    pub(super) adaptive: bool,
}

/// A positive finite number (`--exposure`, `--target-error`).
fn parse_positive(text: &str) -> Result<f32, String> {
    text.trim()
        .parse::<f32>()
        .ok()
        .filter(|v| v.is_finite() && *v > 0.0)
        .ok_or_else(|| format!("expected a positive number such as `0.5`, found `{text}`"))
}

fn parse_layers(text: &str) -> Result<Vec<Layer>, String> {
    if text.trim().eq_ignore_ascii_case("all") {
        return Ok(Layer::ALL.to_vec());
    }
    Layer::parse(text)
        .map(|l| vec![l])
        .map_err(|e| e.to_string())
}

fn parse_samples(text: &str) -> Result<Range<u32>, String> {
    text.split_once("..")
        .and_then(|(a, b)| Some(a.trim().parse::<u32>().ok()?..b.trim().parse::<u32>().ok()?))
        .filter(|r| !r.is_empty())
        .ok_or_else(|| {
            format!(
                "expected START..END with whole numbers START < END, e.g. `0..16`, found `{text}`"
            )
        })
}

fn parse_max_rmse(text: &str) -> Result<f64, String> {
    text.trim()
        .parse::<f64>()
        .ok()
        .filter(|v| v.is_finite() && *v >= 0.0)
        .ok_or_else(|| format!("expected a non-negative number, found `{text}`"))
}

fn parse_seconds(text: &str) -> Result<Duration, String> {
    if text.trim().parse::<f64>().is_ok_and(|s| s == 0.0) {
        return Ok(Duration::ZERO);
    }
    parse_duration(text).map_err(|_| {
        format!(
            "expected seconds or a duration such as `30`, `90s` or `5m` (0: after every pass), found `{text}`"
        )
    })
}

/// A duration such as `30s`, `2m`, `1.5h`, `250ms` or a bare number of seconds; positive.
pub(super) fn parse_duration(text: &str) -> Result<Duration, String> {
    let t = text.trim();
    let (number, unit) = match t.find(|c: char| c.is_ascii_alphabetic()) {
        Some(i) => t.split_at(i),
        None => (t, "s"),
    };
    let scale = match unit {
        "ms" => 1e-3,
        "s" => 1.0,
        "m" | "min" => 60.0,
        "h" => 3600.0,
        _ => f64::NAN,
    };
    number
        .trim()
        .parse::<f64>()
        .ok()
        .map(|n| n * scale)
        .filter(|s| *s > 0.0)
        .and_then(|s| Duration::try_from_secs_f64(s).ok())
        .ok_or_else(|| {
            format!("expected a positive duration such as `30s`, `2m` or `1.5h`, found `{text}`")
        })
}

/// Parses `X,Y,W,H` (the form of `--region`).
pub(super) fn parse_region(text: &str) -> Result<Region, Error> {
    let parts: Vec<Result<u32, _>> = text.split(',').map(|p| p.trim().parse::<u32>()).collect();
    match parts.as_slice() {
        [Ok(x), Ok(y), Ok(w), Ok(h)] => Ok(Region {
            x: *x,
            y: *y,
            width: *w,
            height: *h,
        }),
        _ => Err(Error::Usage(format!(
            "--region `{text}`: expected four non-negative integers X,Y,W,H, e.g. `--region 64,64,128,128`"
        ))),
    }
}

pub(super) fn default_output(scene: &Path) -> PathBuf {
    let stem = scene
        .file_stem()
        .map_or_else(|| "render".into(), |s| s.to_string_lossy().into_owned());
    PathBuf::from(format!("{stem}.png"))
}

/// Whether `path` is a linear EXR image (no exposure applies).
fn is_exr(path: &Path) -> bool {
    matches!(OutputFormat::for_path(path), Ok(OutputFormat::Exr))
}

/// The shard of `--shard` (`None` without it), after checking that the output is one caustic
/// writes and that a shard writes a `.part` film (`render` and `preview` share the rule).
pub(super) fn output_shard(output: &Path, shard: Option<&str>) -> Result<Option<Shard>, Error> {
    if !is_part(output) {
        if shard.is_some() {
            return Err(Error::Usage(format!(
                "--shard writes the mergeable film: the output `{}` must end in `.part`, e.g. `-o shard-1.part`",
                output.display()
            )));
        }
        OutputFormat::for_path(output)?;
    }
    shard
        .map(Shard::parse)
        .transpose()
        .map_err(|e| Error::Usage(e.to_string()))
}

/// Whether `path` asks for the mergeable film (`.part`).
pub(super) fn is_part(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("part"))
}

/// Ctrl-C (and, on unix, SIGTERM/SIGHUP) for `caustic render`: before the render starts it ends
/// the process at once (nothing has been written yet); from then on it raises the cancel flag
/// the render polls, so the run can stop cleanly without writing the output.
struct Interrupt {
    rendering: Arc<AtomicBool>,
    cancel: Arc<AtomicBool>,
}

impl Interrupt {
    fn install(quiet: bool) -> Self {
        let rendering = Arc::new(AtomicBool::new(false));
        let cancel = Arc::new(AtomicBool::new(false));
        let (r, c) = (Arc::clone(&rendering), Arc::clone(&cancel));
        let installed = ctrlc::set_handler(move || {
            if r.load(Ordering::SeqCst) {
                c.store(true, Ordering::SeqCst);
            } else {
                eprintln!("interrupted: no image written");
                std::process::exit(130);
            }
        });
        if let Err(e) = installed
            && !quiet
        {
            eprintln!("warning: cannot catch Ctrl-C ({e}); interrupting will not clean up");
        }
        Self { rendering, cancel }
    }

    /// From now on a signal cancels the render instead of ending the process.
    fn start_rendering(&self) -> Arc<AtomicBool> {
        self.rendering.store(true, Ordering::SeqCst);
        Arc::clone(&self.cancel)
    }

    fn raised(&self) -> bool {
        self.cancel.load(Ordering::SeqCst)
    }
}

/// Renders the scene and writes the image (or the mergeable film).
pub fn run(args: &RenderArgs) -> Result<(), Error> {
    let interrupt = Interrupt::install(args.quiet);
    let output = args
        .output
        .clone()
        .unwrap_or_else(|| default_output(&args.scene.scene));
    // Refuse a bad output name before doing any work.
    let shard = output_shard(&output, args.shard.as_deref())?;
    if let Some(cp) = &args.checkpoint {
        if OutputFormat::for_path(cp).is_err() {
            return Err(Error::Usage(format!(
                "--checkpoint `{}`: the checkpoint must end in `.png` or `.exr`",
                cp.display()
            )));
        }
        if same_file(cp, &output) {
            return Err(Error::Usage(format!(
                "--checkpoint `{}` is the output file; give it a name of its own",
                cp.display()
            )));
        }
    }
    // Refuse an output (or checkpoint) that cannot be written before doing any work.
    for path in std::iter::once(&output).chain(&args.checkpoint) {
        caustic::render::output::check_writable(path)?;
    }
    let layers = layers_flag::listed(&args.layers);
    if args.denoise && is_part(&output) {
        return Err(Error::Usage(format!(
            "--denoise writes an image: the output `{}` must end in `.png` or `.exr`, not `.part`",
            output.display()
        )));
    }
    let trace_features = args.denoise || layers_flag::features_needed(&layers);
    let pictures = layers_flag::check(&output, &layers, args.checkpoint.as_deref())?;
    let region = args.region.as_deref().map(parse_region).transpose()?;
    let reference = super::max_rmse::load(args.compare.as_deref())?;
    if args.threads == Some(0) {
        return Err(Error::Usage("--threads must be at least 1".into()));
    }
    let mut overrides = args.scene.overrides();
    if let Some(x) = args.exposure {
        overrides.sets.push(format!("render.exposure={x:?}"));
    }
    if let Some(x) = args.target_error {
        overrides.sets.push(format!("render.target_error={x:?}"));
    }
    if args.adaptive {
        overrides.sets.push("render.adaptive=true".into());
    }
    // A budget or a target decides when to stop; the sample count only caps it.
    if (args.time.is_some() || args.target_error.is_some())
        && overrides.render.samples_per_pixel.is_none()
    {
        overrides.render.samples_per_pixel = Some(BUDGET_SPP_CAP);
    }
    let mut prepared = prepare(&args.scene.scene, &overrides)?;
    let target_error = prepared.scene.render.target_error;
    if target_error.is_some() && overrides.render.samples_per_pixel.is_none() {
        // The scene's own `render.target_error`: compiled again with the cap (rare).
        overrides.render.samples_per_pixel = Some(BUDGET_SPP_CAP);
        prepared = prepare(&args.scene.scene, &overrides)?;
    }
    let adaptive = prepared.scene.render.with_defaults().adaptive == Some(true);
    if adaptive
        && let Some(why) = [
            (is_part(&output), "a `.part` output"),
            (args.samples.is_some(), "--samples"),
            (args.shard.is_some(), "--shard"),
            (args.denoise, "--denoise"),
        ]
        .iter()
        .find_map(|&(refused, name)| refused.then_some(name))
    {
        return Err(Error::Usage(format!(
            "--adaptive (render.adaptive) cannot be used with {why}: an adaptive render decides each pixel's samples from all its earlier ones, so it cannot be split into sample ranges and merged; render without --adaptive, or render the whole image adaptively"
        )));
    }
    if !args.quiet {
        print_warnings(&prepared.warnings);
    }
    if args.stats {
        print_stats(&prepared.stats);
    }
    if let Some(reference) = &reference {
        let p = &prepared.render_scene.params;
        super::max_rmse::check_size(reference, p.width, p.height, region)?;
    }
    // `None`: automatic, chosen from the finished film (`auto_exposure`).
    let stated_exposure = prepared.scene.render.exposure;
    let exposure = prepared.render_scene.params.exposure;
    let tonemap = tonemap_for(stated_exposure, prepared.scene.render.tonemap);
    let display = Display { exposure, tonemap };
    let spp = prepared.render_scene.params.samples_per_pixel;
    let samples = match &args.samples {
        Some(r) if r.end > spp => {
            return Err(Error::Usage(format!(
                "--samples {}..{}: the render has {spp} samples per pixel, so END must be at most {spp}",
                r.start, r.end
            )));
        }
        Some(r) => Some(r.clone()),
        None => shard
            .map(|s| s.samples(spp))
            .transpose()
            .map_err(|e| Error::Usage(e.to_string()))?,
    };
    let first_sample = samples.as_ref().map_or(0, |r| r.start);
    let samples_taken = samples.clone();
    let hash = is_part(&output).then(|| settings_hash(&prepared.render_scene));
    let terminal = !args.quiet && std::io::stderr().is_terminal();
    let options = RenderOptions {
        threads: args.threads,
        region,
        progress: terminal && args.time.is_none(),
        cancel: Some(interrupt.start_rendering()),
        photon_cache: args.photon_cache.clone(),
        samples: samples_taken,
        light_paths: args.denoise || layers.iter().any(|l| matches!(l, Layer::Part(_))),
    };
    let taken = samples.clone().unwrap_or(0..spp);
    // `--denoise`: the samples below `split` are the first half-buffer.
    let split = taken.start + (taken.end - taken.start) / 2;
    if args.denoise && split == taken.start {
        return Err(Error::Usage(format!(
            "--denoise needs at least 2 samples per pixel (it compares two halves of them); this render takes {}",
            taken.end - taken.start
        )));
    }
    let mut job = match RenderJob::new(&prepared.render_scene, &options) {
        // Ctrl-C during photon tracing.
        Err(RenderError::Cancelled) => {
            return Err(Error::Interrupted("interrupted: no image written".into()));
        }
        other => other?,
    };
    if !args.quiet
        && let Some(why) = &prepared.render_scene.params.default_estimator
    {
        // The scene and the command line named no integrator: which one, and why.
        eprintln!(
            "default estimator {}",
            why.describe(prepared.render_scene.params.integrator)
        );
    }
    let maps = job.integrator().photon_maps();
    if !args.quiet
        && let Some(maps) = maps
    {
        eprintln!("{}", maps.summary);
    }
    if !args.quiet
        && maps.is_none()
        && let Some(dir) = &args.photon_cache
    {
        eprintln!(
            "warning: --photon-cache `{}` is ignored: the {:?} integrator keeps no photon maps to cache (only `--integrator photon` does; ppm and path-ppm trace fresh maps every pass)",
            dir.display(),
            prepared.render_scene.params.integrator
        );
    }
    let plan = PassPlan {
        checkpoint: args.checkpoint.as_deref().map(|path| CheckpointPlan {
            path,
            every: args.checkpoint_every,
            display,
            auto_exposure: stated_exposure.is_none(),
        }),
        time_budget: args.time,
        progress: terminal,
        target_error: target_error.map(f64::from),
        adaptive: adaptive.then(|| {
            caustic::render::adaptive::AdaptivePlan::new(target_error.map(f64::from), spp)
        }),
    };
    let first_half = if args.denoise {
        match job.render_pass(split - taken.start) {
            Err(RenderError::Cancelled) => {
                return Err(Error::Interrupted("interrupted: no image written".into()));
            }
            other => other?,
        }
        Some(caustic::render::denoised::FirstHalf {
            sums: job.sums().clone(),
            parts: job.parts().map(<[_]>::to_vec),
        })
    } else {
        None
    };
    let outcome = render_in_passes(job, &plan);
    let saved = outcome.checkpoint_spp;
    let error = outcome.error;
    let interrupted = || {
        let kept = match (&args.checkpoint, saved) {
            (Some(cp), Some(n)) => format!(
                " to `{}`; `{}` holds the last complete checkpoint ({n} of {spp} samples per pixel)",
                output.display(),
                cp.display()
            ),
            _ => String::new(),
        };
        Error::Interrupted(format!("interrupted: no image written{kept}"))
    };
    let out = match outcome.result {
        Err(RenderError::Cancelled) => return Err(interrupted()),
        other => other?,
    };
    // A signal that came after the last tile still means "stop": the output is not written.
    if interrupt.raised() {
        return Err(interrupted());
    }
    let features = if trace_features {
        let started = std::time::Instant::now();
        let traced = caustic::render::Features::trace(
            &prepared.render_scene,
            region,
            taken.clone(),
            split,
            args.threads,
            options.cancel.as_deref(),
        );
        let f = match traced {
            Err(RenderError::Cancelled) => return Err(interrupted()),
            other => other?,
        };
        if !args.quiet {
            eprintln!(
                "features: albedo, normal and depth traced in {:.2} s",
                started.elapsed().as_secs_f64()
            );
        }
        Some(f)
    } else {
        None
    };
    let denoised = match (&first_half, &features) {
        (Some(first), Some(f)) => {
            let started = std::time::Instant::now();
            let film = caustic::render::denoised::denoise_render(
                &out.sums,
                out.parts.as_deref(),
                first,
                f,
                &caustic::denoise::DenoiseParams::default(),
                args.threads,
            )
            .map_err(|e| Error::Usage(e.to_string()))?;
            if !args.quiet {
                eprintln!("denoised in {:.2} s", started.elapsed().as_secs_f64());
            }
            Some(film)
        }
        _ => None,
    };
    // The display of 8-bit outputs: the stated exposure, else the finished film's own.
    let (display, auto) = resolve(
        denoised.as_ref().unwrap_or(&out.film),
        stated_exposure,
        tonemap,
    );
    let auto = auto.filter(|_| hash.is_none() && !is_exr(&output));
    if let Some(hash) = hash {
        let taken =
            out.stats.samples / (u64::from(out.film.width) * u64::from(out.film.height)).max(1);
        let end = first_sample + taken as u32;
        let meta = PartMeta {
            // NaN: automatic (`merge` then chooses it from the merged film).
            exposure: stated_exposure.unwrap_or(f32::NAN),
            scene: args.scene.scene.display().to_string(),
            shard: shard.map(|s| s.to_string()),
            seconds: out.stats.elapsed.as_secs_f64(),
            ..PartMeta::of(&prepared.render_scene, hash, first_sample..end, spp, region)
        };
        out.sums.write(&output, &meta.to_text())?;
    } else if features.is_some() || denoised.is_some() {
        let extras = LayerExtras {
            features: features.as_ref(),
            denoised: denoised.as_ref(),
        };
        write_with_extras(
            &out.sums,
            out.parts.as_deref(),
            extras,
            &layers,
            &output,
            display,
        )?;
    } else if !layers.is_empty() {
        write_with_layers(&out.sums, out.parts.as_deref(), &layers, &output, display)?;
    } else {
        write_image(&out.film, &output, display)?;
    }
    if let (Some(cp), Some(_)) = (&args.checkpoint, saved)
        && let Err(e) = std::fs::remove_file(cp)
        && !args.quiet
    {
        eprintln!(
            "warning: cannot remove the checkpoint `{}`: {e}",
            cp.display()
        );
    }
    let st = &out.stats;
    let secs = st.elapsed.as_secs_f64();
    let reached = st.samples / (u64::from(out.film.width) * u64::from(out.film.height)).max(1);
    // A shard or `--samples` range says which samples of the render's it took.
    let range = match &samples {
        Some(r) if reached > 0 => format!(
            " (samples {}..{} of {spp})",
            r.start,
            r.start + reached as u32
        ),
        Some(r) => format!(" (none of samples {}..{} of {spp})", r.start, r.end),
        None => String::new(),
    };
    let p = &prepared.render_scene.params;
    println!(
        "{}: {}×{}, {} spp{range}, {:?} integrator{}, {:?} sampler, {} rays in {:.2} s ({:.2} Mrays/s, {} thread{})",
        output.display(),
        out.film.width,
        out.film.height,
        reached,
        p.integrator,
        if p.default_estimator.is_some() {
            " (default)"
        } else {
            ""
        },
        p.sampler,
        st.rays,
        secs,
        st.rays as f64 / secs.max(1e-9) / 1e6,
        st.threads,
        if st.threads == 1 { "" } else { "s" }
    );
    if let (Some((e, reached)), Some(target)) = (error, target_error)
        && !args.quiet
    {
        eprintln!(
            "target error {target}: {} — estimated relMSE {:.5} (its worst 1 % of pixels: {:.4}) at {reached_spp} spp in {secs:.2} s",
            if reached {
                "reached"
            } else {
                "not reached (the time or samples ran out)"
            },
            e.image,
            e.worst,
            reached_spp = reached_spp(&out),
        );
    }
    if adaptive && !args.quiet {
        eprintln!("{}", adaptive_summary(&out.sums, target_error));
    }
    if let Some(auto) = &auto
        && !args.quiet
    {
        eprintln!("{}", auto.describe());
    }
    if !pictures.is_empty() && !args.quiet {
        let names: Vec<String> = pictures
            .iter()
            .map(|p| format!("`{}`", p.display()))
            .collect();
        eprintln!("layers: {}", names.join(", "));
    }
    if let Some(pr) = &st.progressive
        && !args.quiet
    {
        let t = &pr.totals;
        eprintln!(
            "photons: {} passes of fresh maps, {} photons emitted and {} stored in all ({:.2} s), {} estimates; the last pass read {:.3} of each initial radius{}",
            t.passes,
            t.emitted,
            t.stored,
            t.time.as_secs_f64(),
            st.photon_estimates,
            pr.last_shrink,
            match pr.caustic_radius {
                Some((typical, empty)) => format!(
                    " (caustic map: R = {typical:.4} for a typical photon, {empty:.4} where the pilot map found none)"
                ),
                None => String::new(),
            }
        );
    } else if st.photon_estimates > 0 && !args.quiet {
        eprintln!(
            "photons: {} estimates, {:.1}% cut short by the largest radius (photons.max_radius): those found fewer than the photons they ask for (photons.gather) within it, so they average fewer photons and are noisier; if the image looks blotchy, trace more photons (--photons, --caustic-photons) or raise --max-radius (which blurs more)",
            st.photon_estimates,
            100.0 * st.photon_radius_cut as f64 / st.photon_estimates as f64
        );
    }
    if st.nan_samples > 0 {
        eprintln!(
            "warning: {} samples were NaN or infinite and were dropped",
            st.nan_samples
        );
    }
    if let Some(reference) = &reference {
        super::max_rmse::check(
            reference,
            denoised.as_ref().unwrap_or(&out.film),
            &output,
            display.exposure,
            region,
            args.max_rmse,
        )?;
    }
    Ok(())
}

/// What an adaptive render spent: samples per pixel (mean, fewest, most) and the estimated
/// relMSE of the image and of its worst 1 % of pixels.
fn adaptive_summary(sums: &caustic::render::PixelSums, target: Option<f32>) -> String {
    use caustic::render::adaptive::AdaptivePlan;
    use caustic::render::error_estimate::ErrorEstimate;
    let n = sums.width as usize * sums.height as usize;
    let counts = (0..n).map(|i| sums.count(i));
    let total: u64 = counts.clone().map(u64::from).sum();
    let e = ErrorEstimate::of_sums(sums);
    format!(
        "adaptive: {:.2} samples per pixel on average ({} to {}), each pixel until its estimated relMSE is at most {}; estimated relMSE {:.5}, worst 1 % of pixels {:.4}",
        total as f64 / n.max(1) as f64,
        counts.clone().min().unwrap_or(0),
        counts.max().unwrap_or(0),
        AdaptivePlan::new(target.map(f64::from), 1).pixel_target as f32,
        e.image,
        e.worst
    )
}

/// Samples per pixel a render output holds.
fn reached_spp(out: &caustic::render::RenderOutput) -> u64 {
    out.stats.samples / (u64::from(out.film.width) * u64::from(out.film.height)).max(1)
}

pub(super) fn print_stats(s: &caustic::compile::CompileStats) {
    eprintln!(
        "scene: {} ({} dropped), {}, {}{}, {}, {}, {}",
        count(s.triangles, "triangle"),
        count(s.degenerate_triangles, "degenerate triangle"),
        count(s.spheres, "sphere"),
        count(s.ellipsoids, "ellipsoid"),
        super::quadric_counts(s),
        count(s.materials, "material"),
        count(s.lights, "light"),
        count(s.meshes_loaded, "OBJ file"),
    );
    eprintln!(
        "bvh: {} nodes, {} leaves, depth {}, max leaf {}, SAH cost {:.2}; flatten {:.3} s, build {:.3} s",
        s.bvh.nodes,
        s.bvh.leaves,
        s.bvh.max_depth,
        s.bvh.max_leaf_size,
        s.bvh.sah_cost,
        s.flatten_time.as_secs_f64(),
        s.bvh_time.as_secs_f64()
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn durations_parse_with_units_and_refuse_nonsense() {
        assert_eq!(parse_duration("30s"), Ok(Duration::from_secs(30)));
        assert_eq!(parse_duration("2m"), Ok(Duration::from_secs(120)));
        assert_eq!(parse_duration("1.5h"), Ok(Duration::from_secs(5400)));
        assert_eq!(parse_duration("250ms"), Ok(Duration::from_millis(250)));
        assert_eq!(parse_duration("12"), Ok(Duration::from_secs(12)));
        for bad in ["", "0s", "-3s", "3 parsecs", "NaNs", "infs"] {
            assert!(parse_duration(bad).is_err(), "{bad}");
        }
    }
}
