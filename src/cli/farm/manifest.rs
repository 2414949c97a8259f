//! The farm job folder's `manifest.json`: what `caustic farm plan` decided (the settings hash,
//! the shards and their sample ranges, the Slurm resources, the binary), read back by
//! `farm status`, `farm cache` and the merge job.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use caustic::Error;

/// First field of the manifest: format and version.
pub const FORMAT: &str = "caustic-farm 1";
/// The manifest's file name in the job folder.
pub const FILE: &str = "manifest.json";
/// The resolved scene's file name in the job folder.
pub const SCENE: &str = "scene.ron";
/// Folder of the shards' `.part` films in the job folder.
pub const SHARDS: &str = "shards";
/// Folder of the photon-map cache in the job folder.
pub const PHOTONS: &str = "photons";
/// Folder of the Slurm logs in the job folder.
pub const LOGS: &str = "logs";

/// A planned farm job (`DIR/manifest.json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// [`FORMAT`].
    pub format: String,
    /// Settings hash of the resolved scene (16 hex digits), as in every shard's `.part`.
    pub hash: String,
    /// The scene file the job was planned from (for the record; shards render `scene.ron`).
    pub source_scene: PathBuf,
    /// The command-line overrides applied to it, as `path=value` (already in `scene.ron`).
    pub overrides: Vec<String>,
    /// Number of shards (array tasks).
    pub shards: u32,
    /// Samples per pixel of the whole render.
    pub samples_per_pixel: u32,
    /// Sample range `[start, end)` of each shard, shard 1 first.
    pub ranges: Vec<[u32; 2]>,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// The integrator's name.
    pub integrator: String,
    /// Absolute path of the `caustic` binary the job scripts run.
    pub caustic: PathBuf,
    /// Slurm time limit of each shard (`#SBATCH --time`).
    pub time_limit: String,
    /// Render-time budget of each shard in seconds (`render --time`; `None` under a 2-minute
    /// limit): a shard that is slower than planned stops there and writes the samples it took.
    #[serde(default)]
    pub shard_budget_seconds: Option<u64>,
    /// CPUs per shard (`#SBATCH --cpus-per-task`, passed to `--threads`).
    pub cpus_per_task: u32,
    /// The merged images the merge job writes, relative to the job folder.
    pub outputs: Vec<String>,
}

impl Manifest {
    /// The `.part` file of shard `index` (1-based) in job folder `dir`.
    #[must_use]
    pub fn shard_path(dir: &Path, index: u32) -> PathBuf {
        dir.join(SHARDS).join(format!("shard-{index}.part"))
    }

    /// Reads `dir/manifest.json`.
    ///
    /// # Errors
    /// [`Error::Usage`] naming the file when it is missing, not JSON of this format, or of
    /// another format version.
    pub fn read(dir: &Path) -> Result<Self, Error> {
        let path = dir.join(FILE);
        let text = std::fs::read_to_string(&path).map_err(|e| {
            Error::Usage(format!(
                "cannot read `{}`: {e} (is `{}` a folder written by `caustic farm plan`?)",
                path.display(),
                dir.display()
            ))
        })?;
        let m: Self = serde_json::from_str(&text).map_err(|e| {
            Error::Usage(format!(
                "`{}`: not a caustic farm manifest: {e}",
                path.display()
            ))
        })?;
        if m.format != FORMAT {
            return Err(Error::Usage(format!(
                "`{}`: format `{}`, expected `{FORMAT}`; plan the job again with this caustic",
                path.display(),
                m.format
            )));
        }
        Ok(m)
    }

    /// The settings hash as a number.
    ///
    /// # Errors
    /// When the manifest's `hash` is not hexadecimal.
    pub fn hash_value(&self) -> Result<u64, Error> {
        caustic::farm::merge::parse_hash(&self.hash).map_err(super::super::merge::usage)
    }
}
