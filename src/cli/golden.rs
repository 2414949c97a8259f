//! `caustic golden`: noise-aware snapshot tests, the command-line side only. `update` renders
//! each scene batch by batch and stores the golden ([`caustic::render::golden`]: block means
//! per batch, per-pixel means, the settings) and states its detection floor; `check` renders
//! again with a fresh seed and decides "same scene within noise" or "changed" by the
//! batch-means test of [`caustic::render::golden::batch_means`] (exit code 3 when a scene
//! changed). This file parses the flags, finds the scenes, applies the recorded flags and
//! prints; the report's words are [`caustic::render::golden::report`]'s.

use std::path::{Path, PathBuf};

use clap::{Args, Subcommand};

use caustic::Error;
use caustic::farm::part_meta::settings_hash;
use caustic::pipeline::{SceneOverrides, prepare};
use caustic::render::RenderOptions;
use caustic::render::golden::floor::{self, DetectSearch, DetectStep, DetectionFloor};
use caustic::render::golden::{
    BatchBlocks, GoldenImage, GoldenMeta, GoldenTest, PixelEstimates, golden_file_name,
    render_batches, report, scene_files,
};
use caustic::settings::{IntegratorKind, SamplerKind};

use super::golden_report::{self as verdict, Outcome};
use super::{SceneArgs, print_warnings};

/// Arguments of `caustic golden`.
#[derive(Args)]
pub struct GoldenArgs {
    #[command(subcommand)]
    command: GoldenCommand,
}

#[derive(Subcommand)]
enum GoldenCommand {
    /// Render each scene (its settings plus the flags given) and store DIR/<file>.golden: the
    /// image, each pixel's variance of the mean, the settings hash and the flags.
    Update(UpdateArgs),
    /// Render each scene again (with the golden's flags, a fresh seed, then the flags given)
    /// and decide "same within noise" (exit 0) or "changed" (exit 3, with an error image and
    /// the blocks that moved); see docs/golden.md for the statistic.
    Check(CheckArgs),
}

/// Arguments of `caustic golden update`.
#[derive(Args)]
struct UpdateArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// More scene files, or folders whose .ron and .toml files are all taken.
    #[arg(value_name = "MORE")]
    more: Vec<PathBuf>,
    /// The folder of golden images (created if missing).
    #[arg(short, long, value_name = "DIR")]
    output: PathBuf,
    /// Block side in pixels (the finest scale of the test; coarser scales are squares of
    /// 2×2, 4×4, … blocks).
    #[arg(long, default_value = "8", value_name = "PIXELS")]
    block: u32,
    /// The smallest change to catch, e.g. `2%`: render at the samples per pixel that catch a
    /// change of that size over a block of about 5 % of the image in 95 % of checks (for the
    /// median block; predicted from the noise measured, rendered and measured again; recorded
    /// as `--spp`).
    #[arg(long, value_name = "PERCENT", value_parser = parse_percent)]
    detect: Option<f64>,
    /// Most samples per pixel `--detect` may choose.
    #[arg(long, default_value = "4096", value_name = "SPP")]
    detect_limit: u32,
    /// The checks' false-alarm rate, for the detection floor stated.
    #[arg(long, default_value = "0.01", value_parser = parse_alpha)]
    alpha: f64,
    /// Worker threads (default: all cores); never changes the pixels.
    #[arg(long)]
    threads: Option<usize>,
    /// No warnings.
    #[arg(short, long)]
    quiet: bool,
}

