//! What `caustic farm plan` decides before it writes a job folder: the shards' sample ranges,
//! a shard's render budget under its Slurm time limit, the samples per pixel of a plan in time,
//! and the resolved scene the shards render (the scene with its overrides applied, every
//! setting pinned to the value in effect and asset paths absolute, as RON).

use std::path::Path;
use std::time::Duration;

use serde_json::Value;

use super::Shard;
use crate::render_scene::RenderParams;
use crate::scene::SceneFile;

/// Samples per pixel each shard's range holds in a plan in time (`--time` without `--spp`):
/// more than any shard renders within a Slurm time limit.
pub const TIME_PLAN_SPP_PER_SHARD: u32 = 1 << 16;

/// The default time limit of a shard.
pub const DEFAULT_TIME: Duration = Duration::from_secs(3600);

/// Why a farm plan is refused; each text names the flag and what is valid. Converted into
/// [`crate::Error::Usage`].
#[derive(Debug, thiserror::Error)]
pub enum PlanError {
    /// A plan in time under a limit too short for a budget ([`shard_budget`]), in seconds.
    #[error(
        "--time {0}s without --spp plans shards that render until their time is spent, which needs a limit of at least 2 minutes; give a longer --time or --spp"
    )]
    TimeTooShort(u64),
    /// More shards than a plan in time can number.
    #[error("--shards {0}: at most {max} shards in a plan in time", max = u32::MAX / TIME_PLAN_SPP_PER_SHARD)]
    TooManyShards(u32),
    /// More shards than samples per pixel.
    #[error("{0}; or give --time without --spp, for shards that render until their time is spent")]
    Shard(super::shard::ShardError),
    /// The resolved scene cannot be written as RON.
    #[error("cannot write the resolved scene of `{}`: {reason}", from.display())]
    Resolve {
        /// The scene file planned.
        from: std::path::PathBuf,
        /// What failed.
        reason: String,
    },
}

impl From<PlanError> for crate::Error {
    fn from(e: PlanError) -> Self {
        crate::Error::Usage(e.to_string())
    }
}

/// The render-time budget of a shard under a Slurm time limit: the limit less a tenth and
/// 30 s (for loading the scene and photon cache, writing the film, and one pass of overrun),
/// so that a slow shard stops early and writes the samples it took instead of being killed
/// with nothing; none under 2 minutes.
#[must_use]
pub fn shard_budget(limit: Duration) -> Option<Duration> {
    (limit >= Duration::from_secs(120))
        .then(|| Duration::from_secs((limit - limit / 10 - Duration::from_secs(30)).as_secs()))
}

/// The samples per pixel of a plan in time of `shards` shards under the time limit `limit`:
/// [`TIME_PLAN_SPP_PER_SHARD`] each.
///
/// # Errors
/// [`PlanError::TimeTooShort`] when the limit leaves no budget, [`PlanError::TooManyShards`].
pub fn time_plan_spp(shards: u32, limit: Duration) -> Result<u32, PlanError> {
    if shard_budget(limit).is_none() {
        return Err(PlanError::TimeTooShort(limit.as_secs()));
    }
    shards
        .checked_mul(TIME_PLAN_SPP_PER_SHARD)
        .ok_or(PlanError::TooManyShards(shards))
}

/// The sample range `[start, end)` of each of `shards` shards of `spp` samples per pixel,
/// shard 1 first.
///
/// # Errors
/// [`PlanError::Shard`] when there are more shards than samples.
pub fn shard_ranges(shards: u32, spp: u32) -> Result<Vec<[u32; 2]>, PlanError> {
    (1..=shards)
        .map(|index| {
            let r = Shard {
                index,
                count: shards,
            }
            .samples(spp)
            .map_err(PlanError::Shard)?;
            Ok([r.start, r.end])
        })
        .collect()
}

/// Makes every relative `file` field (meshes, image textures) absolute against `base`.
fn absolute_assets(v: &mut Value, base: &Path) {
    match v {
        Value::Object(map) => {
            for (key, x) in map.iter_mut() {
                match x {
                    Value::String(s) if key == "file" && Path::new(s.as_str()).is_relative() => {
                        *s = base.join(s.as_str()).display().to_string();
                    }
                    _ => absolute_assets(x, base),
                }
            }
        }
        Value::Array(items) => items.iter_mut().for_each(|x| absolute_assets(x, base)),
        _ => {}
    }
}

