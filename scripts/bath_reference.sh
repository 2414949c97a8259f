#!/usr/bin/env bash
# The bath's long reference and the relMSE comparison of issue #27, for a QUIET machine (it
# takes the whole CPU for a long time; do not run it while others build).
#
#   scripts/bath_reference.sh [OUT_DIR] [REF_SPP] [BUDGET]
#
# 1. Renders the reference: scenes/bath.ron at 800×600 with `path` (unbiased) at REF_SPP
#    (default 1024) samples per pixel into OUT_DIR/bath_ref.exr (kept out of git; its sha256 is
#    printed for docs/gallery.md), with its render time.
# 2. Residual of the reference: a second, independent half (seed + 1, REF_SPP/2) compared with a
#    first half; the reference's own relMSE is about a quarter of the halves' mutual relMSE.
# 3. The default render (today's scene, its own integrator) under `--time BUDGET` (default 20s)
#    and 2c48cd9's default (the old binary, CAUSTIC_OLD, default /work/tgt/old/release/caustic:
#    photon, 6 spp, its own scene file from git) under the same budget, each compared with
#    the reference; prints both relMSE figures and their ratio (the issue asks ≤ 0.25).
# Small test run: WIDTH=80 HEIGHT=60 scripts/bath_reference.sh /tmp/bathref 16 2s
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${1:-/tmp/bath_reference}
SPP=${2:-1024}
BUDGET=${3:-20s}
W=${WIDTH:-800}
H=${HEIGHT:-600}
NEW=${CAUSTIC_BIN:-target/release/caustic}
OLD=${CAUSTIC_OLD:-/work/tgt/old/release/caustic}
mkdir -p "$OUT"
size=(--width "$W" --height "$H")

t0=$(date +%s.%N)
"$NEW" render scenes/bath.ron "${size[@]}" --integrator path --spp "$SPP" --quiet -o "$OUT/bath_ref.exr"
t1=$(date +%s.%N)
echo "reference: ${W}x${H}, path, $SPP spp, $(python3 -c "print(round($t1 - $t0, 1))") s wall"
sha256sum "$OUT/bath_ref.exr"

half=$((SPP / 2 > 0 ? SPP / 2 : 1))
"$NEW" render scenes/bath.ron "${size[@]}" --integrator path --spp "$half" --quiet -o "$OUT/half_a.exr"
"$NEW" render scenes/bath.ron "${size[@]}" --integrator path --spp "$half" --seed 16 --quiet -o "$OUT/half_b.exr"
echo "residual (two independent halves; the reference's relMSE ≈ a quarter of this):"
"$NEW" compare "$OUT/half_a.exr" "$OUT/half_b.exr" --json

relmse() { "$1" compare "$2" "$OUT/bath_ref.exr" --json | python3 -c 'import json,sys; print(json.load(sys.stdin)["figures"]["overall"]["rel_mse"])'; }

"$NEW" render scenes/bath.ron "${size[@]}" --time "$BUDGET" --quiet -o "$OUT/new.exr"
git show 2c48cd9:scenes/bath.ron > "$OUT/old_bath.ron"
# The old scene's assets are looked up relative to it: render it from scenes/.
cp "$OUT/old_bath.ron" scenes/.old_bath.ron
trap 'rm -f scenes/.old_bath.ron' EXIT
"$OLD" render scenes/.old_bath.ron "${size[@]}" --time "$BUDGET" --quiet -o "$OUT/old.exr"
new=$(relmse "$NEW" "$OUT/new.exr")
old=$(relmse "$NEW" "$OUT/old.exr")
echo "relMSE at $BUDGET: new default $new, 2c48cd9 default $old, ratio $(python3 -c "print($new / $old)") (want <= 0.25)"
