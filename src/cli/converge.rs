//! `caustic converge`: error against time for several integrators, each measured by
//! [`caustic::analysis::convergence::measure`] in its share of `--time`. Writes DIR/convergence.csv,
//! DIR/convergence.json (machine, settings, points, fitted slopes), DIR/convergence.png and .svg
//! (RMSE against wall time, log-log) and each integrator's last image as DIR/<name>.exr.

use std::io::IsTerminal;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use clap::{Args, ValueEnum};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use serde_json::json;

use caustic::Error;
use caustic::analysis::convergence::{self, Series, csv};
use caustic::analysis::metrics::Reference;
use caustic::pipeline::prepare;
use caustic::render::output::{write_atomic, write_image};

use super::compare::figures_json;
use super::render::parse_duration;
use caustic::analysis::convergence_plot::{Curve, Plot};
use caustic::analysis::slope::fmt_slope;
use caustic::settings::IntegratorKind;

use super::{SceneArgs, print_warnings};

/// Samples per pixel a series may reach when `--spp` is not given.
const SPP_CAP: u32 = 1 << 20;

/// Arguments of `caustic converge`.
#[derive(Args)]
pub struct ConvergeArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// The converged reference image (EXR, or PNG for 8-bit figures), the scene's size.
    #[arg(long, value_name = "REF")]
    reference: PathBuf,
    /// Integrators to measure, comma-separated (the names `--integrator` takes).
    #[arg(long, value_enum, value_delimiter = ',', required = true)]
    integrators: Vec<IntegratorKind>,
    /// Total time, shared equally between the integrators (e.g. `120s`, `2m`).
    #[arg(long, value_name = "DURATION", value_parser = parse_duration)]
    time: Duration,
    /// Output folder (created if missing).
    #[arg(short, long, value_name = "DIR")]
    output: PathBuf,
    /// Worker threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
    /// No progress bars and no warnings.
    #[arg(short, long)]
    quiet: bool,
}

/// The machine, for the table: CPU model, logical cores, load average.
fn machine() -> serde_json::Value {
    let cpuinfo = std::fs::read_to_string("/proc/cpuinfo").unwrap_or_default();
    let cpu = cpuinfo
        .lines()
        .find_map(|l| {
            let (k, v) = l.split_once(':')?;
            (k.trim() == "model name").then(|| v.trim().to_string())
        })
        .unwrap_or_else(|| "unknown".into());
    let cores = std::thread::available_parallelism().map_or(0, std::num::NonZero::get);
    json!({
        "cpu": cpu,
        "cores": cores,
        "os": std::env::consts::OS,
        "arch": std::env::consts::ARCH,
        "load_average": load_average(),
    })
}

/// The 1-minute load average (Linux), a caveat for the timings.
fn load_average() -> Option<f64> {
    std::fs::read_to_string("/proc/loadavg")
        .ok()?
        .split_whitespace()
        .next()?
        .parse()
        .ok()
}

fn progress_bar(show: bool, name: &str, share: Duration) -> ProgressBar {
    if !show {
        return ProgressBar::hidden();
    }
    let bar =
        ProgressBar::with_draw_target(Some(share.as_millis() as u64), ProgressDrawTarget::stderr());
    if let Ok(style) = ProgressStyle::with_template("{prefix:>8} [{bar:24}] {msg}") {
        bar.set_style(style.progress_chars("=> "));
    }
    bar.set_prefix(name.to_string());
    bar
}

/// Prepares the scene with `integrator` and renders its series.
fn measure(
    args: &ConvergeArgs,
    integrator: IntegratorKind,
    reference: &Reference,
    share: Duration,
    show: bool,
) -> Result<(Series, caustic::render::Film, f32), Error> {
    let started = Instant::now();
    let mut overrides = args.scene.overrides();
    overrides.render.integrator = Some(integrator);
    overrides.render.samples_per_pixel = Some(args.scene.spp.unwrap_or(SPP_CAP));
    let prepared = prepare(&args.scene.scene, &overrides)?;
    if !args.quiet {
        print_warnings(&prepared.warnings);
    }
    let bar = progress_bar(show, integrator.cli_name(), share);
    let (series, film) = convergence::measure(
        &prepared.render_scene,
        integrator,
        reference,
        share,
        args.threads,
        started,
        &mut |point, render_time| {
            bar.set_position(render_time.min(share).as_millis() as u64);
            bar.set_message(format!("{} spp, rmse {:.5}", point.spp, point.error.rmse));
        },
    )?;
    bar.finish_and_clear();
    Ok((series, film, prepared.render_scene.params.exposure))
}

