//! Golden images for noise-aware snapshot tests (`caustic golden`): a render's per-pixel means
//! and, for every batch of its passes, each block's mean ([`batch_means`]), so that a later
//! render (any seed, thread count or machine) can be judged "the same scene within noise" or
//! "changed" by a statistical test instead of a fixed RMSE threshold — a test whose noise
//! estimate holds for every integrator, the progressive ones included (docs/golden.md).
//!
//! A golden file stores, after a signature, the image size, a metadata text (the settings hash
//! of `farm::part_meta::settings_hash`, the seed, samples per pixel, integrator, sampler,
//! exposure, the command-line overrides of `golden update`, and the scene's settings as
//! `path=value` lines so a check can say which settings changed), per pixel the mean and the
//! variance of the mean per channel as little-endian `f32` (24 bytes a pixel, for the error
//! image), then the block side, the batch count, each batch's samples per pixel and each
//! batch's block means as `f64`, then the cells of the structure test ([`structure`]: the cell
//! side, the cell batch count — 0 when the render has fewer than
//! [`structure::MIN_BATCHES`] batches, which the test needs —, each cell batch's samples per
//! pixel and each cell's mean per batch as `f32`), and an FNV-1a checksum.
//!
//! The modules: [`batch_means`] (the batches and the test), [`floor`] (the smallest change a
//! golden catches and the samples per pixel for a requested one), [`noise_scaling`] (how a
//! golden's noise falls with its samples per pixel; the cap on `photon` replications),
//! [`structure`] (the pattern of light within blocks: a randomization test over small cells),
//! [`record`] (rendering a scene batch by batch), [`report`] (the verdict in words, the settings that changed),
//! [`pixel_variance`] (the older per-pixel-variance block test, valid for estimators whose
//! pixels err independently, used to compare two estimators' images) and [`quantile`].

pub mod batch_means;
pub mod combined;
pub mod floor;
pub mod noise_scaling;
pub mod pixel_variance;
pub mod quantile;
pub mod record;
pub mod report;
pub mod structure;

use std::path::{Path, PathBuf};

use glam::Vec3;

use super::PixelSums;
use super::output::{OutputError, write_atomic};
use crate::binfile::fnv1a;
use crate::binfile::meta_text::{MetaText, malformed};
use crate::render_scene::RenderScene;

pub use batch_means::{BatchBlocks, BatchTest, BatchVerdict};
pub use combined::{GoldenTest, GoldenVerdict, block_alpha};
pub use floor::DetectionFloor;
pub use pixel_variance::{BlockTest, BlockZ, Verdict};
pub use record::{GoldenRender, render_batches};
pub use structure::{StructureSkip, StructureTest, StructureVerdict};

/// File signature of a golden image.
const MAGIC: &[u8; 16] = b"caustic-golden3\n";
/// Signature of the first format (per-pixel variances only), refused with a clear message.
const MAGIC_V1: &[u8; 16] = b"caustic-golden1\n";
/// Signature of the second format (block batches, no cells), refused with a clear message.
const MAGIC_V2: &[u8; 16] = b"caustic-golden2\n";
/// First line of the metadata text.
const HEADER: &str = "caustic-golden 3";

/// Why a golden file could not be read.
#[derive(Debug, thiserror::Error)]
pub enum GoldenError {
    /// Reading failed (a missing file included).
    #[error("cannot read `{path}`: {source}")]
    Io {
        /// The file.
        path: String,
        /// The OS error.
        source: std::io::Error,
    },
    /// Not a golden file, a truncated or corrupt one, or malformed metadata.
    #[error("`{path}` is not a valid caustic golden image: {reason}")]
    Invalid {
        /// The file.
        path: String,
        /// What is wrong.
        reason: String,
    },
    /// The scenes named for a golden run cannot be listed (the message says why).
    #[error("{0}")]
    Scenes(String),
}

