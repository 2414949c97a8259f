#!/usr/bin/env bash
# The gallery's high-quality bathroom, docs/images/bath_hq.png: scenes/bath.ron at its own
# 800×600 and estimator with many more samples per pixel than the scene's 8. Too slow for the
# doc-image test, so it is not a line of docs/images/manifest.txt (tests/it/doc_images.rs lists
# it in SCRIPT_MADE: the test checks only that the image exists and that this script makes it).
# Run it on a quiet machine after a change to the renderer, and copy the figures it prints (the
# render's own summary line and the whole run's wall time, photon tracing and loading included,
# with the machine) into docs/gallery.md.
#
# Usage: scripts/bath_hq.sh [SPP]   (default 128)
set -euo pipefail
cd "$(dirname "$0")/.."
spp=${1:-128}
source scripts/caustic_bin.sh
out=docs/images/bath_hq.png
echo "caustic render scenes/bath.ron --spp $spp --no-denoise -o $out"
start=$(date +%s.%N)
"$caustic" render scenes/bath.ron --spp "$spp" --no-denoise -o "$out"
end=$(date +%s.%N)
cpu=$(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo 2>/dev/null | head -n 1)
echo "wall time $(awk -v a="$start" -v b="$end" 'BEGIN { printf "%.1f", b - a }') s (loading and photon tracing included) on $(nproc) threads of ${cpu:-an unknown CPU}, $(date +'%-d %B %Y')"