/// Arguments of `caustic golden check`.
#[derive(Args)]
struct CheckArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// More scene files, or folders whose .ron and .toml files are all taken.
    #[arg(value_name = "MORE")]
    more: Vec<PathBuf>,
    /// The folder of golden images written by `caustic golden update`.
    #[arg(long, value_name = "DIR")]
    golden: PathBuf,
    /// False-alarm rate per scene: the largest chance that a render of an unchanged scene is
    /// called changed.
    #[arg(long, default_value = "0.01", value_parser = parse_alpha)]
    alpha: f64,
    /// Where error images of changed scenes go (default: the golden folder), as
    /// <file>.error.png.
    #[arg(long, value_name = "DIR")]
    error_dir: Option<PathBuf>,
    /// Worker threads (default: all cores); never changes the pixels.
    #[arg(long)]
    threads: Option<usize>,
    /// No warnings.
    #[arg(short, long)]
    quiet: bool,
}

fn parse_percent(text: &str) -> Result<f64, String> {
    let t = text.trim();
    t.strip_suffix('%')
        .unwrap_or(t)
        .trim()
        .parse::<f64>()
        .ok()
        .filter(|p| *p > 0.0 && *p < 100.0)
        .map(|p| p / 100.0)
        .ok_or_else(|| format!("expected a percentage between 0 and 100, e.g. 2%, found `{text}`"))
}

fn parse_alpha(text: &str) -> Result<f64, String> {
    text.trim()
        .parse::<f64>()
        .ok()
        .filter(|a| *a > 0.0 && *a < 1.0)
        .ok_or_else(|| format!("expected a probability between 0 and 1, e.g. 0.01, found `{text}`"))
}

/// Runs `golden update` or `golden check`.
pub fn run(args: &GoldenArgs) -> Result<(), Error> {
    match &args.command {
        GoldenCommand::Update(a) => update(a),
        GoldenCommand::Check(a) => check(a),
    }
}

fn usage(text: String) -> Error {
    Error::Usage(text)
}

/// The overrides that `update` records for `check` to apply again (all but the seed).
fn record(o: &SceneOverrides) -> Vec<(String, String)> {
    let mut out: Vec<(String, String)> = o.sets.iter().map(|s| ("set".into(), s.clone())).collect();
    for (key, v) in [
        ("width", o.render.width),
        ("height", o.render.height),
        ("spp", o.render.samples_per_pixel),
        ("max_depth", o.render.max_depth),
        ("caustic_photons", o.photons.caustic),
    ] {
        if let Some(v) = v {
            out.push((key.into(), v.to_string()));
        }
    }
    if let Some(i) = o.render.integrator {
        out.push(("integrator".into(), i.cli_name().into()));
    }
    if let Some(s) = o.render.sampler {
        out.push(("sampler".into(), s.cli_name().into()));
    }
    out
}

/// The golden's recorded overrides, then the check's own on top (its `--set`s after the
/// golden's, its flags instead of the golden's); the seed is the check's, or the golden's + 1
/// so that the two renders' noise is independent.
fn combined(
    golden: &GoldenMeta,
    own: &SceneOverrides,
    path: &Path,
) -> Result<SceneOverrides, Error> {
    let mut o = SceneOverrides::default();
    for (key, value) in &golden.overrides {
        let unknown = || {
            usage(format!(
                "`{}`: its recorded flag `{key}={value}` names no such choice; run `caustic golden update` again",
                path.display()
            ))
        };
        let num = || {
            value.parse::<u32>().map_err(|_| {
                usage(format!(
                    "`{}`: its recorded flag `{key}={value}` is malformed; run `caustic golden update` again",
                    path.display()
                ))
            })
        };
        match key.as_str() {
            "set" => o.sets.push(value.clone()),
            "width" => o.render.width = Some(num()?),
            "height" => o.render.height = Some(num()?),
            "spp" => o.render.samples_per_pixel = Some(num()?),
            "max_depth" => o.render.max_depth = Some(num()?),
            "caustic_photons" => o.photons.caustic = Some(num()?),
            "integrator" => {
                o.render.integrator = Some(IntegratorKind::from_name(value).ok_or_else(unknown)?)
            }
            "sampler" => {
                o.render.sampler = Some(SamplerKind::from_name(value).ok_or_else(unknown)?)
            }
            _ => {
                return Err(usage(format!(
                    "`{}`: unknown recorded flag `{key}` (written by a newer caustic?); run `caustic golden update` again",
                    path.display()
                )));
            }
        }
    }
    o.sets.extend(own.sets.iter().cloned());
    o.render = own.render.or(&o.render);
    o.photons = own.photons.or(&o.photons);
    o.render.seed = Some(own.render.seed.unwrap_or(golden.seed.wrapping_add(1)));
    Ok(o)
}

