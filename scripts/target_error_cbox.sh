#!/usr/bin/env bash
# `--target-error` on the caustic Cornell box (issue #43): for each seed, renders
# benches/scenes/cbox_caustic.ron with the default estimator until its estimated relMSE is at
# most TARGET, then scores the image against the Mitsuba 3 reference
# (../shared/bench/mitsuba/cbox_caustic.ref.exr) with `caustic compare`. Prints per seed the
# samples per pixel and time reached, the estimate, the true relMSE and true / target (the
# issue asks for ≤ 1.3). Times are wall-clock: run it on a quiet machine for timing figures.
#
# Usage: scripts/target_error_cbox.sh [TARGET] [SEEDS...]   (default: 0.01, seeds 1 2 3)
set -euo pipefail
cd "$(dirname "$0")/.."
target=${1:-0.01}
shift $(( $# > 0 ? 1 : 0 ))
seeds=("$@")
[ ${#seeds[@]} -gt 0 ] || seeds=(1 2 3)
source scripts/caustic_bin.sh
REF=../shared/bench/mitsuba/cbox_caustic.ref.exr
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
echo "load before: $(cut -d' ' -f1-3 /proc/loadavg)"
for seed in "${seeds[@]}"; do
  line=$("$caustic" render benches/scenes/cbox_caustic.ron --threads 2 --seed "$seed" \
    --target-error "$target" -o "$out/c$seed.exr" 2>&1 | grep '^target error')
  est=$(echo "$line" | sed -n 's/.*estimated relMSE \([0-9.]*\).*/\1/p')
  spp=$(echo "$line" | sed -n 's/.* at \([0-9]*\) spp in \([0-9.]*\) s.*/\1/p')
  secs=$(echo "$line" | sed -n 's/.* spp in \([0-9.]*\) s.*/\1/p')
  true_rel=$("$caustic" compare "$out/c$seed.exr" "$REF" | sed -n 's/.*relMSE \([0-9.]*\).*/\1/p' | head -1)
  ratio=$(awk -v t="$true_rel" -v x="$target" 'BEGIN { printf "%.3f", t / x }')
  echo "seed $seed: $spp spp in $secs s, estimated relMSE $est, true relMSE $true_rel, true / target $ratio"
done
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