/// The scene files named: files as given, folders replaced by their `.ron` and `.toml` files
/// (sorted); refuses two scenes whose golden files would have the same name.
///
/// # Errors
/// [`GoldenError::Scenes`] for an unreadable folder, a folder without scenes, or two scenes
/// whose golden files would have the same name.
pub fn scene_files(first: &Path, more: &[PathBuf]) -> Result<Vec<PathBuf>, GoldenError> {
    let mut out = Vec::new();
    for path in std::iter::once(first).chain(more.iter().map(PathBuf::as_path)) {
        if path.is_dir() {
            let entries = std::fs::read_dir(path).map_err(|e| {
                GoldenError::Scenes(format!("cannot read the folder `{}`: {e}", path.display()))
            })?;
            let mut found: Vec<PathBuf> = entries
                .filter_map(Result::ok)
                .map(|e| e.path())
                .filter(|p| {
                    p.is_file()
                        && matches!(p.extension().and_then(|e| e.to_str()), Some("ron" | "toml"))
                })
                .collect();
            if found.is_empty() {
                return Err(GoldenError::Scenes(format!(
                    "the folder `{}` holds no scene (.ron or .toml) files",
                    path.display()
                )));
            }
            found.sort();
            out.extend(found);
        } else {
            out.push(path.to_path_buf());
        }
    }
    let mut names: Vec<(String, &PathBuf)> = out.iter().map(|p| (golden_file_name(p), p)).collect();
    names.sort();
    for w in names.windows(2) {
        if w[0].0 == w[1].0 {
            return Err(GoldenError::Scenes(format!(
                "`{}` and `{}` would share the golden file `{}`; check them with separate --golden folders",
                w[0].1.display(),
                w[1].1.display(),
                w[0].0
            )));
        }
    }
    Ok(out)
}

/// The golden file's name for a scene: its file name and `.golden` (`cornell.ron.golden`).
#[must_use]
pub fn golden_file_name(scene: &Path) -> String {
    let name = scene
        .file_name()
        .map_or_else(|| "scene".into(), |n| n.to_string_lossy().into_owned());
    format!("{name}.golden")
}

/// Per-pixel estimates of an image: each pixel's mean radiance and the variance of that mean
/// (the samples' unbiased variance over their count), row-major from the top-left.
#[derive(Debug, Clone, PartialEq)]
pub struct PixelEstimates {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Mean linear radiance per pixel.
    pub mean: Vec<Vec3>,
    /// Variance of each pixel's mean per channel (squared radiance units); 0 where a pixel
    /// has fewer than two samples.
    pub variance: Vec<Vec3>,
}

impl PixelEstimates {
    /// The estimates of a rendered film's sums.
    #[must_use]
    pub fn from_sums(sums: &PixelSums) -> Self {
        let n = sums.width as usize * sums.height as usize;
        let mut mean = Vec::with_capacity(n);
        let mut variance = Vec::with_capacity(n);
        for i in 0..n {
            mean.push(sums.mean(i));
            let count = sums.count(i);
            variance.push(if count < 2 {
                Vec3::ZERO
            } else {
                sums.variance(i) / count as f32
            });
        }
        Self {
            width: sums.width,
            height: sums.height,
            mean,
            variance,
        }
    }
}

/// What a golden image records about the render it holds.
#[derive(Debug, Clone, PartialEq)]
pub struct GoldenMeta {
    /// [`super::part_meta::settings_hash`] of the compiled scene after overrides.
    pub hash: u64,
    /// The seed it was rendered with (a check renders with another one by default).
    pub seed: u64,
    /// Samples per pixel.
    pub spp: u32,
    /// The integrator's name (`Path`, `PathPpm`, ...).
    pub integrator: String,
    /// The sampler's name (`Sobol`, `Independent`).
    pub sampler: String,
    /// The scene's exposure.
    pub exposure: f32,
    /// Informational: the scene file rendered.
    pub scene: String,
    /// The command-line overrides of `golden update` as `key=value` (`set=PATH=VALUE`,
    /// `width=64`, ...), which `golden check` applies again.
    pub overrides: Vec<(String, String)>,
    /// The scene's settings after overrides as `(path, value)`, sorted by path, so a check
    /// can name the ones that changed.
    pub settings: Vec<(String, String)>,
}

