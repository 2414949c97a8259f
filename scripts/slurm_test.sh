#!/usr/bin/env bash
# The farm's test against a real Slurm (issue 16; docs/farm.md): brings up a one-node cluster on
# localhost (munged + slurmctld + slurmd, as root, no systemd), then
#   1. submits `caustic farm plan`'s job for a small Cornell box with 4 shards and checks that
#      the merged .exr and .png are byte-identical to a single-process render;
#   2. plans a longer path-traced job, scancels the last shard while it runs, and checks that
#      the merge job's `merge --partial` image is byte-identical to a single render of exactly
#      the samples of the shards that finished (`render --samples 0..K`).
# Tears down the daemons it started, by PID. Skips (exit 0, saying why) when not root or when
# Debian's slurm-wlm and munge cannot be installed. Run by .ci/run after the test command.
#
# Usage: scripts/slurm_test.sh [path/to/caustic]   (default: the release build, built if missing)
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
START=$(date +%s)

skip() {
    echo "slurm test: SKIPPED: $*"
    exit 0
}

[ "$(id -u)" = 0 ] || skip "needs root to start munged, slurmctld and slurmd (run as root, e.g. in CI)"

if ! command -v slurmctld >/dev/null || ! command -v slurmd >/dev/null || ! command -v sbatch >/dev/null ||
    ! command -v munged >/dev/null; then
    echo "slurm test: installing Debian's slurm-wlm and munge"
    export DEBIAN_FRONTEND=noninteractive
    apt-get install -y -qq slurm-wlm munge >/dev/null 2>&1 ||
        { apt-get update -qq >/dev/null 2>&1 && apt-get install -y -qq slurm-wlm munge >/dev/null 2>&1; } ||
        skip "cannot install slurm-wlm and munge with apt-get (no network or no Debian archive?)"
fi

CAUSTIC=${1:-${CARGO_TARGET_DIR:-$ROOT/target}/release/caustic}
if [ ! -x "$CAUSTIC" ]; then
    cargo build --release --locked
fi
CAUSTIC=$(realpath "$CAUSTIC")

