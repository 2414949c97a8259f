#!/usr/bin/env bash
# The bath's error table in docs/gallery.md (issue 27): two long references by two different
# estimators (the default, path-ppm, 256 spp; photon 48 spp), the default and `photon` (the
# default before issue #24) under `--time 20s` at four seeds, and each one's relMSE against each
# reference, with the ratio default/photon per seed and the medians. (`path` is neither a
# reference nor a candidate for the bath: its rays see the sun's 0.27° disc only by chance, so
# its sun caustics through the water are rare enormous samples — two 64-spp path renders
# differ by relMSE ~300.)
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
rel() { "$B" compare "$O/$1.exr" "$O/$2.exr" --json | python3 -c "
import json, sys; print(json.load(sys.stdin)['figures']['overall']['rel_mse'])"; }
# The reference's own noise: two 64-spp renders of the default differ by about 2× the relMSE
# of one; a reference of N spp has about 64/N of one's.
echo "p1 vs p2 (the reference's noise): relMSE $(rel p1 p2)"
echo "ref_photon vs ref_ppm (the references' residual): relMSE $(rel ref_photon ref_ppm)"
# Four seeds (the scene's own, then 1, 2, 3): one render's relMSE is dominated by a few rare
# bright samples, so the ratio is quoted per seed and as the median over seeds.
: > "$O/ratios.txt"
for seed in scene 1 2 3; do
  flag=(); [ "$seed" = scene ] || flag=(--seed "$seed")
  d=$($B render scenes/bath.ron --time 20s "${flag[@]}" -o "$O/default_$seed.exr" 2>&1 | sed -n 's/.*, \([0-9]*\) spp.*/\1/p')
  p=$($B render scenes/bath.ron --integrator photon --time 20s "${flag[@]}" -o "$O/photon_$seed.exr" 2>&1 | sed -n 's/.*, \([0-9]*\) spp.*/\1/p')
  for r in ref_ppm ref_photon; do
    a=$(rel "default_$seed" $r); b=$(rel "photon_$seed" $r)
    ratio=$(python3 -c "print(f'{$a / $b:.3f}')")
    echo "seed $seed vs $r: default ($d spp) relMSE $a, photon ($p spp) relMSE $b, ratio $ratio"
    echo "$r $ratio $a $b" >> "$O/ratios.txt"
  done
done
for r in ref_ppm ref_photon; do
  python3 - "$O/ratios.txt" "$r" <<'PY'
import statistics, sys
rows = [l.split() for l in open(sys.argv[1]) if l.split()[0] == sys.argv[2]]
med = lambda i: statistics.median(float(x[i]) for x in rows)
print(f"vs {sys.argv[2]}: median ratio {med(1):.3f}; median relMSE default {med(2):.4f}, "
      f"photon {med(3):.4f} (ratio of medians {med(2) / med(3):.3f})")
PY
done
