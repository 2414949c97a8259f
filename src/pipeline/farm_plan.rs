//! `caustic farm plan`'s library half over the front half: the scene prepared for a plan (a
//! plan in time gets [`crate::farm::plan::time_plan_spp`] samples per pixel), and the resolved
//! scene written into the job folder and proven to render like the planned one. The shards'
//! ranges, budgets and the resolved scene's text are [`crate::farm::plan`]'s; the binary writes
//! the manifest and the Slurm scripts.

use std::path::Path;
use std::time::Duration;

use super::{Prepared, SceneOverrides, prepare};
use crate::Error;
use crate::farm::part_meta::settings_hash;
use crate::farm::plan::{DEFAULT_TIME, resolved_scene, time_plan_spp};
use crate::render::output::write_atomic;

/// A scene prepared for a farm plan.
#[derive(Debug)]
pub struct PlannedScene {
    /// The compiled scene, its warnings and figures.
    pub prepared: Prepared,
    /// The overrides it was compiled with (the command line's, and a plan in time's samples).
    pub overrides: SceneOverrides,
    /// Its settings hash, which every shard's `.part` carries.
    pub hash: u64,
    /// Whether the plan is in time (`--time` without `--spp`): every shard renders its range
    /// until its budget is spent.
    pub in_time: bool,
    /// The time limit of each shard ([`DEFAULT_TIME`] unless given).
    pub time: Duration,
}

/// Prepares `scene` with `overrides` for `shards` shards under the time limit `time`
/// (`None`: [`DEFAULT_TIME`]); given without stated samples per pixel, the plan is in time.
///
/// # Errors
/// [`crate::farm::plan::PlanError`]'s for a plan in time, the scene's errors.
pub fn prepare_plan(
    scene: &Path,
    overrides: &SceneOverrides,
    shards: u32,
    time: Option<Duration>,
) -> Result<PlannedScene, Error> {
    let mut overrides = overrides.clone();
    let limit = time.unwrap_or(DEFAULT_TIME);
    // `--time` without `--spp`: a plan in time, every shard renders until its budget.
    let in_time = time.is_some() && overrides.render.samples_per_pixel.is_none();
    if in_time {
        overrides.render.samples_per_pixel = Some(time_plan_spp(shards, limit)?);
    }
    let prepared = prepare(scene, &overrides)?;
    let hash = settings_hash(&prepared.render_scene);
    Ok(PlannedScene {
        prepared,
        overrides,
        hash,
        in_time,
        time: limit,
    })
}

impl PlannedScene {
    /// Writes the resolved scene of `source` (this plan's scene file) to `path` and reads it
    /// back: it must render with this plan's settings hash, without the command line.
    ///
    /// # Errors
    /// [`Error::Usage`] when the scene's folder has no absolute path or the resolved scene
    /// renders differently; the resolved scene's and the writer's errors.
    pub fn write_resolved_scene(&self, source: &Path, path: &Path) -> Result<(), Error> {
        let base = self.prepared.source.base_dir();
        let base = std::path::absolute(if base.as_os_str().is_empty() {
            Path::new(".")
        } else {
            &base
        })
        .map_err(|e| Error::Usage(format!("cannot write `{}`: {e}", base.display())))?;
        let params = &self.prepared.render_scene.params;
        let text = resolved_scene(&self.prepared.scene, params, &base, source)?;
        write_atomic(path, text.as_bytes())?;
        // The shards render the resolved scene: it must be the very scene that was planned.
        let again = prepare(path, &SceneOverrides::default())?;
        if settings_hash(&again.render_scene) != self.hash {
            return Err(Error::Usage(format!(
                "the resolved scene `{}` does not render like `{}` with its overrides (a field that does not survive RON); please report this",
                path.display(),
                source.display()
            )));
        }
        Ok(())
    }
}
