#!/usr/bin/env bash
# The error-against-time figures of docs/convergence.md for the progressive integrators:
# references (long renders of another seed), then `caustic converge` per scene.
#
# Usage: scripts/convergence_figures.sh OUT_DIR [REFERENCE_MINUTES]
# References are kept in OUT_DIR and reused when present (delete them to remake). Run it on a
# quiet machine: the times are wall-clock times of 2 threads.
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:?usage: scripts/convergence_figures.sh OUT_DIR [REFERENCE_MINUTES]}
minutes=${2:-20}
mkdir -p "$out"
source scripts/caustic_bin.sh

# Per-pass photon counts for the progressive integrators (the scenes' own counts are sized for
# `photon`, which traces once).
cbox_pp=(--set photons.caustic=20000 --set photons.global=20000 --set photons.caustic_gather=20 --set photons.gather=20)
water_pp=(--set photons.caustic=50000 --set photons.global=10000 --set photons.caustic_gather=30 --set photons.gather=30)

ref() { # NAME SCENE INTEGRATOR [flags...]
  local name=$1 scene=$2 integrator=$3; shift 3
  if [ ! -f "$out/$name.exr" ]; then
    "$caustic" render "$scene" --integrator "$integrator" --seed 777 --spp 1000000 \
      --time "${minutes}m" -o "$out/$name.exr" "$@" 2>&1 | tail -2 | tee "$out/$name.log"
  fi
}

ref cbox_ref benches/scenes/cbox_caustic.ron path-ppm "${cbox_pp[@]}"
"$caustic" converge benches/scenes/cbox_caustic.ron --reference "$out/cbox_ref.exr" \
  --integrators path,path-ppm,ppm --time 90s -o "$out/cbox" "${cbox_pp[@]}"

ref water_ref scenes/water.ron path-ppm "${water_pp[@]}"
"$caustic" converge scenes/water.ron --reference "$out/water_ref.exr" \
  --integrators photon,ppm,path-ppm --time 96s -o "$out/water" "${water_pp[@]}"
