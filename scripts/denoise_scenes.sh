#!/usr/bin/env bash
# The denoiser's figures on the bath, the glass of water and the pool at noon (issue 46's
# "Measured" list; docs/denoise.md), at reduced size: for each scene the default render (its
# own samples per pixel, the default estimator) with `--denoise`, the same scene noisy at 16×
# the samples, OIDN on the same noisy inputs, each against a reference, by
# scripts/denoise_bench.py (relMSE; the caustic region, where the caustic layer is at least half
# of the light: its mean over the reference's and the correlation with the reference there).
#
#   scripts/denoise_scenes.sh [BIN] [OUT]        BIN: caustic (default target/release/caustic)
#   SCENES="bath water pool" REF_DIR=DIR THREADS=2 KEEP_HIGH=1 scripts/denoise_scenes.sh
# (KEEP_HIGH=1: an OUT/<scene>.high.exr already there is used, not rendered again; the noisy
# renders do not depend on the denoiser.)
#
# The candidates use seed 101; the references another seed (or another estimator), so their
# noise is independent. References: REF_DIR/<scene>.ref.exr when present (same size), else
# rendered here (not timed; they take long on a loaded machine):
#   bath:  `--integrator ppm` (pure progressive photon mapping: another estimator than the
#          default path-ppm under test), 1284 passes, seed 103, 200×150 (80 min on one thread;
#          it agrees with path-ppm at 128 passes of 100 000 caustic photons within 1.3 % on the
#          tub floor's caustic, where `--integrator photon` read 4 % above both before its maps took
#          the sample-point estimate: docs/denoise.md);
#   water: benches/scenes/user/glass_of_water.ron, default estimator, 1024 spp, seed 7, 128×96;
#   pool:  benches/scenes/user/pool_noon.ron, default estimator, 1024 spp, seed 7, 128×96.
# The caustic region is read from the 16×-spp render's caustic layer. Pictures (PNG, the
# scene's tone curve) of every image and a crop around the caustic's hot spot go to OUT.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(dirname "$here")"
bin="${1:-$root/target/release/caustic}"
out="${2:-$root/target/denoise-scenes}"
threads="${THREADS:-2}"
venv="${VENV:-$root/target/denoise-venv}"
ref_dir="${REF_DIR:-$out}"
scenes="${SCENES:-bath water pool}"
mkdir -p "$out" "$ref_dir"
if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
    "$venv/bin/pip" install --quiet numpy openexr pyoidn
fi
for name in $scenes; do
    case $name in
        bath) scene=scenes/bath.ron size=(--width 200 --height 150) spp=8
              ref=(--integrator ppm --spp 1284 --seed 103) look=(--exposure 0.3 --tonemap aces) ;;
        water) scene=benches/scenes/user/glass_of_water.ron size=(--width 128 --height 96) spp=4
               ref=(--spp 1024 --seed 7) look=(--exposure 1.0 --tonemap aces) ;;
        pool) scene=benches/scenes/user/pool_noon.ron size=(--width 128 --height 96) spp=4
              ref=(--spp 1024 --seed 7) look=(--exposure 0.15 --tonemap aces) ;;
        *) echo "unknown scene $name (bath, water, pool)" >&2; exit 2 ;;
    esac
    if [ ! -f "$ref_dir/$name.ref.exr" ]; then
        "$bin" render "$root/$scene" "${size[@]}" "${ref[@]}" --threads "$threads" --quiet \
            -o "$ref_dir/$name.ref.exr"
    fi
    "$bin" render "$root/$scene" "${size[@]}" --spp "$spp" --seed 101 --threads "$threads" \
        --denoise --layers albedo,normal,depth,caustic -o "$out/$name.low.exr"
    if [ -z "${KEEP_HIGH:-}" ] || [ ! -f "$out/$name.high.exr" ]; then
        "$bin" render "$root/$scene" "${size[@]}" --spp $((16 * spp)) --seed 101 \
            --threads "$threads" --layers caustic --quiet -o "$out/$name.high.exr"
    fi
    echo "== $name: ${size[*]}, $spp spp denoised against $((16 * spp)) spp noisy"
    "$venv/bin/python" "$here/denoise_bench.py" --low "$out/$name.low.exr" \
        --high "$out/$name.high.exr" --reference "$ref_dir/$name.ref.exr" --caustic-share 0.5 \
        "${look[@]}" --pictures "$out/$name." --crop "$out/$name.crop." \
        --json "$out/$name.figures.json"
done
