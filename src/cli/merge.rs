//! `caustic merge`: joins `.part` films (farm shards, or renders of disjoint sample ranges)
//! into one image that is byte-identical to a single render of the same samples. Checks that
//! every part comes from the same scene, settings and seed, and that no sample is counted
//! twice; without `--partial`, that no sample is missing.

use std::ops::Range;
use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::Args;

use caustic::Error;
use caustic::farm::PartMeta;
use caustic::farm::part_meta::format_ranges;
use caustic::render::PixelSums;
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

/// What a merge produced.
pub struct Merged {
    /// The summed films.
    pub sums: PixelSums,
    /// Their metadata: the union of the sample ranges, the summed render time.
    pub meta: PartMeta,
    /// Sample ranges of `0..spp` no part covers.
    pub missing: Vec<Range<u32>>,
}

fn usage(text: String) -> Error {
    Error::Usage(text)
}

/// Reads one part with its metadata.
pub fn read_part(path: &Path) -> Result<(PixelSums, PartMeta), Error> {
    let (sums, text) = PixelSums::read(path).map_err(|e| usage(e.to_string()))?;
    let name = path.display().to_string();
    let meta = PartMeta::parse(&text, &name).map_err(|e| usage(e.to_string()))?;
    let (w, h) = meta
        .region
        .map_or((meta.width, meta.height), |r| (r.width, r.height));
    if (sums.width, sums.height) != (w, h) {
        return Err(usage(format!(
            "`{name}`: its film is {}×{} but its metadata says {w}×{h}",
            sums.width, sums.height
        )));
    }
    Ok((sums, meta))
}

/// Merges the parts, checking that they belong together and that no sample index is taken
/// twice. `expect_hash` additionally pins the settings hash.
///
/// # Errors
/// A clear [`Error::Usage`] naming the files for an unreadable part, parts of different
/// scenes/settings/regions, or overlapping sample ranges; no check on missing samples (see
/// [`Merged::missing`]).
pub fn merge_parts(parts: &[PathBuf], expect_hash: Option<u64>) -> Result<Merged, Error> {
    let Some((first_path, rest)) = parts.split_first() else {
        return Err(usage("no parts to merge".into()));
    };
    let (mut sums, mut meta) = read_part(first_path)?;
    if let Some(h) = expect_hash
        && h != meta.hash
    {
        return Err(usage(format!(
            "`{}` has settings hash {:016x}, not the expected {h:016x}: the scene, its assets, the settings or the caustic version changed since the job was planned",
            first_path.display(),
            meta.hash
        )));
    }
    let mut taken: Vec<(Range<u32>, &Path)> = meta
        .samples
        .iter()
        .map(|r| (r.clone(), first_path.as_path()))
        .collect();
    for path in rest {
        let (s, m) = read_part(path)?;
        let what = if m.hash != meta.hash {
            Some(format!(
                "settings hash {:016x} vs {:016x} (different scene, assets, settings, seed or caustic version)",
                m.hash, meta.hash
            ))
        } else if m.region != meta.region {
            Some("different --region crops".to_string())
        } else {
            None
        };
        if let Some(what) = what {
            return Err(usage(format!(
                "`{}` and `{}` are not parts of the same render: {what}",
                path.display(),
                first_path.display()
            )));
        }
        taken.extend(m.samples.iter().map(|r| (r.clone(), path.as_path())));
        sums.merge(&s).map_err(|e| usage(e.to_string()))?;
        meta.seconds += m.seconds;
    }
    taken.sort_by_key(|(r, _)| (r.start, r.end));
    for pair in taken.windows(2) {
        let ((a, pa), (b, pb)) = (&pair[0], &pair[1]);
        if b.start < a.end {
            let same = if pa == pb {
                format!("`{}` is given twice", pa.display())
            } else {
                format!(
                    "`{}` (samples {}) and `{}` (samples {}) overlap",
                    pa.display(),
                    format_ranges(std::slice::from_ref(a)),
                    pb.display(),
                    format_ranges(std::slice::from_ref(b))
                )
            };
            return Err(usage(format!(
                "{same}: samples {}..{} would be counted twice; merge each shard once",
                b.start,
                a.end.min(b.end)
            )));
        }
    }
    meta.samples = coalesce(taken.into_iter().map(|(r, _)| r));
    let missing = gaps(&meta.samples, meta.spp);
    meta.shard = None;
    Ok(Merged {
        sums,
        meta,
        missing,
    })
}

/// Sorted disjoint ranges with touching neighbours joined.
fn coalesce(sorted: impl Iterator<Item = Range<u32>>) -> Vec<Range<u32>> {
    let mut out: Vec<Range<u32>> = Vec::new();
    for r in sorted {
        match out.last_mut() {
            Some(last) if last.end == r.start => last.end = r.end,
            _ => out.push(r),
        }
    }
    out
}

/// The parts of `0..spp` that sorted disjoint `ranges` leave out.
fn gaps(ranges: &[Range<u32>], spp: u32) -> Vec<Range<u32>> {
    let mut out = Vec::new();
    let mut at = 0;
    for r in ranges {
        if r.start > at {
            out.push(at..r.start);
        }
        at = at.max(r.end);
    }
    if at < spp {
        out.push(at..spp);
    }
    out
}

/// Parses a settings hash as printed in manifests and errors (hex).
pub fn parse_hash(text: &str) -> Result<u64, Error> {
    u64::from_str_radix(text.trim(), 16).map_err(|_| {
        usage(format!(
            "--expect-hash `{text}`: expected 16 hexadecimal digits, as in the farm manifest's `hash`"
        ))
    })
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
    let expect = args.expect_hash.as_deref().map(parse_hash).transpose()?;
    let merged = merge_parts(&args.parts, expect)?;
    let meta = &merged.meta;
    if !merged.missing.is_empty() && !args.partial {
        return Err(usage(format!(
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gaps_and_coalescing_by_hand() {
        assert_eq!(coalesce([0..2, 2..4, 6..8].into_iter()), vec![0..4, 6..8]);
        assert_eq!(gaps(&[0..4, 6..8], 10), vec![4..6, 8..10]);
        assert_eq!(gaps(std::slice::from_ref(&(2..10)), 10), vec![0..2]);
        assert_eq!(
            gaps(std::slice::from_ref(&(0..10)), 10),
            Vec::<Range<u32>>::new()
        );
        assert_eq!(gaps(&[], 3), vec![0..3]);
    }
}