impl GoldenMeta {
    /// What a golden of `scene` (whose settings hash is `hash`) records: its seed, samples per
    /// pixel, integrator, sampler and exposure from the render parameters; the informational
    /// scene path, the recorded overrides and the settings are empty, for the caller to set.
    #[must_use]
    pub fn of(scene: &RenderScene, hash: u64) -> Self {
        let p = &scene.params;
        Self {
            hash,
            seed: p.seed,
            spp: p.samples_per_pixel,
            integrator: format!("{:?}", p.integrator),
            sampler: format!("{:?}", p.sampler),
            exposure: p.exposure,
            scene: String::new(),
            overrides: Vec::new(),
            settings: Vec::new(),
        }
    }

    /// The metadata text stored in the file: one `key=value` per line.
    #[must_use]
    pub fn to_text(&self) -> String {
        let clean = |s: &str| s.replace(['\n', '\r'], " ");
        let mut t = format!(
            "{HEADER}\nhash={:016x}\nseed={}\nspp={}\nintegrator={}\nsampler={}\nexposure={:?}\nscene={}\n",
            self.hash,
            self.seed,
            self.spp,
            clean(&self.integrator),
            clean(&self.sampler),
            self.exposure,
            clean(&self.scene)
        );
        for (k, v) in &self.overrides {
            t.push_str(&format!("override.{}={}\n", clean(k), clean(v)));
        }
        for (k, v) in &self.settings {
            t.push_str(&format!("setting.{}={}\n", clean(k), clean(v)));
        }
        t
    }

    /// Reads [`GoldenMeta::to_text`]'s output; `path` names the file in errors.
    ///
    /// # Errors
    /// [`GoldenError::Invalid`] when the header is not this format's or a field is missing or
    /// malformed.
    pub fn parse(text: &str, path: &str) -> Result<Self, GoldenError> {
        let err = |reason: String| GoldenError::Invalid {
            path: path.to_string(),
            reason,
        };
        let m = MetaText::parse(text, HEADER)
            .ok_or_else(|| err(format!("its metadata does not start with `{HEADER}`")))?;
        let get = |key: &str| m.get(key).map_err(&err);
        let hash_text = get("hash")?;
        Ok(Self {
            hash: u64::from_str_radix(hash_text, 16)
                .map_err(|_| err(malformed("hash", hash_text)))?,
            seed: m.parsed("seed").map_err(&err)?,
            spp: m.parsed("spp").map_err(&err)?,
            integrator: get("integrator")?.to_string(),
            sampler: get("sampler")?.to_string(),
            exposure: m.parsed("exposure").map_err(&err)?,
            scene: get("scene")?.to_string(),
            overrides: m.prefixed("override."),
            settings: m.prefixed("setting."),
        })
    }
}

/// A golden image: the estimates of a render, its batches and what it was rendered from.
#[derive(Debug, Clone, PartialEq)]
pub struct GoldenImage {
    /// Means and variances of the means per pixel (for the error image).
    pub estimates: PixelEstimates,
    /// Each block's mean in each batch of passes (for the test).
    pub batches: BatchBlocks,
    /// Each cell's mean in each (merged) batch, for the structure test; no batch when the
    /// render had fewer than [`structure::MIN_BATCHES`].
    pub cells: BatchBlocks,
    /// Settings hash, seed, overrides and settings.
    pub meta: GoldenMeta,
}

