#!/usr/bin/env bash
# The gallery's pictures of light in water and air (issue 44, docs/gallery.md "Light in water
# and air"): docs/images/bath_steam.png, docs/images/glass_of_water.png,
# docs/images/foggy_box.png, docs/images/volume_caustic.png and docs/images/fog_window.png, each
# at most 400×300 with its scene's own samples and estimator.
# Too slow for the doc-image test, so they are not lines of docs/images/manifest.txt
# (tests/it/doc_images.rs lists them in SCRIPT_MADE: the test checks only that each image exists
# and that this script makes it). Run it after a change to the renderer and copy the figures it
# prints (each render's summary line and its wall time, loading and photon tracing included,
# with the machine) into docs/gallery.md.
#
# Usage: scripts/media_images.sh [NAME...]
#   (default: all five: bath_steam glass_of_water foggy_box volume_caustic fog_window)
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/caustic_bin.sh
cpu=$(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo 2>/dev/null | head -n 1)
render() {
  local name=$1
  shift
  local out="docs/images/$name.png"
  echo "caustic render benches/scenes/$name.ron $* --no-denoise -o $out"
  local start end
  start=$(date +%s.%N)
  "$caustic" render "benches/scenes/$name.ron" "$@" --no-denoise -o "$out"
  end=$(date +%s.%N)
  echo "wall time $(awk -v a="$start" -v b="$end" 'BEGIN { printf "%.1f", b - a }') s on $(nproc) threads of ${cpu:-an unknown CPU}, $(date -u +'%-d %B %Y %H:%M UTC')"
}
names=("$@")
[ ${#names[@]} -eq 0 ] && names=(bath_steam glass_of_water foggy_box volume_caustic fog_window)
for name in "${names[@]}"; do
  case $name in
    # The scene's own 400×300 and 8 samples per pixel.
    bath_steam) render bath_steam ;;
    # 480×360 in the scene: 400×300 here, its 64 samples per pixel.
    glass_of_water) render glass_of_water --width 400 --height 300 ;;
    # 320×320 in the scene: 300×300 here, its 64 samples per pixel.
    foggy_box) render foggy_box --width 300 --height 300 ;;
    # Volumetric caustics: the scene's own 320×240 and 64 samples per pixel.
    volume_caustic) render volume_caustic ;;
    # Light shafts through a glass pane: the scene's own 320×240 and 32 samples per pixel.
    fog_window) render fog_window ;;
    *) echo "error: unknown picture \`$name\`; known: bath_steam, glass_of_water, foggy_box, volume_caustic, fog_window" >&2; exit 2 ;;
  esac
done
