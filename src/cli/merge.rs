//! `caustic merge`: joins `.part` films (farm shards, or renders of disjoint sample ranges)
//! into one image that is byte-identical to a single render of the same samples; the checks and
//! the merging are [`caustic::farm::merge`]'s. Without `--partial`, refuses missing samples.

use std::path::PathBuf;
use std::time::Instant;

use clap::Args;

use caustic::Error;
use caustic::farm::merge::{MergeError, merge_parts, parse_hash};
use caustic::farm::part_meta::format_ranges;
use caustic::render::auto_exposure::{resolve, tonemap_for};
use caustic::render::output::{OutputFormat, check_writable, write_image};

use super::render::is_part;

/// Arguments of `caustic merge`.
#[derive(Args)]
pub struct MergeArgs {
    /// The `.part` films to merge (written by `caustic render --shard I/N -o FILE.part`).
    #[arg(required = true, value_name = "PARTS")]
    parts: Vec<PathBuf>,
    /// Output: `.exr`, `.png` or `.part` (the merged film, mergeable again); repeat for several.
    #[arg(short, long, required = true)]
    output: Vec<PathBuf>,
    /// Merge whatever parts are given even when samples are missing (a failed or cancelled
    /// shard): the image then has fewer samples per pixel, and the summary says how many.
    #[arg(long)]
    partial: bool,
    /// Refuse parts whose settings hash is not this one (16 hex digits, from the farm's
    /// manifest), e.g. a scene or asset edited after `caustic farm plan`.
    #[arg(long, value_name = "HASH")]
    expect_hash: Option<String>,
}

/// A merge error as the command reports it (exit code 2).
pub fn usage(e: MergeError) -> Error {
    Error::Usage(e.0)
}

/// Merges and writes the outputs.
pub fn run(args: &MergeArgs) -> Result<(), Error> {
    let start = Instant::now();
    for out in &args.output {
        if !is_part(out) {
            OutputFormat::for_path(out)?;
        }
        check_writable(out)?;
    }
    let expect = (args.expect_hash.as_deref().map(parse_hash).transpose()).map_err(usage)?;
    let merged = merge_parts(&args.parts, expect).map_err(usage)?;
    let meta = &merged.meta;
    if !merged.missing.is_empty() && !args.partial {
        return Err(Error::Usage(format!(
            "samples {} of the {} per pixel are in none of the {} parts (a shard that failed or has not finished?); pass --partial to merge what is there",
            format_ranges(&merged.missing),
            meta.spp,
            args.parts.len()
        )));
    }
    let film = merged.sums.to_film();
    for out in &args.output {
        if is_part(out) {
            merged.sums.write(out, &meta.to_text())?;
        } else {
            // A non-finite exposure is an automatic one (`render` writes NaN): chosen from the
            // merged film, as the single render chooses it from its own.
            let stated = meta.exposure.is_finite().then_some(meta.exposure);
            let (display, _) = resolve(&film, stated, tonemap_for(stated, None));
            write_image(&film, out, display)?;
        }
    }
    let names: Vec<String> = args
        .output
        .iter()
        .map(|p| p.display().to_string())
        .collect();
    let missing = if merged.missing.is_empty() {
        String::new()
    } else {
        format!(
            " (partial: samples {} missing)",
            format_ranges(&merged.missing)
        )
    };
    println!(
        "{}: merged {} parts, {} of {} samples per pixel{missing}, in {:.3} s",
        names.join(", "),
        args.parts.len(),
        meta.sample_count(),
        meta.spp,
        start.elapsed().as_secs_f64()
    );
    Ok(())
}
