#!/usr/bin/env bash
# Error against a converged reference at a geometric series of samples per pixel, for both
# samplers, with wall time, samples/s and rays/s: the table in docs/performance.md.
#
# Usage: scripts/error_vs_spp.sh SCENE REFERENCE.exr "SPP LIST" [extra caustic flags...]
#   e.g. scripts/error_vs_spp.sh scenes/cornell.ron out/cornell_ref.exr "4 16 64 256" --width 128 --height 128
# Make the reference first with a long render of another seed, e.g.
#   caustic render SCENE --integrator path --sampler independent --seed 777 --spp 16384 -o REF.exr
set -euo pipefail
cd "$(dirname "$0")/.."
scene=$1; ref=$2; spps=$3; shift 3
source scripts/caustic_bin.sh
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
echo "| sampler | spp | time (s) | Msamples/s | Mrays/s | RMSE | relMSE |"
echo "|---|---:|---:|---:|---:|---:|---:|"
for sampler in independent sobol; do
  for spp in $spps; do
    line=$("$caustic" render "$scene" --integrator path --sampler "$sampler" --spp "$spp" \
      --quiet -o "$out/img.exr" "$@")
    # "img.exr: W×H, N spp, R rays in T s (M Mrays/s, ...)"
    secs=$(echo "$line" | sed -E 's/.* in ([0-9.]+) s.*/\1/')
    mrays=$(echo "$line" | sed -E 's/.*\(([0-9.]+) Mrays\/s.*/\1/')
    dims=$(echo "$line" | sed -E 's/.*: ([0-9]+)×([0-9]+),.*/\1 \2/')
    msps=$(echo "$dims $spp $secs" | awk '{printf "%.2f", $1*$2*$3/$4/1e6}')
    err=$("$caustic" compare "$out/img.exr" "$ref")
    rmse=$(echo "$err" | awk 'NR==1{print $2}')
    rel=$(echo "$err" | awk 'NR==1{print $4}')
    echo "| $sampler | $spp | $secs | $msps | $mrays | $rmse | $rel |"
  done
done
