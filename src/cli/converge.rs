//! `caustic converge`: error against time for several integrators. Each integrator renders the
//! scene progressively, and at 1, 2, 4, 8, … samples per pixel the image so far is compared with
//! a reference (the film after n samples is bit-identical to a fresh render at n samples, so one
//! progressive render gives the whole series for the time of its last point). The series
//! doubles until the integrator's share of `--time` would be overrun. Writes DIR/convergence.csv,
//! DIR/convergence.json (machine, settings, points, fitted slopes), DIR/convergence.png and .svg
//! (RMSE against wall time, log-log) and each integrator's last image as DIR/<name>.exr.

use std::fmt::Write as _;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use clap::{Args, ValueEnum};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use serde_json::json;

use caustic::Error;
use caustic::analysis::metrics::{ImageError, Reference};
use caustic::pipeline::prepare;
use caustic::render::output::{write_atomic, write_image};
use caustic::render::{RenderJob, RenderOptions};

use super::compare::figures_json;
use super::render::parse_duration;
use caustic::analysis::convergence_plot::{Curve, Plot};
use caustic::analysis::slope::{fmt_slope, log_log_slope};
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

/// One measurement: the image after `spp` samples per pixel.
#[derive(Debug, Clone, Copy)]
struct Point {
    spp: u32,
    /// Render time to reach it (scene loading and comparisons excluded).
    seconds: f64,
    error: ImageError,
}

/// One integrator's series.
#[derive(Debug, Clone)]
struct Series {
    integrator: IntegratorKind,
    points: Vec<Point>,
    rays: u64,
    prepare_seconds: f64,
}

impl Series {
    fn name(&self) -> String {
        self.integrator.cli_name().to_string()
    }

    /// Slope of RMSE against wall time (log-log).
    fn time_slope(&self) -> Option<f64> {
        log_log_slope(self.points.iter().map(|p| (p.seconds, p.error.rmse)))
    }

    /// Slope of RMSE against samples per pixel (log-log).
    fn spp_slope(&self) -> Option<f64> {
        log_log_slope(self.points.iter().map(|p| (f64::from(p.spp), p.error.rmse)))
    }
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

/// Renders the series of one integrator.
fn measure(
    args: &ConvergeArgs,
    integrator: IntegratorKind,
    reference: &Reference,
    share: Duration,
    show: bool,
) -> Result<(Series, caustic::render::Film, f32), Error> {
    let t = Instant::now();
    let mut overrides = args.scene.overrides();
    overrides.render.integrator = Some(integrator);
    overrides.render.samples_per_pixel = Some(args.scene.spp.unwrap_or(SPP_CAP));
    let prepared = prepare(&args.scene.scene, &overrides)?;
    if !args.quiet {
        print_warnings(&prepared.warnings);
    }
    let params = &prepared.render_scene.params;
    if (params.width, params.height) != (reference.film.width, reference.film.height) {
        return Err(Error::Usage(format!(
            "the reference `{}` is {}×{} but the scene renders {}×{}; give --width {} \
             --height {} or a reference of the scene's size",
            reference.path.display(),
            reference.film.width,
            reference.film.height,
            params.width,
            params.height,
            reference.film.width,
            reference.film.height
        )));
    }
    let exposure = params.exposure;
    let options = RenderOptions {
        threads: args.threads,
        ..RenderOptions::default()
    };
    let mut job = RenderJob::new(&prepared.render_scene, &options)?;
    let prepare_seconds = t.elapsed().as_secs_f64();
    let name = integrator.cli_name();
    let bar = progress_bar(show, name, share);
    let cap = job.samples_per_pixel();
    let mut points = Vec::new();
    let mut render_time = Duration::ZERO;
    let mut target = 1u32;
    loop {
        let t = Instant::now();
        job.render_pass(target - job.samples_done())?;
        render_time += t.elapsed();
        let film = job.snapshot();
        let c = reference
            .compare(&film, Path::new(&name), exposure, None)
            .map_err(|e| Error::Usage(e.to_string()))?;
        points.push(Point {
            spp: target,
            seconds: render_time.as_secs_f64(),
            error: c.error,
        });
        bar.set_position(render_time.min(share).as_millis() as u64);
        bar.set_message(format!("{target} spp, rmse {:.5}", c.error.rmse));
        if target >= cap {
            break;
        }
        let next = target.saturating_mul(2).min(cap);
        let per_sample = render_time.as_secs_f64() / f64::from(target);
        if render_time.as_secs_f64() + per_sample * f64::from(next - target) > share.as_secs_f64() {
            break;
        }
        target = next;
    }
    bar.finish_and_clear();
    let out = job.into_output();
    let series = Series {
        integrator,
        points,
        rays: out.stats.rays,
        prepare_seconds,
    };
    Ok((series, out.film, exposure))
}

fn csv(series: &[Series]) -> String {
    let mut s = String::from(
        "integrator,spp,seconds,rmse,rel_mse,mae,bias,max_abs,rmse_red,rmse_green,rmse_blue\n",
    );
    for ser in series {
        for p in &ser.points {
            let e = &p.error;
            let _ = writeln!(
                s,
                "{},{},{:.6},{:.8},{:.8},{:.8},{:.8},{:.8},{:.8},{:.8},{:.8}",
                ser.name(),
                p.spp,
                p.seconds,
                e.rmse,
                e.rel_mse,
                e.mae,
                e.mean_bias,
                e.max_abs,
                e.channels[0].rmse,
                e.channels[1].rmse,
                e.channels[2].rmse
            );
        }
    }
    s
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
