#!/usr/bin/env bash
# The README's picture of the flagship at its defaults, docs/images/bath_default.png: exactly the
# README's first command, `caustic render scenes/bath.ron -o bath.png` (800×600, 8 samples per
# pixel, the default estimator, denoised by default: docs/denoise.md). Denoising is not local
# to a crop, so the doc-image test cannot check it row by row: it is not a line of
# docs/images/manifest.txt (tests/it/doc_images.rs lists it in SCRIPT_MADE and checks that it
# exists and that this script makes it). Run it after a change to the renderer and copy the
# figures it prints into README.md.
#
# Usage: scripts/bath_default.sh
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/caustic_bin.sh
out=docs/images/bath_default.png
echo "caustic render scenes/bath.ron -o $out"
start=$(date +%s.%N)
"$caustic" render scenes/bath.ron -o "$out"
end=$(date +%s.%N)
cpu=$(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo 2>/dev/null | head -n 1)
echo "wall time $(awk -v a="$start" -v b="$end" 'BEGIN { printf "%.1f", b - a }') s (loading, photon tracing and denoising included) on $(nproc) threads of ${cpu:-an unknown CPU}, $(date +'%-d %B %Y')"