/// A scene rendered for the golden test.
struct Rendered {
    estimates: PixelEstimates,
    batches: BatchBlocks,
    cells: BatchBlocks,
    meta: GoldenMeta,
    /// The settings hash as if rendered with `hash_seed` instead of its own seed.
    hash_at_seed: u64,
    /// How its noise falls with more samples per pixel (for `--detect`).
    noise: caustic::render::golden::noise_scaling::NoiseScaling,
}

/// Prepares and renders `path` batch by batch; refuses fewer than 2 samples per pixel (no
/// noise estimate). `golden_seed` (a check's) is the golden's seed: the settings hash is also
/// computed as if rendered with it, and the progressive integrators' pilot maps are traced
/// from it, so that golden and check have the same radius field and thus the same expected
/// image (docs/golden.md).
fn render_scene(
    path: &Path,
    overrides: &SceneOverrides,
    block: u32,
    threads: Option<usize>,
    quiet: bool,
    golden_seed: Option<u64>,
) -> Result<Rendered, Error> {
    let hash_seed = golden_seed;
    let mut prepared = prepare(path, overrides)?;
    prepared.render_scene.params.photons.pilot_seed = golden_seed;
    if !quiet {
        print_warnings(&prepared.warnings);
    }
    let p = &prepared.render_scene.params;
    if p.samples_per_pixel < 2 {
        return Err(usage(format!(
            "`{}`: a golden test needs at least 2 samples per pixel to measure the noise, found {}; give --spp",
            path.display(),
            p.samples_per_pixel
        )));
    }
    let hash = settings_hash(&prepared.render_scene);
    let seed = prepared.render_scene.params.seed;
    let hash_at_seed = match hash_seed {
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
    if out.output.stats.nan_samples > 0 && !quiet {
        eprintln!(
            "warning: `{}`: {} samples were NaN or infinite and were dropped",
            path.display(),
            out.output.stats.nan_samples
        );
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
    Ok(Rendered {
        estimates: PixelEstimates::from_sums(&out.output.sums),
        batches: out.batches,
        cells: out.cells,
        meta,
        hash_at_seed,
        noise: out.noise,
    })
}

fn update(a: &UpdateArgs) -> Result<(), Error> {
    let scenes = scene_files(&a.scene.scene, &a.more).map_err(|e| usage(e.to_string()))?;
    if a.block == 0 {
        return Err(usage("--block must be at least 1 pixel".into()));
    }
    std::fs::create_dir_all(&a.output)
        .map_err(|e| usage(format!("cannot create `{}`: {e}", a.output.display())))?;
    let overrides = a.scene.overrides();
    for path in &scenes {
        let mut r = render_scene(path, &overrides, a.block, a.threads, a.quiet, None)?;
        let mut floor = DetectionFloor::of(&r.batches, &r.cells, a.alpha).with_noise(r.noise);
        if let Some(target) = a.detect {
            let (w, h) = (r.estimates.width, r.estimates.height);
            let mut search = DetectSearch::new(target, a.alpha, a.detect_limit);
            while let DetectStep::Render(spp) = search.next(&floor, r.meta.spp, w, h) {
                let scale = &floor.scales[floor.detect_scale(w, h)];
                println!(
                    "{}: {} spp catch a change of {} % over {side}×{side} px (≈ {} % of the image), or a pattern change of ±{} % over {cell}×{cell} px cells, in 95 % of checks; measuring at {spp} spp",
                    path.display(),
                    r.meta.spp,
                    report::number((1000.0 * scale.median).round() / 10.0),
                    report::number(100.0 * floor::DETECT_AREA),
                    report::number((1000.0 * floor.structure).round() / 10.0),
                    side = scale.side,
                    cell = floor.cell
                );
                let mut more = overrides.clone();
                more.render.samples_per_pixel = Some(spp);
                let next = render_scene(path, &more, a.block, a.threads, a.quiet, None)?;
                let next_floor =
                    DetectionFloor::of(&next.batches, &next.cells, a.alpha).with_noise(next.noise);
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
                println!(
                    "{}: warning: {} spp do not reach a floor of {} % over {side}×{side} px and over the structure test's cells (--detect-limit {})",
                    path.display(),
                    r.meta.spp,
                    report::number(100.0 * target),
                    a.detect_limit,
                    side = floor.scales[floor.detect_scale(w, h)].side
                );
            }
        }
        let target = a.output.join(golden_file_name(path));
        let (w, h) = (r.estimates.width, r.estimates.height);
        let (spp, integrator) = (r.meta.spp, r.meta.integrator.clone());
        GoldenImage {
            estimates: r.estimates,
            batches: r.batches,
            cells: r.cells,
            meta: r.meta,
        }
        .write(&target)?;
        println!(
            "{}: {w}×{h}, {spp} spp, {integrator}: golden written to `{}`; {}",
            path.display(),
            target.display(),
            report::describe_floor(&floor)
        );
    }
    Ok(())
}

fn check(a: &CheckArgs) -> Result<(), Error> {
    let scenes = scene_files(&a.scene.scene, &a.more).map_err(|e| usage(e.to_string()))?;
    let test = GoldenTest { alpha: a.alpha };
    let own = a.scene.overrides();
    let error_dir = a.error_dir.clone().unwrap_or_else(|| a.golden.clone());
    let (mut changed, mut failed) = (0usize, 0usize);
    for path in &scenes {
        match check_one(path, a, &own, &test, &error_dir) {
            Ok(Outcome::Same) => {}
            Ok(Outcome::Changed) => changed += 1,
            Err(e) => {
                failed += 1;
                let text = e.to_string();
                if text.starts_with("error:") || text.contains("\nerror:") {
                    eprintln!("{text}");
                } else {
                    eprintln!("error: {text}");
                }
            }
        }
    }
    let n = scenes.len();
    if failed > 0 {
        return Err(usage(format!(
            "{failed} of {n} scenes could not be checked (see above); {changed} changed"
        )));
    }
    if changed > 0 {
        return Err(Error::Mismatch(format!(
            "{changed} of {n} scenes changed beyond their noise (exit code 3)"
        )));
    }
    println!("{n} of {n} scenes the same as their golden images within noise");
    Ok(())
}

fn check_one(
    path: &Path,
    a: &CheckArgs,
    own: &SceneOverrides,
    test: &GoldenTest,
    error_dir: &Path,
) -> Result<Outcome, Error> {
    let golden_path = a.golden.join(golden_file_name(path));
    let golden = GoldenImage::read(&golden_path).map_err(|e| {
        usage(format!(
            "{}: {e}; write it with `caustic golden update {} -o {}`",
            path.display(),
            path.display(),
            a.golden.display()
        ))
    })?;
    let overrides = combined(&golden.meta, own, &golden_path)?;
    let block = golden.batches.block;
    let r = render_scene(
        path,
        &overrides,
        block,
        a.threads,
        a.quiet,
        Some(golden.meta.seed),
    )?;
    verdict::report(
        path,
        &golden,
        &verdict::Now {
            estimates: &r.estimates,
            batches: &r.batches,
            cells: &r.cells,
            meta: &r.meta,
            hash_at_golden_seed: r.hash_at_seed,
        },
        test,
        error_dir,
    )
}
