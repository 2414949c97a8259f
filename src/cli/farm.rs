//! `caustic farm`: render on a Slurm cluster. `plan` writes a job folder (the resolved scene,
//! a manifest, the batch scripts); `sbatch DIR/render.sbatch` runs it (photon cache, shard
//! array, merge); `status` says which shards are done; `cache` is the first job's step.

mod cache;
mod manifest;
mod scripts;
mod status;

use std::path::{Path, PathBuf};
use std::time::Duration;

use clap::{Args, Subcommand};
use serde_json::Value;

use caustic::Error;
use caustic::farm::Shard;
use caustic::farm::part_meta::settings_hash;
use caustic::pipeline::{SceneOverrides, prepare};
use caustic::render_scene::RenderParams;
use caustic::scene::SceneFile;

use self::manifest::{FORMAT, LOGS, Manifest, PHOTONS, SCENE, SHARDS};
use self::scripts::{Resources, scripts, slurm_time};
use super::render::parse_duration;
use super::{SceneArgs, print_warnings};

/// Arguments of `caustic farm`.
#[derive(Args)]
pub struct FarmArgs {
    #[command(subcommand)]
    command: FarmCommand,
}

#[derive(Subcommand)]
enum FarmCommand {
    /// Write a job folder for Slurm: DIR/scene.ron (the scene with the overrides applied and
    /// asset paths made absolute), DIR/manifest.json, and DIR/render.sbatch (submit it with
    /// `sbatch`), shard.sbatch and merge.sbatch.
    Plan(Box<PlanArgs>),
    /// Which shards of a job folder are done (valid films), the samples per pixel so far, and
    /// an estimate of the time left.
    Status(DirArgs),
    /// Build the job's photon cache (DIR/photons) once for all shards; nothing to do for
    /// integrators without fixed photon maps. Run by the job's first step.
    Cache(CacheArgs),
}

/// Arguments of `caustic farm plan`.
#[derive(Args)]
struct PlanArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// Number of shards (Slurm array tasks); at most the samples per pixel.
    #[arg(long, value_name = "N")]
    shards: u32,
    /// Time limit of each shard (and of the photon-cache job), e.g. `2h`, `90m`; default 1h.
    /// A shard renders for at most this less a tenth and 30 s, then writes the samples it
    /// took. Given without `--spp`, the plan is in time, not samples: every shard renders
    /// passes of its own range of samples until its budget is spent (as `render --time`), so
    /// any number of shards fits a scene of few samples per pixel.
    #[arg(long, value_name = "DURATION", value_parser = parse_duration)]
    time: Option<Duration>,
    /// The job folder to create (must not hold a job already).
    #[arg(short, long, value_name = "DIR")]
    output: PathBuf,
    /// CPUs (render threads) per shard.
    #[arg(long, default_value = "1", value_name = "N")]
    cpus: u32,
    /// Slurm partition for every job.
    #[arg(long)]
    partition: Option<String>,
    /// Slurm account for every job.
    #[arg(long)]
    account: Option<String>,
    /// Memory per job, as Slurm writes it (e.g. `4G`).
    #[arg(long)]
    mem: Option<String>,
    /// The caustic binary the jobs run (default: this one); must be reachable from the nodes.
    #[arg(long, value_name = "PATH")]
    caustic: Option<PathBuf>,
}

#[derive(Args)]
struct DirArgs {
    /// The job folder written by `caustic farm plan`.
    dir: PathBuf,
}

#[derive(Args)]
struct CacheArgs {
    /// The job folder written by `caustic farm plan`.
    dir: PathBuf,
    /// Worker threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
}

/// Runs a `farm` subcommand.
pub fn run(args: &FarmArgs) -> Result<(), Error> {
    match &args.command {
        FarmCommand::Plan(a) => plan(a),
        FarmCommand::Status(a) => status::run(&a.dir),
        FarmCommand::Cache(a) => cache::run(&a.dir, a.threads),
    }
}

fn usage(text: String) -> Error {
    Error::Usage(text)
}

