#!/usr/bin/env bash
# Adaptive sampling at equal numbers of samples (issue #43; docs/convergence.md, "Adaptive
# sampling"): for each scene, an adaptive render (`--adaptive --spp CAP --target-error TAU`),
# then a uniform render of the default estimator with as many samples per pixel as the adaptive
# one's mean (rounded up), both scored against a reference with `caustic compare`. The figures
# are free of CPU time (the machine may be loaded); the equal-time command is printed at the
# end.
#
#   scripts/adaptive_bench.sh [OUT]    (default OUT: a temporary folder)
#
# Scenes: ../shared/bench/cbox_caustic.ron at its 256×256 against Mitsuba 3's reference
# (../shared/bench/mitsuba/cbox_caustic.ref.exr); benches/scenes/user/*.ron at SIZE (default
# 128x96) against a uniform render of the default estimator at REF_SPP (default 1024) samples
# per pixel with another seed (written once to OUT/<scene>.ref.exr; it judges variance, not the
# estimator's bias, which both renders share). CAP (default 256) and TAU (default 0.02) set the
# adaptive render.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/caustic_bin.sh
out=${1:-$(mktemp -d)}
mkdir -p "$out"
size=${SIZE:-128x96}
cap=${CAP:-256}
tau=${TAU:-0.02}
ref_spp=${REF_SPP:-1024}
w=${size%x*}
h=${size#*x}
field() { sed -n "s/.*$1 \([0-9.e+-]*\).*/\1/p" | sed -n 1p; }
echo "load before: $(cut -d' ' -f1-3 /proc/loadavg)"
echo
echo "| scene | size | adaptive spp (mean) | uniform spp | relMSE adaptive | relMSE uniform | ratio | RMSE adaptive | RMSE uniform | mean bias adaptive | mean bias uniform | photon passes adaptive / uniform |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|"
run() {
  local name=$1 scene=$2 ref=$3
  shift 3
  local a="$out/$name.adaptive.exr" u="$out/$name.uniform.exr"
  local alog ulog mean spp ac uc
  alog=$("$caustic" render "$scene" "$@" --threads 2 --adaptive --spp "$cap" --target-error "$tau" -o "$a" 2>&1)
  echo "$alog" >"$out/$name.adaptive.log"
  mean=$(echo "$alog" | sed -n 's/^adaptive: \([0-9.]*\) samples per pixel.*/\1/p')
  spp=$(awk -v m="$mean" 'BEGIN { s = int(m); if (s < m) s++; print s }')
  ulog=$("$caustic" render "$scene" "$@" --threads 2 --spp "$spp" -o "$u" 2>&1)
  echo "$ulog" >"$out/$name.uniform.log"
  ac=$("$caustic" compare "$a" "$ref" | sed -n 1p)
  uc=$("$caustic" compare "$u" "$ref" | sed -n 1p)
  local ar ur
  ar=$(echo "$ac" | field relMSE)
  ur=$(echo "$uc" | field relMSE)
  local ap up
  ap=$(echo "$alog" | sed -n 's/^photons: \([0-9]*\) passes.*/\1/p')
  up=$(echo "$ulog" | sed -n 's/^photons: \([0-9]*\) passes.*/\1/p')
  echo "| $name | $(echo "$ulog" | sed -n 's/.*: \([0-9]*×[0-9]*\), .*/\1/p' | sed -n 1p) | $mean | $spp | $ar | $ur | $(awk -v a="$ar" -v u="$ur" 'BEGIN { printf "%.3f", a / u }') | $(echo "$ac" | field rmse) | $(echo "$uc" | field rmse) | $(echo "$ac" | sed -n 's/.*mean bias \([0-9.e+-]*\).*/\1/p') | $(echo "$uc" | sed -n 's/.*mean bias \([0-9.e+-]*\).*/\1/p') | ${ap:--} / ${up:--} |"
}
run cbox_caustic ../shared/bench/cbox_caustic.ron ../shared/bench/mitsuba/cbox_caustic.ref.exr
for f in benches/scenes/user/*.ron; do
  s=$(basename "$f" .ron)
  if [ ! -f "$out/$s.ref.exr" ]; then
    "$caustic" render "$f" --threads 2 --width "$w" --height "$h" --spp "$ref_spp" --seed 101 \
      -o "$out/$s.ref.exr" >"$out/$s.ref.log" 2>&1
  fi
  run "$s" "$f" "$out/$s.ref.exr" --width "$w" --height "$h"
done
echo
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
echo "Equal time (wall-clock: on a quiet machine), per scene S:"
echo "  caustic render S --threads 2 --time 20s -o u.exr; caustic render S --threads 2 --adaptive --time 20s -o a.exr"
echo "  caustic compare u.exr REF; caustic compare a.exr REF"
