#!/usr/bin/env bash
# Issue #24's "error keeps falling" target: the log-log slope of RMSE against render time from
# 4 s to MAX_SECONDS (the issue: 256) for caustic's default estimator on the caustic Cornell box
# (against ../shared/bench/mitsuba/cbox_caustic.ref.exr, Mitsuba 3's curve on the same plot) and
# on the pool scene (against the reference of scripts/pool_reference.sh; caustic only). Run it on
# a QUIET machine: every figure is wall-clock. It prints its expected run time first.
#
#   scripts/convergence_slopes.sh [MAX_SECONDS] [OUT_DIR] [POOL_REF_DIR]
#     MAX_SECONDS  256 (the issue's range, about 25 min), 64 (about 7 min) or any 4·2^k
#     OUT_DIR      default ../convergence_slopes_MAX (CSVs, SVG plots, JSON, the last images)
#     POOL_REF_DIR default ../pool_ref (pool_ref.exr and its halves pool_ref_h{1,2}.exr)
#   SKIP_MITSUBA=1 / SKIP_POOL=1 leave those parts out.
#
# Caustic: `caustic render SCENE --time Ts --threads 2 --seed 1` for T = 4, 8, …, MAX (separate
# renders: `caustic converge` measures at 1, 2, 4, … spp, not at given times, and cannot draw
# another renderer's curve), the scene naming no integrator (the default estimator: path-ppm with
# the per-pass photons it chooses). The point's time is the render time the summary reports.
# Mitsuba 3 (`render.py`, `path` + `ldsampler`, 2 threads): a 64-spp calibration gives its time
# per sample τ; then N = 2^k spp from N ≈ 4/τ to N ≈ MAX/τ (rounded to the nearest power of two
# in log), each rendered as one `render.py` call when N ≤ 1024 and N is a power of 4 (ldsampler
# rounds other counts UP to a power of 4: asked for 32 it renders 64), else as the mean of calls
# of equal power-of-4 counts ≤ 1024 (seeds 1, 2, …); its time is the sum of their `render_s`
# (kernels warm, process start excluded). Caustic and Mitsuba renders alternate, level by level.
# RMSE everywhere is `caustic compare`'s (√ mean (a − b)² over pixels and channels).
# Slopes: least squares of ln RMSE against ln time over all points (`caustic plot`),
# also with the reference's own noise σ taken out (√(RMSE² − σ²)): σ = 0.005 for the Mitsuba
# reference (its README), and for the pool reference the RMSE of its halves' mean noise.
# Quick check that it runs: scripts/convergence_slopes.sh 8
set -euo pipefail
cd "$(dirname "$0")/.."
MAX=${1:-256}
OUT=${2:-../convergence_slopes_$MAX}
POOL_REF_DIR=${3:-${POOL_REF_DIR:-../pool_ref}}
source scripts/caustic_bin.sh
M=../shared/bench/mitsuba
PY=${MITSUBA_PY:-/root/.cache/mitsuba3-venv/bin/python}
[ -x "$PY" ] || PY=$(bash "$M/setup.sh")
CB=benches/scenes/cbox_caustic.ron
CB_REF=$M/cbox_caustic.ref.exr
CB_REF_NOISE=${CB_REF_NOISE:-0.005}
POOL=benches/scenes/pool.ron
POOL_REF=$POOL_REF_DIR/pool_ref.exr
CHUNK=1024
times=()
for ((t = 4; t <= MAX; t *= 2)); do times+=("$t"); done
if [ ${#times[@]} -lt 2 ]; then
  echo "error: MAX_SECONDS must be at least 8 (the points are 4, 8, …, MAX s)" >&2
  exit 2
fi
[ "${SKIP_POOL:-0}" = 1 ] || [ -f "$POOL_REF" ] || {
  echo "error: no pool reference at $POOL_REF (scripts/pool_reference.sh), or SKIP_POOL=1" >&2
  exit 2
}
mkdir -p "$OUT"

# Mitsuba's levels for a time per sample τ: powers of two from round(log2(4/τ)) to
# round(log2(MAX/τ)); prints "spp chunk_spp chunks" per level.
levels() {
  python3 - "$1" "$MAX" "$CHUNK" <<'EOF'
import math, sys
tau, mx, chunk = float(sys.argv[1]), float(sys.argv[2]), int(sys.argv[3])
lo, hi = round(math.log2(4 / tau)), round(math.log2(mx / tau))
for k in range(max(lo, 2), max(hi, 2) + 1):
    n = 2 ** k
    c = 4 ** int(math.log(min(n, chunk), 4) + 1e-9)   # largest power of 4 <= min(n, chunk)
    print(n, c, n // c)
EOF
}
# Expected run time: caustic Σ T per scene plus ~3 s per render (load, BVH, process); Mitsuba
# about 2·MAX of rendering (the doubling series up to ≈ MAX) plus ~3 s per render.py call.
estimate() { # tau
  python3 - "$1" "$MAX" "${#times[@]}" "${SKIP_MITSUBA:-0}" "${SKIP_POOL:-0}" "$(levels "$1" | awk '{s += $3} END {print s}')" \
    "$(levels "$1" | awk -v t="$1" '{s += $1 * t} END {print s}')" <<'EOF'
import sys
tau, mx, n, skm, skp, calls, mrender = sys.argv[1:]
mx, n, calls, mrender = float(mx), int(n), int(calls), float(mrender)
caustic = (2 * mx - 4 + 3 * n) * (1 if skp == "1" else 2)
mitsuba = 0 if skm == "1" else mrender + 3 * calls + 15
print(f"{(caustic + mitsuba) / 60:.0f} min (caustic {caustic / 60:.1f} min, Mitsuba {mitsuba / 60:.1f} min)")
EOF
}
# τ on a quiet 2-vCPU AMD EPYC: 256 spp in 6.2 s (docs/convergence.md, 5 December 2026).
echo "caustic $(git rev-parse --short HEAD 2>/dev/null || echo '?'); $(nproc) CPUs:$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2)"
echo "points at ${times[*]} s; expected run time on a quiet 2-vCPU machine: about $(estimate 0.0242)"
echo "load before: $(cut -d' ' -f1-3 /proc/loadavg)"
echo "load before: $(cut -d' ' -f1-3 /proc/loadavg)" > "$OUT/machine.txt"
grep -m1 'model name' /proc/cpuinfo >> "$OUT/machine.txt"

# `caustic compare`'s overall RMSE and relMSE of an image against a reference: "rmse,rel_mse".
figs() {
  "$caustic" compare "$1" "$2" --json | python3 -c 'import json, sys
f = json.load(sys.stdin)["figures"]["overall"]
print("%.8f,%.8f" % (f["rmse"], f["rel_mse"]))'
}
# caustic render at T seconds → a CSV row (seconds, rmse, rel_mse, spp, budget).
caustic_point() { # scene ref T csv tag
  local log
  log=$("$caustic" render "$1" --threads 2 --seed 1 --time "$3s" --quiet -o "$OUT/$5_$3s.exr" 2>/dev/null | tail -1)
  local spp secs
  spp=$(echo "$log" | sed -n 's/.*, \([0-9]*\) spp,.*/\1/p')
  secs=$(echo "$log" | sed -n 's/.* in \([0-9.]*\) s (.*/\1/p')
  echo "$secs,$(figs "$OUT/$5_$3s.exr" "$2"),$spp,$3" >> "$4"
  echo "  caustic $5 --time $3s: $(tail -1 "$4")"
}
mitsuba_point() { # spp chunk_spp chunks csv
  local n=$1 c=$2 k=$3 total=0 files=()
  for j in $(seq "$k"); do
    local line t
    line=$("$PY" "$M/render.py" --spp "$c" --sampler ldsampler --threads 2 --seed "$j" -o "$OUT/m_${n}_$j.exr" 2>/dev/null)
    t=$(echo "$line" | grep -o 'render_s=[0-9.]*' | cut -d= -f2)
    total=$(python3 -c "print(round($total + $t, 3))")
    files+=("$OUT/m_${n}_$j.exr")
  done
  if [ "$k" -gt 1 ]; then
    "$PY" scripts/mitsuba/mean_exr.py "$OUT/mitsuba_${n}spp.exr" "${files[@]}"
    rm -f "${files[@]}"
  else
    mv "${files[0]}" "$OUT/mitsuba_${n}spp.exr"
  fi
  echo "$total,$(figs "$OUT/mitsuba_${n}spp.exr" "$CB_REF"),$n,${k}x$c" >> "$4"
  echo "  mitsuba $n spp ($k × $c): $(tail -1 "$4")"
}

echo "seconds,rmse,rel_mse,spp,budget_s" > "$OUT/caustic_cbox.csv"
echo "seconds,rmse,rel_mse,spp,calls" > "$OUT/mitsuba_cbox.csv"
mlevels=()
if [ "${SKIP_MITSUBA:-0}" != 1 ]; then
  cal=$("$PY" "$M/render.py" --spp 64 --sampler ldsampler --threads 2 --seed 99 -o "$OUT/m_cal.exr" 2>/dev/null)
  tau=$(echo "$cal" | grep -o 'render_s=[0-9.]*' | cut -d= -f2 | awk '{print $1 / 64}')
  rm -f "$OUT/m_cal.exr"
  mapfile -t mlevels < <(levels "$tau")
  echo "Mitsuba: $(echo "$cal" | grep -o 'mitsuba [0-9][0-9.]*'), $tau s per sample here; levels (spp, chunk, calls): ${mlevels[*]/%/;}"
  echo "expected run time with this τ: about $(estimate "$tau")"
fi
echo "cbox (caustic default and Mitsuba 3, alternating):"
n=$(( ${#times[@]} > ${#mlevels[@]} ? ${#times[@]} : ${#mlevels[@]} ))
for ((i = 0; i < n; i++)); do
  [ $i -lt ${#times[@]} ] && caustic_point "$CB" "$CB_REF" "${times[$i]}" "$OUT/caustic_cbox.csv" cbox
  if [ $i -lt ${#mlevels[@]} ]; then
    read -r spp c k <<< "${mlevels[$i]}"
    mitsuba_point "$spp" "$c" "$k" "$OUT/mitsuba_cbox.csv"
  fi
done
if [ "${SKIP_POOL:-0}" != 1 ]; then
  echo "seconds,rmse,rel_mse,spp,budget_s" > "$OUT/caustic_pool.csv"
  echo "pool (caustic default):"
  for t in "${times[@]}"; do caustic_point "$POOL" "$POOL_REF" "$t" "$OUT/caustic_pool.csv" pool; done
fi
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)" | tee -a "$OUT/machine.txt"

echo
echo "slopes of RMSE against time (target for caustic: ≤ −0.4 on both scenes):"
curves=("caustic default=$OUT/caustic_cbox.csv")
[ "${SKIP_MITSUBA:-0}" = 1 ] || curves+=("Mitsuba 3 path+ldsampler=$OUT/mitsuba_cbox.csv")
"$caustic" plot "${curves[@]}" -o "$OUT/cbox" --ref-noise "$CB_REF_NOISE" \
  --title "cbox_caustic 256x256, 2 threads: RMSE against render time"
if [ "${SKIP_POOL:-0}" != 1 ]; then
  pool_noise=0
  if [ -f "$POOL_REF_DIR/pool_ref_h1.exr" ] && [ -f "$POOL_REF_DIR/pool_ref_h2.exr" ]; then
    pool_noise=$("$PY" scripts/mitsuba/z8.py "$POOL_REF_DIR/pool_ref_h1.exr" "$POOL_REF_DIR/pool_ref_h2.exr" "$POOL_REF" \
      --light 1000 --noise | grep -o 'noise_rmse=[0-9.]*' | cut -d= -f2)
  fi
  "$caustic" plot "caustic default=$OUT/caustic_pool.csv" -o "$OUT/pool" --ref-noise "$pool_noise" \
    --title "pool 320x240, 2 threads: RMSE against render time"
fi
echo "wrote into $OUT: the CSVs (seconds,rmse,rel_mse,spp,…), the plots (SVG, PNG), the slopes as JSON, machine.txt and the images"
