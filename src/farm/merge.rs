//! Merging `.part` films (farm shards, or renders of disjoint sample ranges) into the film of
//! their union, byte-identical to a single render of the same samples: every part must carry
//! the same settings hash (same scene, assets, settings, seed and caustic version) and region,
//! and no sample index may be taken twice. `caustic merge` and `caustic farm status` use it.

use std::ops::Range;
use std::path::{Path, PathBuf};

use super::PartMeta;
use super::part_meta::format_ranges;
use crate::render::PixelSums;

/// Why parts could not be read or merged: the message names the files and what differs.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct MergeError(pub String);

/// What a merge produced.
pub struct Merged {
    /// The summed films.
    pub sums: PixelSums,
    /// Their metadata: the union of the sample ranges, the summed render time.
    pub meta: PartMeta,
    /// Sample ranges of `0..spp` no part covers.
    pub missing: Vec<Range<u32>>,
}

/// Reads one part with its metadata.
pub fn read_part(path: &Path) -> Result<(PixelSums, PartMeta), MergeError> {
    let (sums, text) = PixelSums::read(path).map_err(|e| MergeError(e.to_string()))?;
    let name = path.display().to_string();
    let meta = PartMeta::parse(&text, &name).map_err(|e| MergeError(e.to_string()))?;
    let (w, h) = meta
        .region
        .map_or((meta.width, meta.height), |r| (r.width, r.height));
    if (sums.width, sums.height) != (w, h) {
        return Err(MergeError(format!(
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
/// A [`MergeError`] naming the files for an unreadable part, parts of different
/// scenes/settings/regions, or overlapping sample ranges; no check on missing samples (see
/// [`Merged::missing`]).
pub fn merge_parts(parts: &[PathBuf], expect_hash: Option<u64>) -> Result<Merged, MergeError> {
    let Some((first_path, rest)) = parts.split_first() else {
        return Err(MergeError("no parts to merge".into()));
    };
    let (mut sums, mut meta) = read_part(first_path)?;
    if let Some(h) = expect_hash
        && h != meta.hash
    {
        return Err(MergeError(format!(
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
            return Err(MergeError(format!(
                "`{}` and `{}` are not parts of the same render: {what}",
                path.display(),
                first_path.display()
            )));
        }
        taken.extend(m.samples.iter().map(|r| (r.clone(), path.as_path())));
        sums.merge(&s).map_err(|e| MergeError(e.to_string()))?;
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
            return Err(MergeError(format!(
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
pub fn parse_hash(text: &str) -> Result<u64, MergeError> {
    u64::from_str_radix(text.trim(), 16).map_err(|_| {
        MergeError(format!(
            "--expect-hash `{text}`: expected 16 hexadecimal digits, as in the farm manifest's `hash`"
        ))
    })
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