impl GoldenImage {
    /// The file's bytes (see the module documentation).
    #[must_use]
    pub fn to_bytes(&self) -> Vec<u8> {
        let e = &self.estimates;
        let meta = self.meta.to_text();
        let mut out = Vec::with_capacity(48 + meta.len() + e.mean.len() * 24);
        out.extend_from_slice(MAGIC);
        out.extend_from_slice(&e.width.to_le_bytes());
        out.extend_from_slice(&e.height.to_le_bytes());
        out.extend_from_slice(&(meta.len() as u64).to_le_bytes());
        out.extend_from_slice(meta.as_bytes());
        for (m, v) in e.mean.iter().zip(&e.variance) {
            for x in m.to_array().into_iter().chain(v.to_array()) {
                out.extend_from_slice(&x.to_le_bytes());
            }
        }
        let b = &self.batches;
        out.extend_from_slice(&b.block.to_le_bytes());
        out.extend_from_slice(&(b.batches() as u32).to_le_bytes());
        for s in &b.samples {
            out.extend_from_slice(&s.to_le_bytes());
        }
        for m in &b.means {
            for x in m {
                out.extend_from_slice(&x.to_le_bytes());
            }
        }
        let c = &self.cells;
        let kept = c.batches() >= structure::MIN_BATCHES;
        out.extend_from_slice(&c.block.to_le_bytes());
        out.extend_from_slice(&(if kept { c.batches() as u32 } else { 0 }).to_le_bytes());
        if kept {
            for s in &c.samples {
                out.extend_from_slice(&s.to_le_bytes());
            }
            for m in &c.means {
                for x in m {
                    out.extend_from_slice(&(*x as f32).to_le_bytes());
                }
            }
        }
        let sum = fnv1a(&out);
        out.extend_from_slice(&sum.to_le_bytes());
        out
    }

