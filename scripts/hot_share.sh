#!/usr/bin/env bash
# Load-insensitive speed comparison of two builds: the share of a render's CPU samples spent in
# ray–scene intersection (a fixed amount of work at equal spp and seed, since the paths are the
# same), recorded with `perf record` on one thread. When the rest of the renderer gets faster,
# that share grows: old_share / new_share estimates new_time / old_time, whatever else the
# machine runs (wall and CPU times are not comparable under load; shares within one process
# mostly are). Usage: scripts/hot_share.sh BIN [render args…]
# default args: benches/scenes/cbox_caustic.ron --integrator path --spp 8 --width 256 --height 256
set -euo pipefail
cd "$(dirname "$0")/.."
bin=$1; shift
args=("$@")
[ ${#args[@]} -eq 0 ] && args=(benches/scenes/cbox_caustic.ron --integrator path --spp 8 --width 256 --height 256)
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
perf record -q -F 4000 -g -o "$out/perf.data" -- "$bin" render "${args[@]}" --threads 1 --quiet -o "$out/img.exr" > /dev/null 2>&1
perf report -i "$out/perf.data" --no-children --sort symbol --stdio 2>/dev/null |
  grep -E '^ +[0-9.]+%' > "$out/rep"
awk '/intersect|closest|occluded|Bvh/ {s += $1} END {printf "intersection share: %.2f%%\n", s}' "$out/rep"
head -25 "$out/rep"
