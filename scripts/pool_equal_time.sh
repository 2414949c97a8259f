#!/usr/bin/env bash
# Issue #24's pool-scene table: on benches/scenes/pool.ron (320×240), the default estimator
# (the scene names no integrator: path-ppm with the per-pass photons it chooses), `photon` (the
# scene's photon settings) and `path`, each with `--time BUDGET` (default 16s), 2 threads,
# seeds 1 and 2, alternating (the order rotates from round to round), ROUNDS times (default 3),
# against the pool reference of scripts/pool_reference.sh (REF_DIR/pool_ref.exr, default
# ../pool_ref). Run it on a QUIET machine: the budgets are wall-clock.
#
#   scripts/pool_equal_time.sh [ROUNDS] [BUDGET] [REF_DIR]
#
# Per round and estimator (figures of the two-seed mean M against the reference, by
# scripts/mitsuba/z8.py, as scripts/mitsuba_equal_time.sh computes them for cbox): RMSE, relMSE
# (caustic compare's definitions), mean / ref, z8 (mean of z² over 8×8 blocks and channels, each
# pixel's variance from the two seeds; blocks with a pixel of reference ≥ 1000, the light seen
# directly, excluded: none in this scene), and the glint figure: the brightest pixel of each
# seed's image (largest channel; pixels seeing the light and their neighbours excluded) over the
# reference's brightest there, the worse of the two seeds. Then the medians over the rounds and
# the issue's targets for the default: mean within 1 %, RMSE ≤ 0.5× photon's (per round, the
# median ratio), z8 ≤ 2, glint ≤ 1.5 at every seed (the worst over all rounds).
# Quick check that it runs: scripts/pool_equal_time.sh 1 2s
set -euo pipefail
cd "$(dirname "$0")/.."
rounds=${1:-3}
budget=${2:-16s}
REF_DIR=${3:-${POOL_REF_DIR:-../pool_ref}}
source scripts/caustic_bin.sh
M=../shared/bench/mitsuba
PY=${MITSUBA_PY:-/root/.cache/mitsuba3-venv/bin/python}
[ -x "$PY" ] || PY=$(bash "$M/setup.sh")
SCENE=benches/scenes/pool.ron
REF=$REF_DIR/pool_ref.exr
# sha256 of the reference made by scripts/pool_reference.sh at caustic 80ce43c (docs/convergence.md).
REF_SHA=${POOL_REF_SHA:-6e9b0ca39f8f79f5704542a89e017f579f46f772c7b50a14f96ecccf1228a842}
if [ ! -f "$REF" ]; then
  echo "error: no reference at $REF: run scripts/pool_reference.sh $REF_DIR first (about 70 CPU-minutes)" >&2
  exit 2
fi
sha=$(sha256sum "$REF" | cut -d' ' -f1)
[ "$sha" = "$REF_SHA" ] || echo "warning: $REF has sha256 $sha, not the documented $REF_SHA" >&2
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
names=(default photon path)
flags_default=()
flags_photon=(--integrator photon)
flags_path=(--integrator path)
echo "caustic $(git rev-parse --short HEAD 2>/dev/null || echo '?'); $(nproc) CPUs:$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2)"
echo "load before: $(cut -d' ' -f1-3 /proc/loadavg); budget $budget per render, 2 threads, $rounds round(s)"
for r in $(seq "$rounds"); do
  # Rotate the order so that no estimator always runs first (or right after another).
  order=("${names[@]:$(( (r - 1) % 3 ))}" "${names[@]:0:$(( (r - 1) % 3 ))}")
  for seed in 1 2; do
    for e in "${order[@]}"; do
      declare -n fl="flags_$e"
      "$caustic" render "$SCENE" --threads 2 --seed "$seed" --time "$budget" --quiet \
        -o "$out/$e$seed.exr" "${fl[@]}" 2>/dev/null > "$out/$e$seed.log"
      unset -n fl
    done
  done
  echo "round $r (order ${order[*]}):"
  for e in "${names[@]}"; do
    spp1=$(sed -n 's/.*, \([0-9]*\) spp,.*/\1/p' "$out/${e}1.log")
    spp2=$(sed -n 's/.*, \([0-9]*\) spp,.*/\1/p' "$out/${e}2.log")
    figs=$("$PY" scripts/mitsuba/z8.py "$out/${e}1.exr" "$out/${e}2.exr" "$REF" --light 1000 --glint)
    echo "spp=$spp1/$spp2 $figs" >> "$out/$e.txt"
    printf '  %-8s spp %s/%s  %s\n' "$e" "$spp1" "$spp2" "$figs"
  done
  # This round's RMSE ratio default / photon.
  d=$(tail -1 "$out/default.txt" | grep -o 'rmse=[0-9.]*' | cut -d= -f2)
  p=$(tail -1 "$out/photon.txt" | grep -o 'rmse=[0-9.]*' | cut -d= -f2)
  python3 -c "print($d / $p)" >> "$out/ratio.txt"
done
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"

median() { sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }
key() { grep -o "$1=[0-9.]*" "$2" | cut -d= -f2; }
echo
echo "pool.ron 320×240, --time $budget, 2 threads, seeds 1+2; medians of $rounds round(s) (glint: worst seed of all rounds)"
echo
echo "| estimator | spp (seed 1 / 2) | RMSE | relMSE | mean / ref | z8 | brightest / ref's |"
echo "|---|---:|---:|---:|---:|---:|---:|"
for e in "${names[@]}"; do
  s1=$(grep -o 'spp=[0-9]*' "$out/$e.txt" | cut -d= -f2 | median)
  s2=$(grep -o 'spp=[0-9]*/[0-9]*' "$out/$e.txt" | cut -d/ -f2 | median)
  g=$(key glint_ratio "$out/$e.txt" | sort -g | tail -1)
  label=$e
  [ "$e" = default ] && label="default (path-ppm)"
  [ "$e" = photon ] && label="photon (scene settings)"
  echo "| $label | $s1 / $s2 | $(key rmse "$out/$e.txt" | median) | $(key relmse "$out/$e.txt" | median) | $(key mean_ratio "$out/$e.txt" | median) | $(key z8 "$out/$e.txt" | median) | $g |"
done
echo
ratio=$(median < "$out/ratio.txt")
mr=$(key mean_ratio "$out/default.txt" | median)
z8=$(key z8 "$out/default.txt" | median)
g=$(key glint_ratio "$out/default.txt" | sort -g | tail -1)
python3 - "$mr" "$ratio" "$z8" "$g" <<'EOF'
import sys
mr, ratio, z8, g = map(float, sys.argv[1:])
ok = lambda c: "met" if c else "NOT met"
print(f"targets for the default: mean within 1 %: {mr:.4f} ({ok(abs(mr - 1) <= 0.01)}); "
      f"RMSE <= 0.5x photon's: {ratio:.3f}x ({ok(ratio <= 0.5)}); z8 <= 2: {z8:.2f} ({ok(z8 <= 2)}); "
      f"brightest <= 1.5x the reference's at every seed: {g:.3f} ({ok(g <= 1.5)})")
EOF
