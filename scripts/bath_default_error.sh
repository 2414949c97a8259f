#!/usr/bin/env bash
# The bath at its defaults against an independent reference (issue #43: "relMSE ≤ 0.5× today's at
# the same render time"), at 200×150 so that many seeds fit: for each seed the default (a PNG
# would be denoised: here its EXR twin, `--denoise`), the raw estimate at the scene's 8 spp, and
# the raw estimate at 10 spp (about the denoised default's time: features and denoiser add
# ≈ 17 %, docs/denoise.md). Prints each relMSE, then the medians.
#
#   scripts/bath_default_error.sh REF [OUT] [SEEDS]
# REF: the bath's reference at 200×150, e.g. the `ppm` one of docs/denoise.md ("Measured":
# `render scenes/bath.ron --width 200 --height 150 --integrator ppm --spp 4096 --time 80m --seed
# 103 --threads 1 -o bath.ref.exr`). SEEDS default "101 102 103 104 105 106 107 108".
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/caustic_bin.sh
ref=$1
out=${2:-target/bath-default-error}
seeds=${3:-101 102 103 104 105 106 107 108}
mkdir -p "$out"
rel() { "$caustic" compare "$1" "$ref" --json | python3 -c 'import json,sys; print(json.load(sys.stdin)["figures"]["overall"]["rel_mse"])'; }
for s in $seeds; do
  common=(scenes/bath.ron --width 200 --height 150 --seed "$s" --quiet)
  "$caustic" render "${common[@]}" --denoise -o "$out/den$s.exr" >/dev/null
  "$caustic" render "${common[@]}" -o "$out/raw$s.exr" >/dev/null
  "$caustic" render "${common[@]}" --spp 10 -o "$out/raw10_$s.exr" >/dev/null
  echo "seed $s: denoised 8 spp $(rel "$out/den$s.exr"), raw 8 spp $(rel "$out/raw$s.exr"), raw 10 spp $(rel "$out/raw10_$s.exr")"
done | tee "$out/table.txt"
for k in 6 10 14; do
  awk -v k=$k '{gsub(",", "", $k); print $k}' "$out/table.txt" | sort -g | awk '{a[NR]=$1} END {printf "%s ", (NR % 2) ? a[(NR+1)/2] : (a[NR/2] + a[NR/2+1]) / 2}'
done | awk '{print "medians: denoised 8 spp " $1 ", raw 8 spp " $2 ", raw 10 spp " $3}'
