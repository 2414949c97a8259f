#!/usr/bin/env bash
# The path tracer against the peers at equal time (issue #8 §7): renders the caustic Cornell
# box with `--integrator path --time 26s` (2 threads) ROUNDS times and prints, per run, the
# samples per pixel reached and the RMSE against REFERENCE (docs/convergence.md's 3737-pass
# path-ppm render, made by scripts/convergence_figures.sh), then the medians. With a second
# binary BEFORE (e.g. a build of an older commit), the two alternate run by run, so both see
# the same machine. Run it on a quiet machine: the times are wall-clock.
#
# Usage: scripts/path_equal_time.sh REFERENCE [ROUNDS] [BEFORE]
set -uo pipefail
cd "$(dirname "$0")/.."
ref=${1:?usage: scripts/path_equal_time.sh REFERENCE [ROUNDS] [BEFORE]}
rounds=${2:-3}
before=${3:-}
source scripts/caustic_bin.sh
CB=../shared/bench/cbox_caustic.ron
[ -f "$CB" ] || CB=benches/scenes/cbox_caustic.ron
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
echo "load before: $(cut -d' ' -f1-3 /proc/loadavg)"
run() { # label binary
  local spp rmse
  spp=$("$2" render "$CB" --integrator path --time 26s -o "$out/c.exr" 2>&1 | sed -n 's/.*, \([0-9]*\) spp,.*/\1/p')
  rmse=$("$caustic" compare "$out/c.exr" "$ref" | sed -n 's/^rmse \([0-9.]*\).*/\1/p')
  echo "$1 $spp $rmse"
}
{
  for _ in $(seq "$rounds"); do
    [ -n "$before" ] && run before "$before"
    run after "$caustic"
  done
} | tee "$out/runs.txt"
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
for label in before after; do
  grep "^$label " "$out/runs.txt" | sort -k3 -n | awk -v l="$label" \
    '{s[NR]=$2; r[NR]=$3} END {if (NR) {m=int((NR+1)/2); printf "%s: median RMSE %s (its run: %s spp), over %d runs; Mitsuba 3 peer figure 0.0145 -> ratio %.2f\n", l, r[m], s[m], NR, r[m]/0.0145}}'
done