    /// Reads what [`GoldenImage::to_bytes`] wrote; `name` is used in errors.
    ///
    /// # Errors
    /// [`GoldenError::Invalid`] for a wrong signature, a truncated or corrupt file or bad
    /// metadata.
    pub fn from_bytes(bytes: &[u8], name: &str) -> Result<Self, GoldenError> {
        let bad = |reason: &str| GoldenError::Invalid {
            path: name.to_string(),
            reason: reason.to_string(),
        };
        if bytes.len() >= MAGIC_V1.len() && &bytes[..MAGIC_V1.len()] == MAGIC_V1 {
            return Err(bad(
                "it was written by an older caustic (per-pixel variances, no batches); write it again with `caustic golden update`",
            ));
        }
        if bytes.len() >= MAGIC_V2.len() && &bytes[..MAGIC_V2.len()] == MAGIC_V2 {
            return Err(bad(
                "it was written by an older caustic (block batches only, without the cells of the structure test); write it again with `caustic golden update`",
            ));
        }
        if bytes.len() < MAGIC.len() + 24 || &bytes[..MAGIC.len()] != MAGIC {
            return Err(bad(
                "no caustic golden signature (write it with `caustic golden update`)",
            ));
        }
        let (body, tail) = bytes.split_at(bytes.len() - 8);
        let stored = u64::from_le_bytes(tail.try_into().map_err(|_| bad("truncated"))?);
        if fnv1a(body) != stored {
            return Err(bad("checksum mismatch (truncated or corrupt)"));
        }
        let word = |at: usize| -> [u8; 4] {
            let mut w = [0; 4];
            w.copy_from_slice(&body[at..at + 4]);
            w
        };
        let at = MAGIC.len();
        let width = u32::from_le_bytes(word(at));
        let height = u32::from_le_bytes(word(at + 4));
        let mut len = [0; 8];
        len.copy_from_slice(&body[at + 8..at + 16]);
        let meta_len = usize::try_from(u64::from_le_bytes(len)).map_err(|_| bad("absurd size"))?;
        let start = at + 16;
        let n = width as usize * height as usize;
        let pixels_end = n
            .checked_mul(24)
            .and_then(|p| p.checked_add(meta_len))
            .and_then(|p| p.checked_add(start))
            .ok_or_else(|| bad("absurd size"))?;
        if pixels_end.checked_add(8).is_none_or(|e| e > body.len()) {
            return Err(bad("size does not match its header"));
        }
        let text = std::str::from_utf8(&body[start..start + meta_len])
            .map_err(|_| bad("metadata is not UTF-8"))?;
        let meta = GoldenMeta::parse(text, name)?;
        let mut mean = Vec::with_capacity(n);
        let mut variance = Vec::with_capacity(n);
        let f = |at: usize| f32::from_le_bytes(word(at));
        for i in 0..n {
            let p = start + meta_len + i * 24;
            mean.push(Vec3::new(f(p), f(p + 4), f(p + 8)));
            variance.push(Vec3::new(f(p + 12), f(p + 16), f(p + 20)));
        }
        let block = u32::from_le_bytes(word(pixels_end));
        let count = u32::from_le_bytes(word(pixels_end + 4)) as usize;
        if block == 0 {
            return Err(bad("its block side is 0"));
        }
        let mut batches = BatchBlocks::new(width, height, block);
        let blocks = batches.blocks();
        let cells_at = count
            .checked_mul(4)
            .and_then(|s| s.checked_add(count.checked_mul(blocks)?.checked_mul(24)?))
            .and_then(|s| s.checked_add(pixels_end + 8))
            .ok_or_else(|| bad("absurd size"))?;
        if cells_at.checked_add(8).is_none_or(|e| e > body.len()) {
            return Err(bad("size does not match its header"));
        }
        let cell = u32::from_le_bytes(word(cells_at));
        let cell_count = u32::from_le_bytes(word(cells_at + 4)) as usize;
        if cell == 0 {
            return Err(bad("its cell side is 0"));
        }
        let mut cells = BatchBlocks::new(width, height, cell);
        let cell_blocks = cells.blocks();
        let expected = cell_count
            .checked_mul(4)
            .and_then(|s| s.checked_add(cell_count.checked_mul(cell_blocks)?.checked_mul(12)?))
            .and_then(|s| s.checked_add(cells_at + 8))
            .ok_or_else(|| bad("absurd size"))?;
        if expected != body.len() {
            return Err(bad("size does not match its header"));
        }
        let mut at = pixels_end + 8;
        for _ in 0..count {
            batches.samples.push(u32::from_le_bytes(word(at)));
            at += 4;
        }
        let d = |at: usize| {
            let mut w = [0; 8];
            w.copy_from_slice(&body[at..at + 8]);
            f64::from_le_bytes(w)
        };
        for _ in 0..count * blocks {
            batches.means.push([d(at), d(at + 8), d(at + 16)]);
            at += 24;
        }
        at += 8;
        for _ in 0..cell_count {
            cells.samples.push(u32::from_le_bytes(word(at)));
            at += 4;
        }
        let s = |at: usize| f64::from(f(at));
        for _ in 0..cell_count * cell_blocks {
            cells.means.push([s(at), s(at + 4), s(at + 8)]);
            at += 12;
        }
        Ok(Self {
            estimates: PixelEstimates {
                width,
                height,
                mean,
                variance,
            },
            batches,
            cells,
            meta,
        })
    }

    /// Reads a golden file.
    ///
    /// # Errors
    /// As [`GoldenImage::from_bytes`], or [`GoldenError::Io`].
    pub fn read(path: &Path) -> Result<Self, GoldenError> {
        let bytes = std::fs::read(path).map_err(|source| GoldenError::Io {
            path: path.display().to_string(),
            source,
        })?;
        Self::from_bytes(&bytes, &path.display().to_string())
    }

