//! The Slurm batch scripts of a farm job. `render.sbatch` is the job the user submits: it
//! submits the shard array (after itself) and the merge job (after the array), then builds the
//! photon cache. Every `#SBATCH` line carries its reason (docs/farm.md explains them too).

use std::path::Path;

use super::manifest::{LOGS, Manifest, PHOTONS, SCENE, SHARDS};

/// Optional Slurm resources given to `caustic farm plan`.
#[derive(Debug, Clone, Default)]
pub struct Resources {
    /// `#SBATCH --partition`.
    pub partition: Option<String>,
    /// `#SBATCH --account`.
    pub account: Option<String>,
    /// `#SBATCH --mem` (e.g. `4G`).
    pub mem: Option<String>,
}

/// `text` quoted for bash (single quotes; a single quote becomes `'\''`).
#[must_use]
pub fn quote(text: &str) -> String {
    format!("'{}'", text.replace('\'', r"'\''"))
}

/// A duration as Slurm's `--time` (`H:MM:SS`, or `D-HH:MM:SS` from one day), rounded up to
/// whole seconds.
#[must_use]
pub fn slurm_time(d: std::time::Duration) -> String {
    let s = d.as_secs() + u64::from(d.subsec_nanos() > 0);
    let (days, h, m, s) = (s / 86_400, s / 3600 % 24, s / 60 % 60, s % 60);
    if days > 0 {
        format!("{days}-{h:02}:{m:02}:{s:02}")
    } else {
        format!("{h}:{m:02}:{s:02}")
    }
}

fn common(res: &Resources) -> String {
    let mut out = String::new();
    let lines = [
        (
            &res.partition,
            "partition",
            "the partition (queue) given to `farm plan --partition`",
        ),
        (
            &res.account,
            "account",
            "the account charged, given to `farm plan --account`",
        ),
        (
            &res.mem,
            "mem",
            "memory per shard, given to `farm plan --mem` (scene + BVH + photon maps + film)",
        ),
    ];
    for (value, name, why) in lines {
        if let Some(v) = value {
            out.push_str(&format!("#SBATCH --{name}={v}\n# ^ {why}\n"));
        }
    }
    out
}

