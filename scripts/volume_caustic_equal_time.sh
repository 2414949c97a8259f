#!/usr/bin/env bash
# Issue 44's volumetric-caustics figure: on benches/scenes/volume_caustic.ron (rippled murky
# water under a 4° sun) at 160×120, the default estimator (path-ppm with the volume caustic map)
# and `path` at equal CPU time, against a long `path` reference.
#
#   scripts/volume_caustic_equal_time.sh [BUDGET_CPU_S] [REF_SPP] [REF_DIR]
#
# BUDGET_CPU_S (default 40): CPU seconds (user + sys) per render. Each estimator first renders
# 4 samples per pixel to measure its CPU cost per sample, then renders seeds 1 and 2 with the
# samples per pixel that cost BUDGET_CPU_S (2 threads). CPU time, not wall time, so that the
# budget holds on a loaded machine; a render's real CPU time is printed beside it (the 4-spp
# calibration includes the start-up, so renders come out somewhat under the budget), and the
# RMSE is also given at exactly the budget: its noise part (noise_rmse) scaled by
# √(cpu/budget), its remainder (bias, and the reference's noise) kept,
# √(rmse² − noise² + noise²·cpu/budget).
# REF_SPP (default 16384: about 250 CPU s a half) and REF_DIR (default ../volume_caustic_ref):
# the reference is two independent `path` halves of REF_SPP each (seeds 101, 102), rendered
# once and kept there.
#
# Figures per estimator, of the mean of its two seeds against the reference's two halves
# (scripts/mitsuba/z8.py with --ref2 --noise): rmse, relmse, mean_ratio, z8 (χ²/dof of the 8×8
# block z-test; the reference's own noise is in its denominator), noise_rmse (the part of the
# RMSE the estimator's own noise explains). Then the ratio RMSE(default) / RMSE(path) at equal
# CPU time. Run it on a QUIET machine for timings to quote; CPU time is robust to other jobs
# only to first order (shared caches and memory bandwidth still slow a loaded machine).
# Quick check that it runs: scripts/volume_caustic_equal_time.sh 4 64 /tmp/vc_ref
set -euo pipefail
cd "$(dirname "$0")/.."
budget=${1:-40}
ref_spp=${2:-16384}
REF_DIR=${3:-../volume_caustic_ref}
source scripts/caustic_bin.sh
M=../shared/bench/mitsuba
PY=${MITSUBA_PY:-/root/.cache/mitsuba3-venv/bin/python}
[ -x "$PY" ] || PY=$(bash "$M/setup.sh")
SCENE=benches/scenes/volume_caustic.ron
SIZE=(--width 160 --height 120)
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

# CPU seconds (user + sys) of one render; the render's summary goes to $2.
cpu() {
  local log=$1
  shift
  /usr/bin/env time -f '%U %S' -o "$out/t" "$caustic" render "$SCENE" "${SIZE[@]}" --threads 2 "$@" \
    > "$log" 2>&1
  awk '{printf "%.2f\n", $1 + $2}' "$out/t"
}

mkdir -p "$REF_DIR"
for seed in 101 102; do
  ref=$REF_DIR/ref_${ref_spp}_$seed.exr
  if [ ! -f "$ref" ]; then
    echo "reference half: path, $ref_spp spp, seed $seed → $ref"
    c=$(cpu "$out/ref.log" --integrator path --spp "$ref_spp" --seed "$seed" -o "$ref")
    echo "  $c CPU s"
  fi
done
REF1=$REF_DIR/ref_${ref_spp}_101.exr
REF2=$REF_DIR/ref_${ref_spp}_102.exr

echo "caustic $(git rev-parse --short HEAD 2>/dev/null || echo '?'); $(nproc) CPUs:$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2)"
echo "load before: $(cut -d' ' -f1-3 /proc/loadavg); budget $budget CPU s per render, 2 threads"
declare -A rmse
for e in default path; do
  flags=()
  [ "$e" = path ] && flags=(--integrator path)
  c4=$(cpu "$out/cal.log" "${flags[@]}" --spp 4 --seed 9 -o "$out/cal.exr")
  spp=$(python3 -c "print(max(1, round($budget * 4 / $c4)))")
  c1=$(cpu "$out/${e}1.log" "${flags[@]}" --spp "$spp" --seed 1 -o "$out/${e}1.exr")
  c2=$(cpu "$out/${e}2.log" "${flags[@]}" --spp "$spp" --seed 2 -o "$out/${e}2.exr")
  figs=$("$PY" scripts/mitsuba/z8.py "$out/${e}1.exr" "$out/${e}2.exr" "$REF1" --ref2 "$REF2" --noise)
  r=$(echo "$figs" | grep -o '\brmse=[0-9.e-]*' | head -1 | cut -d= -f2)
  nz=$(echo "$figs" | grep -o 'noise_rmse=[0-9.e-]*' | head -1 | cut -d= -f2)
  scaled=$(python3 -c "c = ($c1 + $c2) / 2; print(f'{max(0.0, $r**2 - $nz**2 + $nz**2 * c / $budget) ** 0.5:.6f}')")
  rmse[$e]=$scaled
  printf '  %-8s 4 spp in %s CPU s → %s spp: %s + %s CPU s; %s; rmse at the budget %s\n' \
    "$e" "$c4" "$spp" "$c1" "$c2" "$figs" "$scaled"
done
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
python3 -c "print(f'RMSE(default) / RMSE(path) at {$budget} CPU s each: {${rmse[default]} / ${rmse[path]}:.3f}')"
