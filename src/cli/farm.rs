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

use caustic::Error;
use caustic::farm::plan::{shard_budget, shard_ranges};
use caustic::pipeline::farm_plan::prepare_plan;

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

fn plan(a: &PlanArgs) -> Result<(), Error> {
    let source_path = &a.scene.scene;
    let planned = prepare_plan(source_path, &a.scene.overrides(), a.shards, a.time)?;
    print_warnings(&planned.prepared.warnings);
    let p = &planned.prepared.render_scene.params;
    let spp = p.samples_per_pixel;
    if a.shards == 0 {
        return Err(usage("--shards must be at least 1".into()));
    }
    if a.cpus == 0 {
        return Err(usage("--cpus must be at least 1".into()));
    }
    let ranges = shard_ranges(a.shards, spp)?;
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
    planned.write_resolved_scene(source_path, &dir.join(SCENE))?;
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
        hash: format!("{:016x}", planned.hash),
        source_scene: std::path::absolute(source_path).map_err(|e| io(source_path, &e))?,
        overrides: planned.overrides.as_sets(),
        shards: a.shards,
        samples_per_pixel: spp,
        ranges,
        width: p.width,
        height: p.height,
        integrator: format!("{:?}", p.integrator),
        caustic,
        time_limit: slurm_time(planned.time),
        shard_budget_seconds: shard_budget(planned.time).map(|d| d.as_secs()),
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
    let samples = if planned.in_time {
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
