//! `caustic preview SCENE`: a page on 127.0.0.1 that shows the render refining pass by pass,
//! and starts it again whenever the scene file or one of its assets changes on disk
//! (docs/preview.md). Takes every flag of `render`; the page's save writes what `render -o`
//! would for the samples taken so far.

mod denoising;
mod frame;
mod http;
mod save;
mod server;
mod session;
mod state;
mod watch;

use std::ops::Range;
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::Ordering;
use std::sync::mpsc::{Sender, channel};
use std::time::Duration;

use clap::Args;

use caustic::Error;
use caustic::analysis::metrics::Reference;
use caustic::farm::Shard;
use caustic::pipeline::{Prepared, SceneOverrides};
use caustic::render::output::OutputFormat;
use caustic::render::{Layer, Region};

use super::render::{BUDGET_SPP_CAP, RenderArgs, default_output, is_part, parse_region};
use super::same_file::same_file;
use state::{Msg, Phase, Shared};

/// Arguments of `caustic preview`: those of `render`, and the port.
#[derive(Args)]
pub struct PreviewArgs {
    #[command(flatten)]
    render: RenderArgs,
    /// Port to serve the page on, on 127.0.0.1 (default: a free one, printed).
    #[arg(long, value_name = "N")]
    port: Option<u16>,
}

/// How a saved image is written (`-o`, `--layers`, `--compare`).
pub struct SaveSettings {
    /// The output file (`-o`; default: the scene's name with `.png`).
    pub output: PathBuf,
    /// Write the mergeable `.part` film.
    pub part: bool,
    /// Layers beside the image: EXR channels, or pictures beside a PNG.
    pub layers: Vec<Layer>,
    /// `--compare`'s reference, read once at start.
    pub reference: Option<Reference>,
    /// `--max-rmse`.
    pub max_rmse: Option<f64>,
}

/// The render flags, checked once at start.
pub struct Settings {
    /// The scene file.
    pub scene: PathBuf,
    /// `--set` and the render flags that change the scene.
    pub overrides: SceneOverrides,
    /// `--threads`.
    pub threads: Option<usize>,
    /// `--region`.
    pub region: Option<Region>,
    /// `--time`: each render stops refining after this long.
    pub time: Option<Duration>,
    /// `--checkpoint FILE` and `--checkpoint-every`.
    pub checkpoint: Option<(PathBuf, Duration)>,
    /// `--photon-cache`.
    pub photon_cache: Option<PathBuf>,
    /// `--samples`.
    pub samples: Option<Range<u32>>,
    /// `--shard`.
    pub shard: Option<Shard>,
    /// `-q`.
    pub quiet: bool,
    /// `--stats`.
    pub stats: bool,
    /// `--denoise`: the page starts with the denoised image on (its toggle).
    pub denoise: bool,
    /// What the save writes.
    pub save: SaveSettings,
}

impl Settings {
    /// Checks the flags as `render` does before any work.
    fn new(args: &RenderArgs) -> Result<Self, Error> {
        let usage = |m: String| Error::Usage(m);
        let output = args
            .output
            .clone()
            .unwrap_or_else(|| default_output(&args.scene.scene));
        let part = is_part(&output);
        let shard = super::render::output_shard(&output, args.shard.as_deref())?;
        if let Some(cp) = &args.checkpoint {
            if OutputFormat::for_path(cp).is_err() {
                return Err(usage(format!(
                    "--checkpoint `{}`: the checkpoint must end in `.png` or `.exr`",
                    cp.display()
                )));
            }
            if same_file(cp, &output) {
                return Err(usage(format!(
                    "--checkpoint `{}` is the output file; give it a name of its own",
                    cp.display()
                )));
            }
        }
        for path in std::iter::once(&output).chain(&args.checkpoint) {
            caustic::render::output::check_writable(path)?;
        }
        let layers = super::layers_flag::listed(&args.layers);
        super::layers_flag::check(&output, &layers, args.checkpoint.as_deref())?;
        if args.threads == Some(0) {
            return Err(usage("--threads must be at least 1".into()));
        }
        let mut overrides = args.scene.overrides();
        if args.time.is_some() && overrides.render.samples_per_pixel.is_none() {
            overrides.render.samples_per_pixel = Some(BUDGET_SPP_CAP);
        }
        Ok(Self {
            scene: args.scene.scene.clone(),
            overrides,
            threads: args.threads,
            region: args.region.as_deref().map(parse_region).transpose()?,
            time: args.time,
            checkpoint: args
                .checkpoint
                .clone()
                .map(|cp| (cp, args.checkpoint_every)),
            photon_cache: args.photon_cache.clone(),
            samples: args.samples.clone(),
            shard,
            quiet: args.quiet,
            stats: args.stats,
            denoise: args.denoise,
            save: SaveSettings {
                output,
                part,
                layers,
                reference: super::max_rmse::load(args.compare.as_deref())?,
                max_rmse: args.max_rmse,
            },
        })
    }

