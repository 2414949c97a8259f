#!/usr/bin/env bash
# Denoiser yardstick (issue 46; docs/denoise.md): renders the caustic Cornell box at LOW spp with
# `--denoise` and the feature layers, and at HIGH spp noisy, then compares caustic's denoised
# image, Intel Open Image Denoise's on the same noisy image + albedo + normal (the `pyoidn`
# wheel from PyPI, installed into a venv: a yardstick only, not a dependency of caustic), and
# both noisy renders with Mitsuba 3's reference.
#
#   scripts/denoise_bench.sh [BIN] [OUT]      BIN: caustic binary (default target/release/caustic)
#   LOW=16 HIGH=256 THREADS=2 VENV=target/denoise-venv scripts/denoise_bench.sh
#
# Pictures (PNG, linear at EXPOSURE, default 1) of every image go to OUT/<image>.png, and 4×
# enlarged 48×48 crops around the caustic's hot spot to OUT/crop_<image>.png
# (scripts/denoise_gallery.sh puts them in docs/images for docs/gallery.md).
# The render and denoise times are printed by caustic ("denoised in … s"); time them on an idle
# machine.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(dirname "$here")"
bin="${1:-$root/target/release/caustic}"
out="${2:-$root/target/denoise-bench}"
low="${LOW:-16}"
high="${HIGH:-256}"
threads="${THREADS:-2}"
venv="${VENV:-$root/target/denoise-venv}"
scene="${SCENE:-$root/../shared/bench/cbox_caustic.ron}"
reference="${REFERENCE:-$root/../shared/bench/mitsuba/cbox_caustic.ref.exr}"
mkdir -p "$out"
if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
    "$venv/bin/pip" install --quiet numpy openexr pyoidn
fi
"$bin" render "$scene" --spp "$low" --threads "$threads" --denoise \
    --layers albedo,normal,depth,caustic -o "$out/low.exr"
# KEEP_HIGH=1: an OUT/high.exr already there is used (the noisy render does not depend on the
# denoiser).
if [ -z "${KEEP_HIGH:-}" ] || [ ! -f "$out/high.exr" ]; then
    "$bin" render "$scene" --spp "$high" --threads "$threads" --layers caustic -o "$out/high.exr"
fi
"$venv/bin/python" "$here/denoise_bench.py" --low "$out/low.exr" --high "$out/high.exr" \
    --reference "$reference" --oidn-out "$out/oidn.exr" --json "$out/figures.json" \
    --pictures "$out/" --crop "$out/crop_" --exposure "${EXPOSURE:-1}"
