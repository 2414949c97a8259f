#!/usr/bin/env bash
# Median wall time of `caustic render` over N runs (default 5) of a scene, with the renderer's
# own summary lines. Usage: scripts/time_render.sh [scene] [runs] [extra caustic flags...]
set -euo pipefail
cd "$(dirname "$0")/.."
scene=${1:-scenes/cornell.ron}
runs=${2:-5}
shift $(( $# > 2 ? 2 : $# ))
source scripts/caustic_bin.sh
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
for i in $(seq "$runs"); do
  "$caustic" render "$scene" -o "$out/img.png" --quiet "$@"
done | tee "$out/log"
# Median of the "in X s" figures.
grep -o 'in [0-9.]* s' "$out/log" | awk '{print $2}' | sort -n | awk '{a[NR]=$1} END {print "median render time:", a[int((NR+1)/2)], "s over", NR, "runs"}'
