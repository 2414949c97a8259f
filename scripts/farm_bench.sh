#!/usr/bin/env bash
# Wall time of 1, 2 and 4 shards of the same render on this machine (docs/farm.md, "Measured"):
# each shard is a separate `caustic render --shard i/N --threads 1` process, at most as many at
# once as the machine has cores (as a Slurm node with --cpus 1 per shard would run them), after
# the job's photon cache is built once; then the merge, timed, checked byte-identical to a
# single-process render. Prints wall time and CPU time (user + sys) of each stage: on a shared
# machine the wall time shows what the cores left over allowed, the CPU time what the work cost.
# Usage: scripts/farm_bench.sh [caustic] [scene] [flags...]
set -euo pipefail
cd "$(dirname "$0")/.."
CAUSTIC=$(realpath "${1:-${CARGO_TARGET_DIR:-target}/release/caustic}")
SCENE=${2:-scenes/bath.ron}
shift $(($# > 2 ? 2 : $#))
FLAGS=("$@")
[ ${#FLAGS[@]} -gt 0 ] || FLAGS=(--width 400 --height 300 --spp 8)
CORES=$(nproc)
W=$(mktemp -d /tmp/caustic-farm-bench.XXXXXX)
trap 'rm -rf "$W"' EXIT
TIMEFORMAT='%R s wall, %U+%S s CPU'
# Runs "$@" (a stage), printing its wall and CPU time (bash's `time`, children included).
stage() {
    local what=$1
    shift
    { time "$@" >/dev/null 2>&1; } 2>"$W/t"
    echo "  $what: $(cat "$W/t")"
}
shards() {
    seq 1 "$1" | xargs -P "$CORES" -I{} "$CAUSTIC" render "$2/scene.ron" --shard "{}/$1" \
        --threads 1 --photon-cache "$2/photons" -q -o "$2/shards/shard-{}.part"
}

echo "machine: $CORES cores, load $(cut -d' ' -f1-3 /proc/loadavg); $SCENE ${FLAGS[*]}"
stage "single process, $CORES threads (its photon maps included)" \
    "$CAUSTIC" render "$SCENE" "${FLAGS[@]}" --threads "$CORES" -q -o "$W/single.exr"
for n in 1 2 4; do
    echo "$n shard(s) of 1 thread, $CORES at a time:"
    "$CAUSTIC" farm plan "$SCENE" "${FLAGS[@]}" --shards "$n" -o "$W/j$n" >/dev/null
    stage "photon cache ($CORES threads)" "$CAUSTIC" farm cache "$W/j$n" --threads "$CORES"
    stage "shards" shards "$n" "$W/j$n"
    stage "merge" "$CAUSTIC" merge "$W/j$n"/shards/*.part -o "$W/j$n/merged.exr"
    cmp -s "$W/j$n/merged.exr" "$W/single.exr" || { echo "$n shards: merged image differs!"; exit 1; }
    echo "  merged image byte-identical to the single render"
done
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