    /// The sample indices to take of the loaded scene (`--samples`, `--shard`), or the
    /// diagnostic when they do not fit its samples per pixel (or `--compare`'s reference does
    /// not fit its size).
    fn sample_range(&self, prepared: &Prepared) -> Result<Option<Range<u32>>, String> {
        let p = &prepared.render_scene.params;
        if let Some(reference) = &self.save.reference {
            super::max_rmse::check_size(reference, p.width, p.height, self.region)
                .map_err(|e| crate::error_text(&e))?;
        }
        let spp = p.samples_per_pixel;
        match (&self.samples, self.shard) {
            (Some(r), _) if r.end > spp => Err(format!(
                "error: --samples {}..{}: the render has {spp} samples per pixel, so END must be at most {spp}",
                r.start, r.end
            )),
            (Some(r), _) => Ok(Some(r.clone())),
            (None, Some(s)) => s.samples(spp).map(Some).map_err(|e| format!("error: {e}")),
            (None, None) => Ok(None),
        }
    }
}

/// Serves the preview until Ctrl-C, which ends it with [`Error::Interrupted`] (exit code 130).
pub fn run(args: &PreviewArgs) -> Result<(), Error> {
    let settings = Settings::new(&args.render)?;
    // The page shows the scene's file name, not where it is: the status is readable by any
    // local process, and the folder names can say who the user is.
    let shared = Arc::new(Shared::new(scene_name(&settings.scene)));
    let (to_render, from_server) = channel::<Msg>();
    install_interrupt(&shared, &to_render);
    let address = format!("127.0.0.1:{}", args.port.unwrap_or(0));
    let server = server::Server::bind(&address).map_err(|e| {
        Error::Usage(format!(
            "cannot serve the preview on {address}: {e}{}",
            if args.port.is_some() {
                "; choose another --port, or leave it out for a free one"
            } else {
                ""
            }
        ))
    })?;
    let port = server.port();
    let (s, tx) = (Arc::clone(&shared), to_render.clone());
    let mut watch = watch::FileWatch::new(move || {
        // Stop the pass in progress at once; the render thread then reads the scene again.
        s.cancel_render();
        let _ = tx.send(Msg::Changed);
    })
    .map_err(|e| Error::Usage(format!("cannot watch files for changes: {e}")))?;
    println!(
        "preview of `{}` at http://127.0.0.1:{port}/ (Ctrl-C to stop)",
        settings.scene.display()
    );
    let render_shared = Arc::clone(&shared);
    let renderer = std::thread::spawn(move || {
        session::run(&settings, &render_shared, &from_server, &mut watch);
    });
    server.serve(&shared, &to_render, || renderer.is_finished());
    // Ctrl-C: stop the pass in progress and let the render thread end: a save or checkpoint
    // under way finishes first, so no temporary file is left. While the scene loads or photons
    // are traced nothing is being written, and that work does not look at the cancel flag:
    // then the process ends without waiting for it.
    shared.cancel_render();
    let _ = to_render.send(Msg::Quit);
    while !renderer.is_finished() {
        if matches!(shared.status().phase, Phase::Loading | Phase::Photons) {
            return Err(Error::Interrupted("interrupted: preview stopped".into()));
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    let _ = renderer.join();
    Err(Error::Interrupted("interrupted: preview stopped".into()))
}

/// The scene's file name as the page shows it (never its folder).
fn scene_name(scene: &std::path::Path) -> String {
    scene.file_name().map_or_else(
        || scene.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    )
}

/// Ctrl-C (and SIGTERM/SIGHUP): ends the server loop and the render thread cleanly.
fn install_interrupt(shared: &Arc<Shared>, to_render: &Sender<Msg>) {
    let (s, tx) = (Arc::clone(shared), to_render.clone());
    let installed = ctrlc::set_handler(move || {
        s.quit.store(true, Ordering::SeqCst);
        s.cancel_render();
        let _ = tx.send(Msg::Quit);
    });
    if let Err(e) = installed {
        eprintln!("warning: cannot catch Ctrl-C ({e}); interrupting will not clean up");
    }
}
