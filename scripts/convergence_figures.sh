#!/usr/bin/env bash
# The error-against-time figures of docs/convergence.md for the progressive integrators
# (ppm, path-ppm) against path and photon, on the caustic Cornell box, scenes/water.ron (at
# 320×200) and scenes/cornell.ron (at 64×64).
#
# Usage: scripts/convergence_figures.sh OUT_DIR [REFERENCE_MINUTES]
# References (long renders of another seed) are made in OUT_DIR unless present: cbox_ref.exr
# (path-ppm), water_ref.exr (path-ppm without global photons: path-traced indirect light),
# cornell_ref.exr (path, 8192 spp). Run it on a quiet machine: times are wall-clock times of
# 2 threads.
set -uo pipefail
cd "$(dirname "$0")/.."
out=${1:?usage: scripts/convergence_figures.sh OUT_DIR [REFERENCE_MINUTES]}
minutes=${2:-20}
mkdir -p "$out"
source scripts/caustic_bin.sh
B=$caustic
CB=../shared/bench/cbox_caustic.ron
[ -f "$CB" ] || CB=benches/scenes/cbox_caustic.ron
# Photon counts per pass (the scenes' own counts are sized for `photon`, which traces once).
PP=(--set photons.caustic=20000 --set photons.global=20000 --set photons.caustic_gather=20 --set photons.gather=20)
WP=(--width 320 --height 200 --set photons.caustic=50000 --set photons.global=0 --set photons.caustic_gather=30)
WPG=(--width 320 --height 200 --set photons.caustic=50000 --set photons.global=20000 --set photons.caustic_gather=30 --set photons.gather=30)

[ -f "$out/cbox_ref.exr" ] || "$B" render "$CB" --integrator path-ppm --seed 777 --spp 1000000 \
  --time "${minutes}m" "${PP[@]}" -o "$out/cbox_ref.exr"
[ -f "$out/water_ref.exr" ] || "$B" render scenes/water.ron --integrator path-ppm --seed 777 \
  --spp 1000000 --time "${minutes}m" "${WP[@]}" -o "$out/water_ref.exr"
[ -f "$out/cornell_ref.exr" ] || "$B" render scenes/cornell.ron --integrator path --sampler independent --seed 777 \
  --width 64 --height 64 --spp 8192 -o "$out/cornell_ref.exr"

echo "== load"; uptime
for it in path path-ppm ppm; do
  echo "== cbox $it, 26 s"
  extra=(); [ "$it" != path ] && extra=("${PP[@]}")
  "$B" render "$CB" --integrator "$it" --time 26s "${extra[@]}" -o "$out/c_${it}_26.exr" 2>&1 | grep -E "rays in|passes"
  "$B" compare "$out/c_${it}_26.exr" "$out/cbox_ref.exr" | head -1
done
for it in path-ppm ppm path; do
  echo "== water $it, 16 s"
  extra=("${WP[@]}"); [ "$it" = ppm ] && extra=("${WPG[@]}")
  "$B" render scenes/water.ron --integrator "$it" --time 16s "${extra[@]}" -o "$out/w_${it}_16.exr" 2>&1 | grep -E "rays in|passes"
  "$B" compare "$out/w_${it}_16.exr" "$out/water_ref.exr" | head -1
done
echo "== water photon (the scene's photon settings, 4 spp)"
"$B" render scenes/water.ron --integrator photon --width 320 --height 200 -o "$out/w_photon.exr" 2>&1 | grep -E "rays in"
"$B" compare "$out/w_photon.exr" "$out/water_ref.exr" | head -1
echo "== water path-ppm, first image (1 spp)"
"$B" render scenes/water.ron --integrator path-ppm --spp 1 "${WP[@]}" -o "$out/w_first.exr" 2>&1 | grep -E "rays in"
"$B" compare "$out/w_first.exr" "$out/water_ref.exr" | head -1
echo "== converge: cbox"
"$B" converge "$CB" --reference "$out/cbox_ref.exr" --integrators path,path-ppm,ppm --time 90s \
  -o "$out/cbox_conv" "${PP[@]}" --quiet 2>&1 | tail -3
echo "== converge: water"
"$B" converge scenes/water.ron --reference "$out/water_ref.exr" --integrators path-ppm,path \
  --time 64s -o "$out/water_conv" "${WP[@]}" --quiet 2>&1 | tail -3
"$B" converge scenes/water.ron --reference "$out/water_ref.exr" --integrators ppm \
  --time 32s -o "$out/water_conv_ppm" "${WPG[@]}" --quiet 2>&1 | tail -3
echo "== converge: cornell 64x64"
"$B" converge scenes/cornell.ron --reference "$out/cornell_ref.exr" --width 64 --height 64 \
  --integrators path,path-ppm,ppm --time 45s -o "$out/cornell_conv" "${PP[@]}" --quiet 2>&1 | tail -3
echo "== load"; uptime
