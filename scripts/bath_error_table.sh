#!/usr/bin/env bash
# The bath's error table in docs/gallery.md (issue 27): two long references by two different
# estimators (the default, path-ppm, 256 spp; photon 48 spp), each candidate (default, photon,
# path) under `--time 20s`, and every candidate's relMSE against every reference. (`path` is no
# reference for the bath: its rays see the sun's 0.27° disc only by chance, so its sun caustics
# through the water are rare enormous samples — two 64-spp path renders differ by relMSE ~300.)
#
#   scripts/bath_error_table.sh [OUT] [refs|timed|all]
#
# `refs` renders the references (about 22 min on a 2-vCPU machine; not timed, so the machine
# may be busy); `timed` renders the candidates under `--time 20s` and prints the table — run it
# on a quiet machine only; `all` (the default) does both.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/caustic_bin.sh
B=$caustic
O=${1:-/tmp/bath_error_table}
PHASE=${2:-all}
mkdir -p "$O"
if [ "$PHASE" != timed ]; then
  $B render scenes/bath.ron --spp 256 --seed 101 -o "$O/ref_ppm.exr" 2>&1 | grep spp
  $B render scenes/bath.ron --integrator photon --spp 48 --seed 102 -o "$O/ref_photon.exr" 2>&1 | grep spp
  $B render scenes/bath.ron --spp 64 --seed 17 -o "$O/p1.exr" --quiet
  $B render scenes/bath.ron --spp 64 --seed 18 -o "$O/p2.exr" --quiet
  sha256sum "$O"/ref*.exr
fi
[ "$PHASE" = refs ] && exit 0
echo "== load"; uptime
$B render scenes/bath.ron --time 20s -o "$O/default.exr" 2>&1 | grep spp
$B render scenes/bath.ron --integrator photon --time 20s -o "$O/photon.exr" 2>&1 | grep spp
$B render scenes/bath.ron --integrator path --time 20s -o "$O/path.exr" 2>&1 | grep spp
rel() { "$B" compare "$O/$1.exr" "$O/$2.exr" --json | python3 -c "
import json, sys; o = json.load(sys.stdin)['figures']['overall']
print(f\"$1 vs $2: relMSE {o['rel_mse']:.4f} rmse {o['rmse']:.4f} bias {o['bias']:+.4f}\")"; }
# The reference's own noise: two 64-spp renders of the default differ by about 2× the relMSE
# of one; a reference of N spp has about 64/N of one's.
rel p1 p2
for r in ref_ppm ref_photon; do for c in default photon path; do rel $c $r; done; done
rel ref_photon ref_ppm
