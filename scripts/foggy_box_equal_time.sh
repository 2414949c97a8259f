#!/usr/bin/env bash
# Issue 44's side-by-side with Mitsuba 3: benches/scenes/foggy_box.ron (a box of fog lit by a
# small sphere light, no refractive boundaries) at 160×160, caustic's default estimator (it
# chooses `path` here: no specular caster) and Mitsuba 3's `volpath`
# (scripts/mitsuba/foggy_box.py, the same scene) at equal CPU time, both against a long
# Mitsuba render: an independent reference (no caustic code in it).
#
#   scripts/foggy_box_equal_time.sh [BUDGET_CPU_S] [REF_SPP] [REF_DIR] [caustic flags...]
#
# BUDGET_CPU_S (default 30): CPU seconds (user + sys) per render, both renderers on 2 threads.
# Each renderer first renders a few samples per pixel to measure its CPU cost per sample (caustic
# 4 spp, Mitsuba 16), then renders seeds 1 and 2 with the samples per pixel that cost the
# budget. CPU time, not wall time, so that the budget holds on a loaded machine (to first order:
# shared caches and memory bandwidth still slow a loaded machine, and not both renderers
# equally). caustic's CPU time is its whole process (/usr/bin/time: parsing, BVH, render);
# Mitsuba's is that of its render calls only (resource.getrusage around mi.render: kernel
# compilation included, cached by Dr.Jit after the first run; the interpreter's start-up and
# the scene's loading not counted), which if anything favours Mitsuba. The calibrations include
# start-up costs, so renders come out somewhat under the budget; the RMSE is also given at
# exactly the budget: its noise part (noise_rmse) scaled by √(cpu/budget), the remainder
# (bias, and the reference's noise) kept, √(rmse² − noise² + noise²·cpu/budget).
# REF_SPP (default 6144) and REF_DIR (default ../foggy_box_ref): the reference is two
# independent Mitsuba halves of REF_SPP each (seeds 101, 102), rendered once and kept there.
# Extra arguments go to caustic (e.g. `--integrator path`).
#
# Figures per renderer, of the mean of its two seeds against the reference's two halves
# (scripts/mitsuba/z8.py with --ref2 --noise): rmse, relmse, mean_ratio (image mean over the
# reference's), z8 (χ²/dof of the 8×8-block z-test; the reference's own noise is in its
# denominator; blocks that see the light, reference ≥ 39, left out), noise_rmse. Then the ratio
# RMSE(caustic) / RMSE(Mitsuba) at equal CPU time. Quick check that it runs:
# scripts/foggy_box_equal_time.sh 3 64 /tmp/fb_ref
set -euo pipefail
cd "$(dirname "$0")/.."
budget=${1:-30}
ref_spp=${2:-6144}
REF_DIR=${3:-../foggy_box_ref}
shift $(( $# > 3 ? 3 : $# ))
source scripts/caustic_bin.sh
M=../shared/bench/mitsuba
PY=${MITSUBA_PY:-/root/.cache/mitsuba3-venv/bin/python}
[ -x "$PY" ] || PY=$(bash "$M/setup.sh")
SCENE=benches/scenes/foggy_box.ron
W=160
H=160
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

# CPU seconds (user + sys) of one caustic render; its summary goes to $1.
caustic_cpu() {
  local log=$1
  shift
  /usr/bin/env time -f '%U %S' -o "$out/t" "$caustic" render "$SCENE" --width "$W" --height "$H" \
    --threads 2 "$@" > "$log" 2>&1
  awk '{printf "%.2f\n", $1 + $2}' "$out/t"
}

# CPU seconds of one Mitsuba render (its render calls); args: spp seed out.
mitsuba_cpu() {
  "$PY" scripts/mitsuba/foggy_box.py --width "$W" --height "$H" --threads 2 --spp "$1" \
    --seed "$2" -o "$3" | grep -o 'cpu_s=[0-9.]*' | cut -d= -f2
}

mkdir -p "$REF_DIR"
for seed in 101 102; do
  ref=$REF_DIR/mitsuba_${ref_spp}_$seed.exr
  if [ ! -f "$ref" ]; then
    echo "reference half: Mitsuba volpath, $ref_spp spp, seed $seed → $ref"
    echo "  $(mitsuba_cpu "$ref_spp" "$seed" "$ref") CPU s"
  fi
done
REF1=$REF_DIR/mitsuba_${ref_spp}_101.exr
REF2=$REF_DIR/mitsuba_${ref_spp}_102.exr

if [ -n "${CAUSTIC_BIN:-}" ]; then who_c="caustic binary $caustic"; else who_c="caustic $(git rev-parse --short HEAD 2>/dev/null || echo '?')"; fi
echo "$who_c, Mitsuba $("$PY" -c 'import mitsuba; print(mitsuba.__version__)'); $(nproc) CPUs:$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2)"
echo "load before: $(cut -d' ' -f1-3 /proc/loadavg); budget $budget CPU s per render, 2 threads, ${W}×${H}"
declare -A rmse
for who in caustic mitsuba; do
  if [ "$who" = caustic ]; then
    cal=4
    cc=$(caustic_cpu "$out/cal.log" "$@" --spp "$cal" --seed 9 -o "$out/cal.exr")
  else
    cal=16
    cc=$(mitsuba_cpu "$cal" 9 "$out/cal.exr")
  fi
  spp=$(python3 -c "print(max(1, round($budget * $cal / $cc)))")
  if [ "$who" = caustic ]; then
    c1=$(caustic_cpu "$out/${who}1.log" "$@" --spp "$spp" --seed 1 -o "$out/${who}1.exr")
    c2=$(caustic_cpu "$out/${who}2.log" "$@" --spp "$spp" --seed 2 -o "$out/${who}2.exr")
  else
    c1=$(mitsuba_cpu "$spp" 1 "$out/${who}1.exr")
    c2=$(mitsuba_cpu "$spp" 2 "$out/${who}2.exr")
  fi
  figs=$("$PY" scripts/mitsuba/z8.py "$out/${who}1.exr" "$out/${who}2.exr" "$REF1" --ref2 "$REF2" --noise)
  r=$(echo "$figs" | grep -o '\brmse=[0-9.e-]*' | head -1 | cut -d= -f2)
  nz=$(echo "$figs" | grep -o 'noise_rmse=[0-9.e-]*' | head -1 | cut -d= -f2)
  scaled=$(python3 -c "c = ($c1 + $c2) / 2; print(f'{max(0.0, $r**2 - $nz**2 + $nz**2 * c / $budget) ** 0.5:.6f}')")
  rmse[$who]=$scaled
  printf '  %-8s %s spp in %s CPU s → %s spp: %s + %s CPU s; %s; rmse at the budget %s\n' \
    "$who" "$cal" "$cc" "$spp" "$c1" "$c2" "$figs" "$scaled"
done
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
echo "reference noise: $("$PY" scripts/mitsuba/z8.py "$REF1" "$REF2" "$REF1" --ref2 "$REF2" --noise | grep -o 'noise_rmse=[0-9.e-]*' | sed 's/noise_rmse/rmse_of_the_reference_mean/')"
python3 -c "print(f'RMSE(caustic) / RMSE(Mitsuba) at {$budget} CPU s each: {${rmse[caustic]} / ${rmse[mitsuba]}:.3f}')"