fn io(path: &Path, e: &std::io::Error) -> Error {
    usage(format!("cannot write `{}`: {e}", path.display()))
}

/// The render-time budget of a shard under a Slurm time limit: the limit less a tenth and
/// 30 s (for loading the scene and photon cache, writing the film, and one pass of overrun),
/// so that a slow shard stops early and writes the samples it took instead of being killed
/// with nothing; none under 2 minutes.
fn shard_budget(limit: Duration) -> Option<Duration> {
    (limit >= Duration::from_secs(120))
        .then(|| Duration::from_secs((limit - limit / 10 - Duration::from_secs(30)).as_secs()))
}

/// The overrides as `path=value` strings, for the manifest.
fn override_record(o: &SceneOverrides) -> Vec<String> {
    let mut out = o.sets.clone();
    let flags = [
        ("render.width", o.render.width.map(u64::from)),
        ("render.height", o.render.height.map(u64::from)),
        (
            "render.samples_per_pixel",
            o.render.samples_per_pixel.map(u64::from),
        ),
        ("render.max_depth", o.render.max_depth.map(u64::from)),
        ("render.seed", o.render.seed),
        ("photons.caustic", o.photons.caustic.map(u64::from)),
    ];
    for (path, v) in flags {
        if let Some(v) = v {
            out.push(format!("{path}={v}"));
        }
    }
    if let Some(i) = o.render.integrator {
        out.push(format!("render.integrator={}", i.name()));
    }
    if let Some(s) = o.render.sampler {
        out.push(format!("render.sampler={}", s.name()));
    }
    out
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

/// The scene as RON with asset paths absolute, so it renders the same from the job folder.
fn resolved_scene(
    scene: &SceneFile,
    params: &RenderParams,
    base: &Path,
    from: &Path,
) -> Result<String, Error> {
    let fail = |e: String| {
        usage(format!(
            "cannot write the resolved scene of `{}`: {e}",
            from.display()
        ))
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

/// Samples per pixel each shard's range holds in a plan in time (`--time` without `--spp`):
/// more than any shard renders within a Slurm time limit.
const TIME_PLAN_SPP_PER_SHARD: u32 = 1 << 16;

/// The default time limit of a shard.
const DEFAULT_TIME: Duration = Duration::from_secs(3600);

fn plan(a: &PlanArgs) -> Result<(), Error> {
    let mut overrides = a.scene.overrides();
    let time = a.time.unwrap_or(DEFAULT_TIME);
    // `--time` without `--spp`: a plan in time, every shard renders until its budget.
    let in_time = a.time.is_some() && overrides.render.samples_per_pixel.is_none();
    if in_time {
        if shard_budget(time).is_none() {
            return Err(usage(format!(
                "--time {}s without --spp plans shards that render until their time is spent, which needs a limit of at least 2 minutes; give a longer --time or --spp",
                time.as_secs()
            )));
        }
        let total = a
            .shards
            .checked_mul(TIME_PLAN_SPP_PER_SHARD)
            .ok_or_else(|| {
                usage(format!(
                    "--shards {}: at most {} shards in a plan in time",
                    a.shards,
                    u32::MAX / TIME_PLAN_SPP_PER_SHARD
                ))
            })?;
        overrides.render.samples_per_pixel = Some(total);
    }
    let source_path = &a.scene.scene;
    let prepared = prepare(source_path, &overrides)?;
    print_warnings(&prepared.warnings);
    let hash = settings_hash(&prepared.render_scene);
    let p = &prepared.render_scene.params;
    let spp = p.samples_per_pixel;
    if a.shards == 0 {
        return Err(usage("--shards must be at least 1".into()));
    }
    if a.cpus == 0 {
        return Err(usage("--cpus must be at least 1".into()));
    }
    let mut ranges = Vec::new();
    for index in 1..=a.shards {
        let r = Shard {
            index,
            count: a.shards,
        }
        .samples(spp)
        .map_err(|e| {
            usage(format!(
                "{e}; or give --time without --spp, for shards that render until their time is spent"
            ))
        })?;
        ranges.push([r.start, r.end]);
    }
    let dir = &a.output;
    if dir.join(manifest::FILE).exists() {
        return Err(usage(format!(
            "`{}` already holds a farm job ({} exists); choose another folder or delete it",
            dir.display(),
            dir.join(manifest::FILE).display()
        )));
    }
    let dir = std::path::absolute(dir).map_err(|e| io(dir, &e))?;
    let dir_text = dir.display().to_string();
    if dir_text.contains(|c: char| c.is_whitespace() || c == '%') {
        return Err(usage(format!(
            "-o `{dir_text}`: the job folder's path must not contain spaces or `%` (Slurm's #SBATCH lines cannot quote them)"
        )));
    }
    for sub in [SHARDS, PHOTONS, LOGS] {
        std::fs::create_dir_all(dir.join(sub)).map_err(|e| io(&dir.join(sub), &e))?;
    }
    let base = prepared.source.base_dir();
    let base = std::path::absolute(if base.as_os_str().is_empty() {
        Path::new(".")
    } else {
        &base
    })
    .map_err(|e| io(&base, &e))?;
    let params = &prepared.render_scene.params;
    let scene_text = resolved_scene(&prepared.scene, params, &base, source_path)?;
    let scene_path = dir.join(SCENE);
    caustic::render::output::write_atomic(&scene_path, scene_text.as_bytes())?;
    // The shards render the resolved scene: it must be the very scene that was planned.
    let again = prepare(&scene_path, &SceneOverrides::default())?;
    if settings_hash(&again.render_scene) != hash {
        return Err(usage(format!(
            "the resolved scene `{}` does not render like `{}` with its overrides (a field that does not survive RON); please report this",
            scene_path.display(),
            source_path.display()
        )));
    }
    let caustic = match &a.caustic {
        Some(c) => std::path::absolute(c).map_err(|e| io(c, &e))?,
        None => std::env::current_exe().map_err(|e| {
            usage(format!(
                "cannot find the caustic binary's path: {e}; pass --caustic PATH"
            ))
        })?,
    };
    let stem = source_path
        .file_stem()
        .map_or_else(|| "image".into(), |s| s.to_string_lossy().into_owned());
    let m = Manifest {
        format: FORMAT.into(),
        hash: format!("{hash:016x}"),
        source_scene: std::path::absolute(source_path).map_err(|e| io(source_path, &e))?,
        overrides: override_record(&overrides),
        shards: a.shards,
        samples_per_pixel: spp,
        ranges,
        width: p.width,
        height: p.height,
        integrator: format!("{:?}", p.integrator),
        caustic,
        time_limit: slurm_time(time),
        shard_budget_seconds: shard_budget(time).map(|d| d.as_secs()),
        cpus_per_task: a.cpus,
        outputs: vec![format!("{stem}.exr"), format!("{stem}.png")],
    };
    let res = Resources {
        partition: a.partition.clone(),
        account: a.account.clone(),
        mem: a.mem.clone(),
    };
    for (name, text) in scripts(&m, &dir, &res) {
        let path = dir.join(name);
        caustic::render::output::write_atomic(&path, text.as_bytes())?;
    }
    let json = serde_json::to_string_pretty(&m).map_err(|e| usage(e.to_string()))?;
    caustic::render::output::write_atomic(&dir.join(manifest::FILE), json.as_bytes())?;
    let samples = if in_time {
        format!(
            "each rendering its own range of samples per pixel until its budget of {} s is spent",
            m.shard_budget_seconds.unwrap_or(0)
        )
    } else {
        format!("at {spp} spp")
    };
    println!(
        "{}: {} shards of {}×{} {samples} ({}), hash {}; submit with: sbatch {}/render.sbatch",
        dir.display(),
        a.shards,
        p.width,
        p.height,
        m.integrator,
        m.hash,
        dir.display()
    );
    Ok(())
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
}
