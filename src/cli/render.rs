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
pub(super) use caustic::pipeline::render::{BUDGET_SPP_CAP, is_part, output_shard};
use caustic::pipeline::render::{RenderNote, RenderRequest};
use caustic::render::output::OutputFormat;
use caustic::render::{Layer, Region};

use super::same_file::same_file;
use super::{SceneArgs, count, layers_flag, print_warnings};

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
    /// absolute error and bias. The raw estimate is written and scored (a PNG is not denoised
    /// by default with it), unless `--denoise` asks for the denoised image.
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
    /// the denoised image and the noisy one as the `noisy` layer. Under `--time` or a target
    /// error the first half ends at a pass end between a third and a half of the samples. Not
    /// with `--adaptive`, `--shard`/`--samples` or a `.part` output. A `.png` of the whole frame
    /// is denoised by default (`--no-denoise` turns it off); this flag asks for it in an EXR
    /// too, and with `--compare`.
    #[arg(long, conflicts_with_all = ["shard", "no_denoise"])]
    pub(super) denoise: bool,
    /// Write the raw estimate: no default denoising of a `.png` (docs/denoise.md). Golden
    /// checks, `--compare` (unless with `--denoise`) and the layers use the raw one anyway.
    #[arg(long)]
    pub(super) no_denoise: bool,
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
    let pictures = layers_flag::check(&output, &layers, args.checkpoint.as_deref())?;
    let region = args.region.as_deref().map(parse_region).transpose()?;
    let reference = super::max_rmse::load(args.compare.as_deref())?;
    if args.threads == Some(0) {
        return Err(Error::Usage("--threads must be at least 1".into()));
    }
    let request = RenderRequest {
        scene: args.scene.scene.clone(),
        overrides: args.scene.overrides(),
        output,
        threads: args.threads,
        region,
        time: args.time,
        checkpoint: args.checkpoint.clone(),
        checkpoint_every: args.checkpoint_every,
        photon_cache: args.photon_cache.clone(),
        shard,
        samples: args.samples.clone(),
        layers,
        denoise: args.denoise,
        auto_denoise: !args.no_denoise,
        scored: reference.is_some(),
        exposure: args.exposure,
        target_error: args.target_error,
        adaptive: args.adaptive,
        progress: !args.quiet && std::io::stderr().is_terminal(),
    };
    let prepared = request.prepare()?;
    if !args.quiet {
        print_warnings(&prepared.prepared.warnings);
    }
    if args.stats {
        print_stats(&prepared.prepared.stats);
    }
    if let Some(reference) = &reference {
        let p = &prepared.prepared.render_scene.params;
        super::max_rmse::check_size(reference, p.width, p.height, region)?;
    }
    // Why a PNG was left raw: said with the summary, after the render.
    let not_denoised = prepared.auto_denoise_skipped().map(|why| {
        format!("not denoised: {why} (docs/denoise.md says when a PNG is denoised by default)")
    });
    let started = prepared.start(interrupt.start_rendering())?;
    if !args.quiet {
        // The scene and the command line named no integrator: which one, and why.
        if let Some(why) = started.default_estimator() {
            eprintln!("default estimator {why}");
        }
        if let Some(summary) = started.photon_maps_summary() {
            eprintln!("{summary}");
        }
        if let Some(dir) = started.ignored_photon_cache() {
            eprintln!(
                "warning: --photon-cache `{}` is ignored: the {:?} integrator keeps no photon maps to cache (only `--integrator photon` does; ppm and path-ppm trace fresh maps every pass)",
                dir.display(),
                started.integrator()
            );
        }
    }
    let rendered = started.finish(&mut |note| {
        if args.quiet {
            return;
        }
        match note {
            RenderNote::FeaturesTraced(t) => eprintln!(
                "features: albedo, normal and depth traced in {:.2} s",
                t.as_secs_f64()
            ),
            RenderNote::Denoised(t) if args.denoise => {
                eprintln!("denoised in {:.2} s", t.as_secs_f64());
            }
            RenderNote::Denoised(t) => eprintln!(
                "denoised in {:.2} s (the default for a PNG; --no-denoise writes the raw estimate)",
                t.as_secs_f64()
            ),
            RenderNote::NotDenoised(why) => eprintln!("warning: not denoised: {why}"),
            RenderNote::CheckpointKept(cp, e) => eprintln!(
                "warning: cannot remove the checkpoint `{}`: {e}",
                cp.display()
            ),
        }
    })?;
    println!("{}", rendered.summary());
    if !args.quiet {
        let said = [
            rendered.target_error_summary(),
            rendered.adaptive_summary(),
            rendered.auto_exposure.as_ref().map(|a| a.describe()),
            (!pictures.is_empty()).then(|| {
                let names: Vec<String> = pictures
                    .iter()
                    .map(|p| format!("`{}`", p.display()))
                    .collect();
                format!("layers: {}", names.join(", "))
            }),
            rendered.photons_summary(),
            not_denoised,
        ];
        for line in said.into_iter().flatten() {
            eprintln!("{line}");
        }
    }
    let nan = rendered.out.stats.nan_samples;
    if nan > 0 {
        eprintln!("warning: {nan} samples were NaN or infinite and were dropped");
    }
    if let Some(reference) = &reference {
        super::max_rmse::check(
            reference,
            rendered.image(),
            &request.output,
            rendered.display.exposure,
            region,
            args.max_rmse,
        )?;
    }
    Ok(())
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
