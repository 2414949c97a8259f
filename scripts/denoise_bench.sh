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
"$bin" render "$scene" --spp "$high" --threads "$threads" --layers caustic -o "$out/high.exr"
"$venv/bin/python" "$here/denoise_bench.py" --low "$out/low.exr" --high "$out/high.exr" \
    --reference "$reference" --oidn-out "$out/oidn.exr" --json "$out/figures.json"
