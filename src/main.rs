//! The `caustic` command line: render, check, schema, debug-pixel.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use clap::{Args, Parser, Subcommand};

use caustic::Error;
use caustic::pipeline::{SceneOverrides, prepare};
use caustic::render::output::{OutputFormat, write_image};
use caustic::render::{Region, RenderError, RenderJob, RenderOptions, RenderOutput, trace_pixel};
use caustic::scene::Diagnostic;

/// caustic: a ray tracer driven by RON/TOML scene files.
#[derive(Parser)]
#[command(name = "caustic", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene to PNG (sRGB) or EXR (linear float), chosen by the output's extension.
    ///
    /// Ctrl-C stops the render and writes nothing (an existing output file is left untouched);
    /// the exit code is then 130. With `--checkpoint`, the checkpoint file keeps the last
    /// complete checkpoint.
    Render(RenderArgs),
    /// Parse and validate a scene (and its assets) without rendering; reports every error.
    Check(SceneArgs),
    /// Print the JSON Schema of the scene format.
    Schema,
    /// Trace one sample of one pixel and print its ray tree.
    DebugPixel(DebugPixelArgs),
    /// Compare an image with a reference (PNG or EXR): RMSE, relative MSE, max difference, bias.
    Compare {
        /// The image under test.
        image: PathBuf,
        /// The converged reference.
        reference: PathBuf,
    },
}

#[derive(Args)]
struct SceneArgs {
    /// Scene file (.ron or .toml).
    scene: PathBuf,
    /// Override a scene value, e.g. `--set camera.fov_y=35` (repeatable).
    #[arg(long = "set", value_name = "PATH=VALUE")]
    sets: Vec<String>,
    /// Image width in pixels.
    #[arg(long)]
    width: Option<u32>,
    /// Image height in pixels.
    #[arg(long)]
    height: Option<u32>,
    /// Samples per pixel.
    #[arg(long)]
    spp: Option<u32>,
    /// Maximum specular recursion depth.
    #[arg(long)]
    max_depth: Option<u32>,
    /// Seed of the random streams.
    #[arg(long)]
    seed: Option<u64>,
}

#[derive(Args)]
struct RenderArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// Output image (.png or .exr); default: the scene's name with .png in the current directory.
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
    /// Render only the crop X,Y,W,H (pixels from the top-left); its pixels equal the full render's.
    #[arg(long, value_name = "X,Y,W,H")]
    region: Option<String>,
    /// No progress bar and no warnings.
    #[arg(short, long)]
    quiet: bool,
    /// Print scene and BVH statistics.
    #[arg(long)]
    stats: bool,
    /// Render in passes of samples per pixel and save the image so far to FILE (.png or .exr,
    /// not the output) after a pass once `--checkpoint-every` seconds have passed since the last
    /// save. Ctrl-C
    /// leaves the last complete checkpoint there; it is removed once the final image is written.
    /// The final image is the same, bit for bit, as without checkpoints.
    #[arg(long, value_name = "FILE")]
    checkpoint: Option<PathBuf>,
    /// Seconds between checkpoints (0: after every pass).
    #[arg(
        long,
        value_name = "SECONDS",
        default_value = "30",
        requires = "checkpoint",
        value_parser = parse_seconds
    )]
    checkpoint_every: Duration,
}

fn parse_seconds(text: &str) -> Result<Duration, String> {
    text.trim()
        .parse::<f64>()
        .ok()
        .and_then(|s| Duration::try_from_secs_f64(s).ok())
        .ok_or_else(|| format!("expected a non-negative number of seconds, found `{text}`"))
}

#[derive(Args)]
struct DebugPixelArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// Pixel column.
    x: u32,
    /// Pixel row (from the top).
    y: u32,
    /// Which of the pixel's samples to trace.
    #[arg(long, default_value_t = 0)]
    sample: u32,
    /// Print JSON instead of text.
    #[arg(long)]
    json: bool,
}

impl SceneArgs {
    fn overrides(&self) -> SceneOverrides {
        SceneOverrides {
            sets: self.sets.clone(),
            width: self.width,
            height: self.height,
            samples_per_pixel: self.spp,
            max_depth: self.max_depth,
            seed: self.seed,
        }
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Render(args) => cmd_render(&args),
        Command::Check(args) => cmd_check(&args),
        Command::Schema => {
            print!("{}", caustic::scene::schema::json_schema());
            Ok(())
        }
        Command::DebugPixel(args) => cmd_debug_pixel(&args),
        Command::Compare { image, reference } => cmd_compare(&image, &reference),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("{}", error_text(&e));
            ExitCode::from(e.exit_code() as u8)
        }
    }
}

