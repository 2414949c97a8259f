//! Commands of the `caustic` binary and the arguments they share.

mod check;
mod compare;
mod converge;
mod debug_pixel;
mod farm;
mod golden;
mod golden_report;
mod layers_flag;
mod max_rmse;
mod merge;
mod photons;
mod plot;
mod preview;
mod render;
mod same_file;

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand};

use caustic::Error;
use caustic::pipeline::SceneOverrides;
use caustic::scene::Diagnostic;
use caustic::scene::schema::{PhotonSettings, RenderSettings};
use caustic::settings::{IntegratorKind, SamplerKind, Tonemap};

/// caustic: a ray tracer driven by RON/TOML scene files.
#[derive(Parser)]
#[command(name = "caustic", version, about)]
pub struct Cli {
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
    Render(render::RenderArgs),
    /// Parse and validate a scene (and its assets) without rendering; reports every error.
    Check(SceneArgs),
    /// Print the JSON Schema of the scene format.
    Schema,
    /// Trace one sample of one pixel and print its ray tree.
    DebugPixel(debug_pixel::DebugPixelArgs),
    /// Compare an image with a reference (PNG or EXR): RMSE, relative MSE, mean absolute error,
    /// bias and max difference, overall and per channel; optionally over a region, as JSON, and
    /// with a false-colour error image.
    Compare(compare::CompareArgs),
    /// Measure error against time: each integrator of `--integrators` renders at 1, 2, 4, …
    /// samples per pixel until its share of `--time` is spent; writes DIR/convergence.csv,
    /// .json (with the machine and settings), .png and .svg (log-log RMSE against time).
    Converge(converge::ConvergeArgs),
    /// Draw `converge`'s log-log plot of RMSE against time, with fitted slopes, for curves read
    /// from CSV files (`seconds,rmse` columns): another renderer's beside caustic's.
    Plot(plot::PlotArgs),
    /// Draw the photon maps over a dim render of the scene (caustic photons orange, global
    /// blue, brighter where more power landed).
    Photons(photons::PhotonsArgs),
    /// Merge `.part` films (farm shards, renders of disjoint sample ranges) into one image,
    /// byte-identical to a single render of the same samples; refuses parts of different
    /// scenes/settings, duplicates, and (without `--partial`) missing samples.
    Merge(merge::MergeArgs),
    /// Render on a Slurm cluster: `farm plan` writes a job folder, `sbatch DIR/render.sbatch`
    /// runs it, `farm status DIR` reports progress (docs/farm.md).
    Farm(farm::FarmArgs),
    /// Serve a live preview on 127.0.0.1: the render refining pass by pass, restarted whenever
    /// the scene or an asset it uses changes; takes every `render` flag (docs/preview.md).
    Preview(preview::PreviewArgs),
    /// Noise-aware snapshot tests: `golden update SCENES… -o DIR` stores each render with its
    /// per-pixel variance; `golden check SCENES… --golden DIR` renders again and says "same
    /// within noise" or "changed" (exit code 3) by a block z-test (docs/golden.md).
    Golden(golden::GoldenArgs),
}

/// Runs one command.
pub fn run(cli: Cli) -> Result<(), Error> {
    match cli.command {
        Command::Render(args) => render::run(&args),
        Command::Check(args) => check::run(&args),
        Command::Schema => {
            print!("{}", caustic::scene::schema::json_schema());
            Ok(())
        }
        Command::DebugPixel(args) => debug_pixel::run(&args),
        Command::Compare(args) => compare::run(&args),
        Command::Converge(args) => converge::run(&args),
        Command::Plot(args) => plot::run(&args),
        Command::Photons(args) => photons::run(&args),
        Command::Merge(args) => merge::run(&args),
        Command::Farm(args) => farm::run(&args),
        Command::Preview(args) => preview::run(&args),
        Command::Golden(args) => golden::run(&args),
    }
}

/// The scene and the overrides every command that loads one takes.
#[derive(Args)]
pub struct SceneArgs {
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
    /// Maximum path depth (bounces; for Whitted, specular recursion depth).
    #[arg(long)]
    max_depth: Option<u32>,
    /// Seed of the random streams.
    #[arg(long)]
    seed: Option<u64>,
    /// Light-transport algorithm (the scene's `render.integrator`).
    #[arg(long, value_enum)]
    integrator: Option<IntegratorKind>,
    /// Random-number sampler (the scene's `render.sampler`).
    #[arg(long, value_enum)]
    sampler: Option<SamplerKind>,
    /// Photons emitted for the global map (`photons.global`; 0: no global map).
    #[arg(long, value_name = "N")]
    photons: Option<u32>,
    /// Caustic photons (`photons.caustic`), shared by power among all lights: replaces the
    /// lights' own `caustic_photons` (0: no caustic map).
    #[arg(long, value_name = "N")]
    caustic_photons: Option<u32>,
    /// Nearest photons per global estimate (`photons.gather`).
    #[arg(long, value_name = "K")]
    gather: Option<u32>,
    /// Largest photon-estimate radius in scene units (`photons.max_radius`).
    #[arg(long, value_name = "R")]
    max_radius: Option<f32>,
    /// Final-gather rays per camera hit (`photons.final_gather`; 0: read the global map).
    #[arg(long, value_name = "N")]
    final_gather: Option<u32>,
    /// Tone-mapping curve for 8-bit images, after the exposure (`render.tonemap`): `linear`
    /// clips, `aces` rolls highlights off (Narkowicz's ACES fit). EXR output stays linear.
    #[arg(long, value_enum)]
    tonemap: Option<Tonemap>,
}

impl SceneArgs {
    fn overrides(&self) -> SceneOverrides {
        let mut sets = self.sets.clone();
        for (field, v) in [
            ("photons.global", self.photons),
            ("photons.gather", self.gather),
            ("photons.final_gather", self.final_gather),
        ] {
            if let Some(v) = v {
                sets.push(format!("{field}={v}"));
            }
        }
        if let Some(t) = self.tonemap {
            sets.push(format!("render.tonemap={}", t.name()));
        }
        if let Some(r) = self.max_radius {
            sets.push(format!("photons.max_radius={r:?}"));
        }
        SceneOverrides {
            sets,
            render: RenderSettings {
                width: self.width,
                height: self.height,
                samples_per_pixel: self.spp,
                max_depth: self.max_depth,
                seed: self.seed,
                integrator: self.integrator,
                sampler: self.sampler,
                ..RenderSettings::default()
            },
            photons: PhotonSettings {
                caustic: self.caustic_photons,
                ..PhotonSettings::default()
            },
        }
    }
}

/// `n` and the noun, singular for 1: "1 light", "2 lights".
/// ", N discs, M cylinders" for the analytic shapes a scene has (nothing when it has none, so
/// the summaries of scenes without them read as before).
fn quadric_counts(s: &caustic::compile::CompileStats) -> String {
    let mut out = String::new();
    for (n, noun) in [(s.discs, "disc"), (s.cylinders, "cylinder")] {
        if n > 0 {
            out.push_str(&format!(", {}", count(n, noun)));
        }
    }
    out
}

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