W=$(mktemp -d /tmp/caustic-slurm.XXXXXX)
chmod 755 "$W"
PIDS=()
cleanup() {
    local rc=$?
    if [ -n "${SLURM_CONF:-}" ] && [ -f "$SLURM_CONF" ]; then
        scancel --quiet --user=root >/dev/null 2>&1 || true
    fi
    # Daemons last-started first, by the PIDs this script started.
    for ((i = ${#PIDS[@]} - 1; i >= 0; i--)); do
        kill "${PIDS[i]}" 2>/dev/null || true
    done
    for pid in "${PIDS[@]}"; do
        wait "$pid" 2>/dev/null || true
    done
    if [ "$rc" = 0 ]; then
        rm -rf "$W"
    else
        echo "slurm test: FAILED (exit $rc); logs kept in $W" >&2
        for f in "$W"/*.log "$W"/job*/logs/*.log; do
            [ -f "$f" ] && { echo "---- $f" >&2; tail -n 20 "$f" >&2; }
        done
    fi
    exit "$rc"
}
trap cleanup EXIT
trap 'exit 130' INT TERM HUP

fail() {
    echo "slurm test: FAIL: $*" >&2
    exit 1
}

# --- munge: our own daemon, key and socket, run as the munge user -----------------------------
# (munged wants its key private and its socket's folder open to everyone.)
mkdir -p "$W/munge/key"
dd if=/dev/urandom of="$W/munge/key/munge.key" bs=1024 count=1 status=none
chown -R munge:munge "$W/munge"
chmod 755 "$W/munge"
chmod 700 "$W/munge/key"
chmod 400 "$W/munge/key/munge.key"
SOCK=$W/munge/munge.socket
setpriv --reuid=munge --regid=munge --init-groups munged --foreground \
    --socket="$SOCK" --key-file="$W/munge/key/munge.key" --pid-file="$W/munge/munged.pid" \
    --log-file="$W/munge/munged.log" --seed-file="$W/munge/munged.seed" &
PIDS+=($!)
for _ in $(seq 50); do [ -S "$SOCK" ] && break; sleep 0.1; done
[ -S "$SOCK" ] || fail "munged did not start (log: $W/munge/munged.log)"

# --- slurm.conf: one node on 127.0.0.1, no cgroups, no accounting ------------------------------
NODE=caustic-ci-node
# slurmctld runs only on the host named here: this machine's short name (the address avoids
# any name resolution).
HOST=$(uname -n | cut -d. -f1)
NODELINE=$(slurmd -C | head -n 1 | sed -e "s/^NodeName=[^ ]*/NodeName=$NODE/" -e 's/ UpTime=.*//')
CPUS=$(sed -n 's/.* CPUs=\([0-9]*\).*/\1/p' <<<"$NODELINE")
[ -n "$CPUS" ] || fail "cannot read this node's CPUs from \`slurmd -C\`: '$NODELINE'"
mkdir -p "$W/state" "$W/spool"
export SLURM_CONF=$W/slurm.conf
cat >"$SLURM_CONF" <<EOF
ClusterName=causticci
SlurmctldHost=$HOST(127.0.0.1)
SlurmctldPort=16817
SlurmdPort=16818
SlurmUser=root
AuthType=auth/munge
AuthInfo=socket=$SOCK
CredType=cred/munge
StateSaveLocation=$W/state
SlurmdSpoolDir=$W/spool
SlurmctldPidFile=$W/slurmctld.pid
SlurmdPidFile=$W/slurmd.pid
SlurmctldLogFile=$W/slurmctld.log
SlurmdLogFile=$W/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
MpiDefault=none
SwitchType=switch/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SchedulerParameters=sched_min_interval=200000
ReturnToService=2
$NODELINE NodeAddr=127.0.0.1 State=UNKNOWN
PartitionName=ci Nodes=$NODE Default=YES MaxTime=INFINITE State=UP
EOF
slurmctld -D -c -f "$SLURM_CONF" &
PIDS+=($!)
slurmd -D -N "$NODE" -f "$SLURM_CONF" &
PIDS+=($!)
state=
for _ in $(seq 100); do
    for pid in "${PIDS[@]}"; do
        kill -0 "$pid" 2>/dev/null || fail "a daemon (pid $pid) exited; see $W/slurmctld.log, $W/slurmd.log"
    done
    state=$(timeout 5 sinfo -h -n "$NODE" -o %T 2>/dev/null || true)
    [ "$state" = idle ] && break
    sleep 0.2
done
[ "$state" = idle ] || fail "the node did not come up (state: '${state:-none}')"
echo "slurm test: cluster up in $(($(date +%s) - START)) s ($CPUS CPUs)"

# Waits (up to $2 s) until the merge job has left the queue and written $1.
wait_merged() {
    local image=$1 limit=$2 t0
    t0=$(date +%s)
    while true; do
        if [ -f "$image" ] && [ -z "$(timeout 5 squeue -h -o %i 2>/dev/null)" ]; then
            return 0
        fi
        [ $(($(date +%s) - t0)) -lt "$limit" ] || fail "no merged image $image after $limit s: $(squeue 2>&1)"
        sleep 0.5
    done
}

# --- 1. the whole job: merged image == single-process render -----------------------------------
SCENE=$ROOT/scenes/cornell.ron
FLAGS=(--width 64 --height 64 --spp 16)
"$CAUSTIC" farm plan "$SCENE" "${FLAGS[@]}" --shards 4 --time 5m -o "$W/job1" >/dev/null
t0=$(date +%s%3N)
sbatch --parsable "$W/job1/render.sbatch" >/dev/null
wait_merged "$W/job1/cornell.png" 120
t1=$(date +%s%3N)
"$CAUSTIC" render "$SCENE" "${FLAGS[@]}" -o "$W/single.exr" --quiet >/dev/null
# `merge` writes the raw estimate; a single render's PNG is denoised by default.
"$CAUSTIC" render "$SCENE" "${FLAGS[@]}" -o "$W/single.png" --quiet --no-denoise >/dev/null
cmp "$W/job1/cornell.exr" "$W/single.exr" || fail "merged .exr differs from the single render"
cmp "$W/job1/cornell.png" "$W/single.png" || fail "merged .png differs from the single render"
grep -q "16 of 16 samples per pixel" "$W"/job1/logs/merge-*.log || fail "merge log: $(cat "$W"/job1/logs/merge-*.log)"
status=$("$CAUSTIC" farm status "$W/job1")
grep -q "4 of 4 shards done: 16 of 16 samples per pixel" <<<"$status" || fail "farm status: $status"
echo "slurm test: 4-shard job merged byte-identical to a single render ($((t1 - t0)) ms from sbatch to merged image)"

# --- 2. a shard cancelled mid-run: the partial merge == a render of the finished samples -------
FLAGS=(--width 32 --height 32 --spp 4000 --integrator path)
"$CAUSTIC" farm plan "$SCENE" "${FLAGS[@]}" --shards 4 --time 5m -o "$W/job2" >/dev/null
sbatch --parsable "$W/job2/render.sbatch" >/dev/null
task=
for _ in $(seq 600); do
    task=$(squeue -h -r -n caustic-shard -t RUNNING -o %i 2>/dev/null | grep '_4$' || true)
    [ -n "$task" ] && break
    sleep 0.1
done
[ -n "$task" ] || fail "shard 4 never ran: $(squeue 2>&1)"
sleep 1
scancel "$task"
echo "slurm test: cancelled array task $task (shard 4/4) while it ran"
wait_merged "$W/job2/cornell.exr" 120
[ ! -f "$W/job2/shards/shard-4.part" ] || fail "the cancelled shard left a film"
grep -q "3000 of 4000 samples per pixel (partial: samples 3000..4000 missing)" "$W"/job2/logs/merge-*.log ||
    fail "merge log: $(cat "$W"/job2/logs/merge-*.log)"
"$CAUSTIC" render "$SCENE" "${FLAGS[@]}" --samples 0..3000 -o "$W/partial.exr" --quiet >/dev/null
cmp "$W/job2/cornell.exr" "$W/partial.exr" || fail "partial merge differs from a render of samples 0..3000"
echo "slurm test: partial merge byte-identical to a render of the 3000 finished samples"
echo "slurm test: passed in $(($(date +%s) - START)) s"