/// The scene `scene` (read from `from`, its assets relative to `base`, compiled with
/// `params`) as RON with every setting pinned to the value in effect and asset paths
/// absolute, so that it renders the same from the job folder without the command line.
///
/// # Errors
/// [`PlanError::Resolve`] when the scene does not survive the round trip to RON.
pub fn resolved_scene(
    scene: &SceneFile,
    params: &RenderParams,
    base: &Path,
    from: &Path,
) -> Result<String, PlanError> {
    let fail = |e: String| PlanError::Resolve {
        from: from.to_path_buf(),
        reason: e,
    };
    // Every setting pinned to the value in effect (the stated ones over their defaults).
    let mut tree =
        serde_json::to_value(scene.with_default_settings()).map_err(|e| fail(e.to_string()))?;
    absolute_assets(&mut tree, base);
    pin_default_estimator(&mut tree, params);
    let scene: SceneFile = serde_json::from_value(tree).map_err(|e| fail(e.to_string()))?;
    // Written with the extensions the scene loader reads RON with (`scene::parse::ron`):
    // `Option` fields bare (`emission: (radiance: …)`, not `Some((…))`, which the loader's
    // unwrapped newtypes would read as a newtype around a tuple and refuse) and newtype
    // variants unwrapped. Both are default extensions there, so no `#![enable]` header.
    let extensions = ron::extensions::Extensions::IMPLICIT_SOME
        | ron::extensions::Extensions::UNWRAP_VARIANT_NEWTYPES;
    let body = ron::Options::default()
        .with_default_extension(extensions)
        .to_string_pretty(&scene, ron::ser::PrettyConfig::default())
        .map_err(|e| fail(e.to_string()))?;
    Ok(format!(
        "// Written by `caustic farm plan` from `{}` with its overrides applied and asset paths\n// made absolute; the farm's shards render this file.\n{body}\n",
        from.display()
    ))
}

/// A scene that names no integrator renders with the default estimator, which picks its own
/// per-pass photon counts unless the command line states them: the resolved scene names the
/// integrator chosen and the photon counts in effect (each light's own budget too), so the
/// shards render it without the command line and get the very same settings.
fn pin_default_estimator(tree: &mut Value, params: &RenderParams) {
    if params.default_estimator.is_none() {
        return;
    }
    if let Ok(kind) = serde_json::to_value(params.integrator) {
        tree["render"]["integrator"] = kind;
    }
    let p = &params.photons;
    for (field, value) in [
        ("caustic", p.caustic),
        ("global", p.global),
        ("caustic_gather", p.caustic_gather),
        ("gather", p.gather),
    ] {
        tree["photons"][field] = Value::from(value);
    }
    if let Some(lights) = tree["lights"].as_array_mut() {
        for (light, budget) in lights.iter_mut().zip(&p.caustic_per_light) {
            // Externally tagged: `{ "Point": { … } }`.
            if let Some(fields) = light.as_object_mut().and_then(|m| m.values_mut().next())
                && fields.get("caustic_photons").is_some()
            {
                fields["caustic_photons"] = budget.map_or(Value::Null, Value::from);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shard_budgets_leave_a_tenth_and_half_a_minute() {
        assert_eq!(shard_budget(Duration::from_secs(119)), None);
        assert_eq!(
            shard_budget(Duration::from_secs(120)),
            Some(Duration::from_secs(78))
        );
        assert_eq!(
            shard_budget(Duration::from_secs(7200)),
            Some(Duration::from_secs(6450))
        );
    }

    #[test]
    fn shard_ranges_split_the_samples_as_the_shards_do() {
        // ⌊(i−1)·S/N⌋ .. ⌊i·S/N⌋ for S = 10, N = 3, by hand.
        assert_eq!(
            shard_ranges(3, 10).expect("3 of 10"),
            vec![[0, 3], [3, 6], [6, 10]]
        );
        assert!(shard_ranges(4, 3).is_err());
        assert_eq!(
            time_plan_spp(2, Duration::from_secs(3600)).expect("in time"),
            2 * TIME_PLAN_SPP_PER_SHARD
        );
        assert!(matches!(
            time_plan_spp(2, Duration::from_secs(60)),
            Err(PlanError::TimeTooShort(60))
        ));
    }
}
