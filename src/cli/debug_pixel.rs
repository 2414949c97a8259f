//! `caustic debug-pixel`: one pixel sample's ray tree, as text or JSON.

use std::path::PathBuf;

use clap::Args;

use caustic::Error;
use caustic::pipeline::prepare;
use caustic::render::trace_pixel_with;

use super::SceneArgs;

/// Arguments of `caustic debug-pixel`.
#[derive(Args)]
pub struct DebugPixelArgs {
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
    /// Read the photon maps from this folder (saving them there first if missing), as
    /// `caustic render --photon-cache`.
    #[arg(long, value_name = "DIR")]
    photon_cache: Option<PathBuf>,
}

/// Traces the sample exactly as the renderer does and prints its tree.
pub fn run(args: &DebugPixelArgs) -> Result<(), Error> {
    let prepared = prepare(&args.scene.scene, &args.scene.overrides())?;
    let (log, l) = trace_pixel_with(
        &prepared.render_scene,
        args.x,
        args.y,
        args.sample,
        args.photon_cache.as_deref(),
    )?;
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