/// The message of a failed command, every error line starting with `error:` (scene diagnostics
/// already carry their own `error:` lines; an interruption is reported as `interrupted:`).
fn error_text(e: &Error) -> String {
    let text = e.to_string();
    match e {
        Error::Scene(caustic::scene::SceneError::Invalid(_)) | Error::Interrupted(_) => text,
        _ if text.starts_with("error:") => text,
        _ => format!("error: {text}"),
    }
}

/// `n` and the noun, singular for 1: "1 light", "2 lights".
fn count(n: usize, noun: &str) -> String {
    if n == 1 {
        format!("1 {noun}")
    } else {
        format!("{n} {noun}s")
    }
}

fn print_warnings(warnings: &[Diagnostic]) {
    for w in warnings {
        eprint!("{w}");
    }
}

fn cmd_check(args: &SceneArgs) -> Result<(), Error> {
    let prepared = prepare(&args.scene, &args.overrides())?;
    print_warnings(&prepared.warnings);
    let s = &prepared.stats;
    println!(
        "{}: ok ({}, {}, {}, {}, {}; {})",
        args.scene.display(),
        count(s.triangles, "triangle"),
        count(s.spheres, "sphere"),
        count(s.ellipsoids, "ellipsoid"),
        count(s.materials, "material"),
        count(s.lights, "light"),
        count(prepared.warnings.len(), "warning"),
    );
    Ok(())
}

fn parse_region(text: &str) -> Result<Region, Error> {
    let parts: Vec<Result<u32, _>> = text.split(',').map(|p| p.trim().parse::<u32>()).collect();
    match parts.as_slice() {
        [Ok(x), Ok(y), Ok(w), Ok(h)] => Ok(Region {
            x: *x,
            y: *y,
            width: *w,
            height: *h,
        }),
        _ => Err(Error::Usage(format!(
            "error: --region `{text}`: expected four non-negative integers X,Y,W,H, e.g. `--region 64,64,128,128`"
        ))),
    }
}

fn default_output(scene: &Path) -> PathBuf {
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

    fn raised(&self) -> bool {
        self.cancel.load(Ordering::SeqCst)
    }
}

/// Where and how often `--checkpoint` saves the image so far.
struct Checkpoint<'a> {
    path: &'a Path,
    every: Duration,
    exposure: f32,
}

/// The shortest pass worth scheduling between checkpoints (passes cost a sweep over the tiles).
const MIN_PASS: Duration = Duration::from_millis(500);

/// Renders in passes, saving a checkpoint after each pass that ends `every` or more after the
/// last one. The first pass is one sample per pixel; later ones are sized from the measured time
/// per sample to end near the next checkpoint. Returns the render's result and the samples per
/// pixel of the last checkpoint written.
fn render_checkpointed(
    mut job: RenderJob<'_>,
    cp: &Checkpoint<'_>,
) -> (Result<RenderOutput, RenderError>, Option<u32>) {
    let spp = job.samples_per_pixel();
    let mut saved = None;
    let mut last_save = Instant::now();
    let mut render_time = Duration::ZERO;
    let mut pass = 1;
    while job.samples_done() < spp {
        let t = Instant::now();
        if let Err(e) = job.render_pass(pass) {
            return (Err(e), saved);
        }
        render_time += t.elapsed();
        let done = job.samples_done();
        if done == spp {
            break;
        }
        if last_save.elapsed() >= cp.every {
            match write_image(&job.snapshot(), cp.path, cp.exposure) {
                Ok(()) => saved = Some(done),
                Err(e) => eprintln!("warning: checkpoint not saved: {e}"),
            }
            last_save = Instant::now();
        }
        let per_sample = render_time.as_secs_f64() / f64::from(done);
        let target = cp.every.saturating_sub(last_save.elapsed()).max(MIN_PASS);
        // `as` saturates, and a zero estimate only asks for everything left.
        pass = ((target.as_secs_f64() / per_sample) as u32).max(1);
    }
    (job.finish(), saved)
}

/// Whether two paths name the same file (lexically after making them absolute, or the same
/// existing file).
fn same_file(a: &Path, b: &Path) -> bool {
    if let (Ok(x), Ok(y)) = (a.canonicalize(), b.canonicalize()) {
        return x == y;
    }
    matches!((std::path::absolute(a), std::path::absolute(b)), (Ok(x), Ok(y)) if x == y)
}

