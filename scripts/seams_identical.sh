#!/usr/bin/env bash
# Renders every scene in scenes/ with every integrator (PNG, EXR, EXR with layers, .part) plus
# the photon viewer and a debug-pixel tree at a small size with binary BIN into OUT, or, with
# `--compare A B`, compares two such folders: byte-identical files, and for the others the
# largest per-pixel relative difference (`caustic compare`).
# Usage: scripts/seams_identical.sh BIN OUT      scripts/seams_identical.sh --compare BIN A B
set -euo pipefail
cd "$(dirname "$0")/.."
if [ "${1:-}" = "--compare" ]; then
  bin=$2; a=$3; b=$4; same=0; differ=0
  for f in "$a"/*; do
    n=$(basename "$f")
    if [ "${n##*.}" = part ]; then
      # .part: the informational render time (`seconds=` in the metadata, and so the length
      # field and the checksum) differs between any two runs; compare everything else.
      if python3 - "$f" "$b/$n" <<'PY'
import sys
def norm(path):
    b = open(path, 'rb').read()
    i = b.index(b'seconds=')
    j = b.index(b'\n', i)
    return b[:i] + b[j:-8]
a, c = (norm(p) for p in sys.argv[1:3])
sys.exit(0 if a == c else 1)
PY
      then same=$((same+1)); continue; fi
    fi
    if cmp -s "$f" "$b/$n"; then same=$((same+1)); else
      differ=$((differ+1))
      case "$n" in
        *.exr) echo "DIFFERS $n: $("$bin" compare "$b/$n" "$f" 2>&1 | head -2 | tr '\n' ' ')";;
        *) echo "DIFFERS $n";;
      esac
    fi
  done
  echo "identical: $same, differing: $differ"
  exit 0
fi
bin=$1; out=$2; mkdir -p "$out"
W=40; H=30
# The raw estimate in every PNG: binaries since the default denoising take `--no-denoise`
# (older ones wrote it raw anyway), so old and new binaries compare like with like.
raw=()
if "$bin" render --help 2>/dev/null | grep -q -- --no-denoise; then raw=(--no-denoise); fi
for scene in scenes/*.ron scenes/*.toml; do
  s=$(basename "$scene"); s=${s%.*}_${scene##*.}
  for integ in whitted path photon ppm path-ppm; do
    common=(--width $W --height $H --spp 2 --seed 7 --threads 2 --quiet --integrator $integ)
    "$bin" render "$scene" "${common[@]}" "${raw[@]}" -o "$out/$s.$integ.png"
    "$bin" render "$scene" "${common[@]}" -o "$out/$s.$integ.exr"
    "$bin" render "$scene" "${common[@]}" -o "$out/$s.$integ.part"
    "$bin" render "$scene" "${common[@]}" --layers all -o "$out/$s.$integ.layers.exr"
    "$bin" debug-pixel "$scene" 20 15 --width $W --height $H --seed 7 --integrator $integ --json \
      > "$out/$s.$integ.debug.json" 2>&1 || true
  done
  "$bin" photons "$scene" --width $W --height $H -o "$out/$s.photons.png" >/dev/null 2>&1 || true
done
echo "rendered $(ls "$out" | wc -l) files into $out"
