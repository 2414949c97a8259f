//! `caustic golden`: noise-aware snapshot tests, the command-line side only. `update` renders
//! each scene batch by batch and stores the golden ([`caustic::render::golden`]: block means
//! per batch, per-pixel means, the settings) and states its detection floor; `check` renders
//! again with a fresh seed and decides "same scene within noise" or "changed" by the
//! batch-means test of [`caustic::render::golden::batch_means`] (exit code 3 when a scene
//! changed). This file parses the flags, finds the scenes and prints; the renders and the
//! recorded flags are [`caustic::pipeline::golden`]'s, the report's words
//! [`caustic::render::golden::report`]'s.

use std::path::{Path, PathBuf};

use clap::{Args, Subcommand};

use caustic::Error;
use caustic::pipeline::SceneOverrides;
use caustic::pipeline::golden::{GoldenNote, UpdateSettings, check_scene, update_scene};
use caustic::render::golden::{GoldenTest, scene_files};

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

/// Prints what a golden run says on the way: the warnings and dropped samples unless `quiet`,
/// `update`'s search for the samples per pixel always.
fn printer(quiet: bool) -> impl FnMut(GoldenNote<'_>) {
    move |note| match note {
        GoldenNote::Warnings(w) if !quiet => print_warnings(w),
        GoldenNote::NanSamples(path, n) if !quiet => eprintln!(
            "warning: `{}`: {n} samples were NaN or infinite and were dropped",
            path.display()
        ),
        GoldenNote::Warnings(_) | GoldenNote::NanSamples(..) => {}
        GoldenNote::Detect(line) => println!("{line}"),
    }
}

fn update(a: &UpdateArgs) -> Result<(), Error> {
    let scenes = scene_files(&a.scene.scene, &a.more).map_err(|e| usage(e.to_string()))?;
    if a.block == 0 {
        return Err(usage("--block must be at least 1 pixel".into()));
    }
    std::fs::create_dir_all(&a.output)
        .map_err(|e| usage(format!("cannot create `{}`: {e}", a.output.display())))?;
    let overrides = a.scene.overrides();
    let settings = UpdateSettings {
        block: a.block,
        detect: a.detect,
        detect_limit: a.detect_limit,
        alpha: a.alpha,
        threads: a.threads,
    };
    for path in &scenes {
        let updated = update_scene(
            path,
            &overrides,
            &a.output,
            &settings,
            &mut printer(a.quiet),
        )?;
        println!("{}", updated.summary(path));
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
    let (golden, r) = check_scene(path, &a.golden, own, a.threads, &mut printer(a.quiet))?;
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