fn cmd_render(args: &RenderArgs) -> Result<(), Error> {
    let interrupt = Interrupt::install(args.quiet);
    let output = args
        .output
        .clone()
        .unwrap_or_else(|| default_output(&args.scene.scene));
    // Refuse a bad output name before doing any work.
    OutputFormat::for_path(&output)?;
    if let Some(cp) = &args.checkpoint {
        if OutputFormat::for_path(cp).is_err() {
            return Err(Error::Usage(format!(
                "error: --checkpoint `{}`: the checkpoint must end in `.png` or `.exr`",
                cp.display()
            )));
        }
        if same_file(cp, &output) {
            return Err(Error::Usage(format!(
                "error: --checkpoint `{}` is the output file; give it a name of its own",
                cp.display()
            )));
        }
    }
    let region = args.region.as_deref().map(parse_region).transpose()?;
    if args.threads == Some(0) {
        return Err(Error::Usage("error: --threads must be at least 1".into()));
    }
    let prepared = prepare(&args.scene.scene, &args.scene.overrides())?;
    if !args.quiet {
        print_warnings(&prepared.warnings);
    }
    let s = &prepared.stats;
    if args.stats {
        eprintln!(
            "scene: {} ({} dropped), {}, {}, {}, {}, {}",
            count(s.triangles, "triangle"),
            count(s.degenerate_triangles, "degenerate triangle"),
            count(s.spheres, "sphere"),
            count(s.ellipsoids, "ellipsoid"),
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
    let exposure = prepared.render_scene.params.exposure;
    let spp = prepared.render_scene.params.samples_per_pixel;
    let options = RenderOptions {
        threads: args.threads,
        region,
        progress: !args.quiet && std::io::stderr().is_terminal(),
        cancel: Some(interrupt.start_rendering()),
    };
    let job = RenderJob::new(&prepared.render_scene, &options)?;
    let (result, saved) = match &args.checkpoint {
        None => (job.finish(), None),
        Some(path) => render_checkpointed(
            job,
            &Checkpoint {
                path,
                every: args.checkpoint_every,
                exposure,
            },
        ),
    };
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
    let out = match result {
        Err(RenderError::Cancelled) => return Err(interrupted()),
        other => other?,
    };
    // A signal that came after the last tile still means "stop": the output is not written.
    if interrupt.raised() {
        return Err(interrupted());
    }
    write_image(&out.film, &output, exposure)?;
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
    println!(
        "{}: {}×{}, {} spp, {} rays in {:.2} s ({:.2} Mrays/s, {} thread{})",
        output.display(),
        out.film.width,
        out.film.height,
        spp,
        st.rays,
        secs,
        st.rays as f64 / secs.max(1e-9) / 1e6,
        st.threads,
        if st.threads == 1 { "" } else { "s" }
    );
    if st.nan_samples > 0 {
        eprintln!(
            "warning: {} samples were NaN or infinite and were dropped",
            st.nan_samples
        );
    }
    Ok(())
}

fn cmd_debug_pixel(args: &DebugPixelArgs) -> Result<(), Error> {
    let prepared = prepare(&args.scene.scene, &args.scene.overrides())?;
    let (log, l) = trace_pixel(&prepared.render_scene, args.x, args.y, args.sample)?;
    if args.json {
        let mut v = log.to_json();
        v["pixel"] = serde_json::json!([args.x, args.y]);
        v["sample"] = serde_json::json!(args.sample);
        v["radiance"] = serde_json::json!([l.x, l.y, l.z]);
        println!("{}", serde_json::to_string_pretty(&v).unwrap_or_default());
    } else {
        println!("pixel ({}, {}) sample {}:", args.x, args.y, args.sample);
        print!("{}", log.to_text());
    }
    Ok(())
}

fn cmd_compare(image: &Path, reference: &Path) -> Result<(), Error> {
    let c = caustic::render::metrics::compare_files(image, reference)
        .map_err(|e| Error::Usage(e.to_string()))?;
    if let Some(note) = &c.note {
        eprintln!("{note}");
    }
    let e = c.error;
    println!(
        "rmse {:.6}  relMSE {:.6}  max |diff| {:.6}  mean bias {:+.6}",
        e.rmse, e.rel_mse, e.max_abs, e.mean_bias
    );
    Ok(())
}
