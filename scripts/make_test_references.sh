#!/usr/bin/env bash
# Renders the converged references the statistical tests compare against
# (tests/it/references/). Slow: run only when a reference must change, and say why in the commit.
set -euo pipefail
cd "$(dirname "$0")/.."
run() { cargo run --release --quiet -- "$@"; }
run render scenes/cornell.ron --integrator path --sampler independent --seed 1000 \
    --width 32 --height 32 --spp 16384 --quiet -o tests/it/references/cornell_path_32.exr