    /// Writes the golden atomically (temporary file + rename).
    ///
    /// # Errors
    /// When the file cannot be written.
    pub fn write(&self, path: &Path) -> Result<(), OutputError> {
        write_atomic(path, &self.to_bytes())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn golden() -> GoldenImage {
        let mut sums = PixelSums::new(3, 2);
        for (i, v) in [(0, 0.5), (0, 1.5), (0, 1.0), (4, 2.0), (4, 4.0), (5, 7.0)] {
            sums.add(i, Vec3::new(v, v * 2.0, 0.25));
        }
        let mut batches = BatchBlocks::new(3, 2, 2);
        batches.push_batch(&[glam::DVec3::splat(0.5); 6], 1);
        batches.push_batch(&[glam::DVec3::new(1.0, 2.0, 3.0); 6], 2);
        let mut cells = BatchBlocks::new(3, 2, structure::CELL);
        for j in 0..structure::MIN_BATCHES {
            cells.push_batch(&[glam::DVec3::splat(j as f64 * 0.25); 6], 1);
        }
        GoldenImage {
            estimates: PixelEstimates::from_sums(&sums),
            batches,
            cells,
            meta: GoldenMeta {
                hash: 0xfeed_0000_beef,
                seed: 7,
                spp: 3,
                integrator: "Path".into(),
                sampler: "Sobol".into(),
                exposure: 1.0,
                scene: "scenes/cornell.ron".into(),
                overrides: vec![
                    ("set".into(), "lights[0].power=[1, 2, 3]".into()),
                    ("width".into(), "64".into()),
                ],
                settings: vec![("render.width".into(), "64".into())],
            },
        }
    }

    #[test]
    fn estimates_are_the_mean_and_the_variance_of_the_mean() {
        let e = golden().estimates;
        // Pixel 0: samples 0.5, 1.5, 1.0 → mean 1, sample variance 0.25, of the mean 0.25/3.
        assert_eq!(e.mean[0].x, 1.0);
        assert!(
            (e.variance[0].x - 0.25 / 3.0).abs() < 1e-6,
            "{}",
            e.variance[0]
        );
        assert!((e.variance[0].y - 1.0 / 3.0).abs() < 1e-6);
        assert_eq!(e.variance[0].z, 0.0);
        // Pixel 4: 2 and 4 → variance 2, of the mean 1. Pixel 5: one sample, no estimate.
        assert!((e.variance[4].x - 1.0).abs() < 1e-6);
        assert_eq!((e.mean[5].x, e.variance[5].x), (7.0, 0.0));
    }

    #[test]
    fn files_round_trip_and_corruption_is_detected() {
        let g = golden();
        let bytes = g.to_bytes();
        assert_eq!(GoldenImage::from_bytes(&bytes, "g").unwrap(), g);
        for cut in [0, 20, bytes.len() / 2, bytes.len() - 1] {
            assert!(
                GoldenImage::from_bytes(&bytes[..cut], "g").is_err(),
                "{cut}"
            );
        }
        let mut old = bytes.clone();
        old[..16].copy_from_slice(MAGIC_V1);
        let e = GoldenImage::from_bytes(&old, "g.golden").unwrap_err();
        assert!(e.to_string().contains("older caustic"), "{e}");
        old[..16].copy_from_slice(MAGIC_V2);
        let e = GoldenImage::from_bytes(&old, "g.golden").unwrap_err();
        assert!(e.to_string().contains("without the cells"), "{e}");
        // Too few cell batches for the structure test: none are stored.
        let mut few = g.clone();
        few.cells = BatchBlocks::new(3, 2, structure::CELL);
        few.cells.push_batch(&[glam::DVec3::ONE; 6], 1);
        let back = GoldenImage::from_bytes(&few.to_bytes(), "g").unwrap();
        assert_eq!(back.cells.batches(), 0);
        let mut flipped = bytes.clone();
        flipped[bytes.len() - 30] ^= 4;
        let e = GoldenImage::from_bytes(&flipped, "g.golden").unwrap_err();
        assert!(e.to_string().contains("checksum"), "{e}");
        let text = g.meta.to_text().replace("seed=7", "seed=x");
        let e = GoldenMeta::parse(&text, "g.golden").unwrap_err();
        assert!(e.to_string().contains("`seed=x` is malformed"), "{e}");
    }
}