/// Runs the series, writes the table, the JSON and the plots, and prints a summary.
pub fn run(args: &ConvergeArgs) -> Result<(), Error> {
    if args.scene.integrator.is_some() {
        return Err(Error::Usage(
            "converge measures the integrators of --integrators (e.g. `--integrators \
             path,whitted`); --integrator is for `render`"
                .into(),
        ));
    }
    if args.threads == Some(0) {
        return Err(Error::Usage("--threads must be at least 1".into()));
    }
    // Each integrator once, in the order given.
    let mut integrators: Vec<IntegratorKind> = Vec::new();
    for &i in &args.integrators {
        if !integrators.contains(&i) {
            integrators.push(i);
        }
    }
    std::fs::create_dir_all(&args.output).map_err(|e| {
        Error::Usage(format!(
            "cannot create the output folder `{}`: {e}",
            args.output.display()
        ))
    })?;
    let path = |name: &str| args.output.join(name);
    for name in ["convergence.csv", "convergence.json", "convergence.png"] {
        caustic::render::output::check_writable(&path(name))?;
    }
    let reference =
        Reference::read(&args.reference).map_err(|e| Error::Usage(format!("--reference: {e}")))?;
    let load_before = load_average();
    let share = args.time / u32::try_from(integrators.len()).unwrap_or(u32::MAX).max(1);
    let show = !args.quiet && std::io::stderr().is_terminal();
    let mut all = Vec::new();
    for &integrator in &integrators {
        let (series, film, exposure) = measure(args, integrator, &reference, share, show)?;
        write_image(&film, &path(&format!("{}.exr", series.name())), exposure)?;
        if let (Some(first), Some(last)) = (series.points.first(), series.points.last()) {
            println!(
                "{}: {} points, {}–{} spp in {:.2} s; RMSE {:.5} → {:.5}; slope {} per time, {} per spp",
                series.name(),
                series.points.len(),
                first.spp,
                last.spp,
                last.seconds,
                first.error.rmse,
                last.error.rmse,
                fmt_slope(series.time_slope()),
                fmt_slope(series.spp_slope())
            );
        }
        all.push(series);
    }
    let mut machine = machine();
    machine["load_average_before"] = json!(load_before);
    let sampler = args.scene.sampler.map(|s| {
        s.to_possible_value()
            .map_or_else(String::new, |v| v.get_name().to_string())
    });
    let settings = json!({
        "caustic_version": env!("CARGO_PKG_VERSION"),
        "scene": args.scene.scene.display().to_string(),
        "reference": args.reference.display().to_string(),
        "width": reference.film.width,
        "height": reference.film.height,
        "sets": args.scene.sets,
        "sampler": sampler,
        "seed": args.scene.seed,
        "max_depth": args.scene.max_depth,
        "spp_cap": args.scene.spp.unwrap_or(SPP_CAP),
        "threads": args.threads,
        "time_seconds": args.time.as_secs_f64(),
        "share_seconds": share.as_secs_f64(),
        "timing": "render time to reach each point; scene loading and comparisons excluded",
    });
    let integrators_json: Vec<serde_json::Value> = all
        .iter()
        .map(|s| {
            let points: Vec<serde_json::Value> = s
                .points
                .iter()
                .map(|p| json!({"spp": p.spp, "seconds": p.seconds, "figures": figures_json(&p.error)}))
                .collect();
            json!({
                "name": s.name(),
                "slope_rmse_per_time": s.time_slope(),
                "slope_rmse_per_spp": s.spp_slope(),
                "rays": s.rays,
                "prepare_seconds": s.prepare_seconds,
                "points": points,
            })
        })
        .collect();
    let doc = json!({"machine": machine, "settings": settings, "integrators": integrators_json});
    write_atomic(&path("convergence.csv"), csv(&all).as_bytes())?;
    write_atomic(&path("convergence.json"), format!("{doc:#}\n").as_bytes())?;
    let plot = Plot {
        title: format!(
            "{} {}x{}: RMSE against render time",
            args.scene
                .scene
                .file_name()
                .map_or_else(String::new, |n| n.to_string_lossy().into_owned()),
            reference.film.width,
            reference.film.height
        ),
        x_desc: "render time (s)".into(),
        y_desc: "RMSE".into(),
        curves: all
            .iter()
            .map(|s| Curve {
                label: format!("{} (slope {})", s.name(), fmt_slope(s.time_slope())),
                points: s.points.iter().map(|p| (p.seconds, p.error.rmse)).collect(),
            })
            .collect(),
    };
    caustic::analysis::convergence_plot::write(
        &plot,
        &path("convergence.svg"),
        &path("convergence.png"),
    )?;
    println!(
        "wrote {}/convergence.{{csv,json,png,svg}} and one EXR per integrator",
        args.output.display()
    );
    Ok(())
}