/// The three scripts of job folder `dir` (absolute), as (file name, text).
#[must_use]
pub fn scripts(m: &Manifest, dir: &Path, res: &Resources) -> Vec<(&'static str, String)> {
    let d = dir.display().to_string();
    let q = |sub: &str| quote(&format!("{d}/{sub}"));
    let caustic = quote(&m.caustic.display().to_string());
    let (n, cpus, time) = (m.shards, m.cpus_per_task, &m.time_limit);
    let common = common(res);
    let head = format!(
        "#!/bin/bash\n# caustic farm job (written by `caustic farm plan`; see docs/farm.md): {n} shards of\n# {spp} samples per pixel, {w}x{h}, {integ}; settings hash {hash}.\n",
        spp = m.samples_per_pixel,
        w = m.width,
        h = m.height,
        integ = m.integrator,
        hash = m.hash
    );
    let render = format!(
        r#"{head}# Stage 1 of 3 (submit this one: `sbatch render.sbatch`): submits the shard array to start
# after this job and the merge job to start after the array, then builds the photon cache
# once (a no-op for integrators without fixed photon maps).
#SBATCH --job-name=caustic-cache
# ^ the name squeue shows
#SBATCH --output={d}/{LOGS}/cache-%j.log
# ^ logs go to the job folder, whatever folder sbatch was run from
#SBATCH --time={time}
# ^ the shards' limit: tracing photons takes less than rendering with them
#SBATCH --cpus-per-task={cpus}
# ^ photon tracing and kd-tree building use the threads given (--threads below)
#SBATCH --nodes=1
# ^ caustic is one process: more nodes would sit idle
{common}set -euo pipefail
DIR={dq}
# afterany (not afterok): shards start even if the cache job fails; each shard then builds
# the maps itself and says so. The merge job waits for every array task to end in any state
# and judges what finished (`merge --partial`), so a cancelled shard never blocks it.
array=$(sbatch --parsable --dependency=afterany:"$SLURM_JOB_ID" "$DIR/shard.sbatch")
array=${{array%%;*}}
merge=$(sbatch --parsable --dependency=afterany:"$array" "$DIR/merge.sbatch")
echo "caustic farm: shard array $array and merge job ${{merge%%;*}} submitted"
exec {caustic} farm cache "$DIR" --threads "${{SLURM_CPUS_PER_TASK:-1}}"
"#,
        dq = quote(&d),
    );
    let shard = format!(
        r#"{head}# Stage 2 of 3: the shards, one array task each (task i renders shard i/{n}).
#SBATCH --job-name=caustic-shard
# ^ the name squeue shows
#SBATCH --array=1-{n}
# ^ one task per shard; the task id is the shard number
#SBATCH --output={d}/{LOGS}/shard-%a.log
# ^ one log per shard in the job folder
#SBATCH --open-mode=append
# ^ a requeued shard appends to its log instead of erasing the first attempt's
#SBATCH --requeue
# ^ after a node failure Slurm reruns the shard; it rewrites only its own .part, atomically
#SBATCH --time={time}
# ^ the limit given to `farm plan --time`; the shard's --time budget below ends it sooner
#SBATCH --cpus-per-task={cpus}
# ^ the shard renders with this many threads (--threads below)
#SBATCH --nodes=1
# ^ caustic is one process: more nodes would sit idle
{common}set -euo pipefail
i=$SLURM_ARRAY_TASK_ID
exec {caustic} render {scene} --shard "$i/{n}" --threads "${{SLURM_CPUS_PER_TASK:-1}}" \
    --photon-cache {photons} -o {shards}/shard-"$i".part{budget}
"#,
        budget = m.shard_budget_seconds.map_or_else(String::new, |b| format!(
            " \\\n    --spp {spp} --time {b}s  # stop in time to write what was done",
            spp = m.samples_per_pixel
        )),
        scene = q(SCENE),
        photons = q(PHOTONS),
        shards = q(SHARDS),
    );
    let outputs: Vec<String> = m.outputs.iter().map(|o| format!("-o {}", q(o))).collect();
    let merge = format!(
        r#"{head}# Stage 3 of 3: merges whatever shards finished (all of them, normally) into the image.
#SBATCH --job-name=caustic-merge
# ^ the name squeue shows
#SBATCH --output={d}/{LOGS}/merge-%j.log
# ^ the log goes to the job folder
#SBATCH --time=1:00:00
# ^ merging reads each shard's film once: seconds for most images
#SBATCH --cpus-per-task=1
# ^ merging is a single pass over the files
#SBATCH --nodes=1
# ^ one process
{common}set -euo pipefail
parts=()
for i in $(seq 1 {n}); do
    part={shards}/shard-"$i".part
    if [ -f "$part" ]; then parts+=("$part"); else echo "shard $i/{n}: no film (failed, cancelled or timed out)"; fi
done
exec {caustic} merge --partial --expect-hash {hash} "${{parts[@]}}" {outputs}
"#,
        shards = q(SHARDS),
        hash = m.hash,
        outputs = outputs.join(" "),
    );
    vec![
        ("render.sbatch", render),
        ("shard.sbatch", shard),
        ("merge.sbatch", merge),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    #[test]
    fn slurm_times_and_quoting() {
        assert_eq!(slurm_time(Duration::from_secs(7200)), "2:00:00");
        assert_eq!(slurm_time(Duration::from_millis(90_500)), "0:01:31");
        assert_eq!(slurm_time(Duration::from_secs(86_400 + 3661)), "1-01:01:01");
        assert_eq!(quote("a b"), "'a b'");
        assert_eq!(quote("it's"), r"'it'\''s'");
    }
}
