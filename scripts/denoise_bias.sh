#!/usr/bin/env bash
# What a denoiser can reach on the bath, the glass of water and the pool (docs/denoise.md,
# "Bias and variance"): each scene rendered with SEEDS seeds (default 16) at its default
# samples per pixel with `--denoise` and the feature layers, at 16x the samples noisy, and
# (P4=1, the default) at the default samples with 4x the default estimator's caustic photons
# per pass; then scripts/denoise_bias.py splits each image's expected relMSE against the
# reference into bias^2 (the seeds' mean image against the reference, less the mean's own
# variance) and variance (the spread over seeds), per region: whole image, caustic region,
# rest. OIDN (pyoidn) is run on every seed's noisy inputs too. The water's and the pool's
# references are the default estimator at 16x the 16x render's samples: their own noise is
# estimated as that render's variance / 16 (the bath's, ppm's, is not known here).
#
#   scripts/denoise_bias.sh BIN OUT            (REF_DIR: where <scene>.ref.exr are)
#   SCENES="bath water pool" SEEDS=16 FIRST_SEED=101 P4=1 PY=python scripts/denoise_bias.sh ...
#
# Each render is one thread at nice 19 (the machine is shared); renders already in OUT are
# kept (the noisy renders do not depend on the denoiser: DENOISE_ONLY=1 re-renders only the
# low-spp ones, whose EXR holds the denoised image). The caustic region is the one
# scripts/denoise_bench.py uses (the first seed's 16x render's caustic layer, 7x7 average, at
# least half of its whole light, 7x7 average).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(dirname "$here")"
bin="${1:?usage: denoise_bias.sh BIN OUT}"
out="${2:?usage: denoise_bias.sh BIN OUT}"
ref_dir="${REF_DIR:-$root/target/denoise-scenes}"
scenes="${SCENES:-bath water pool}"
seeds="${SEEDS:-16}"
first="${FIRST_SEED:-101}"
py="${PY:-$root/target/denoise-venv/bin/python}"
run() { nice -n 19 "$bin" render "$@" --threads 1 --quiet; }
for name in $scenes; do
    case $name in
        bath) scene=scenes/bath.ron size=(--width 200 --height 150) spp=8 photons=9000 ratio=() ;;
        water) scene=benches/scenes/user/glass_of_water.ron size=(--width 128 --height 96) spp=4 photons=4000 ratio=(--ref-spp-ratio 16) ;;
        pool) scene=benches/scenes/user/pool_noon.ron size=(--width 128 --height 96) spp=4 photons=4000 ratio=(--ref-spp-ratio 16) ;;
        *) echo "unknown scene $name (bath, water, pool)" >&2; exit 2 ;;
    esac
    d="$out/$name"
    mkdir -p "$d"
    for ((s = first; s < first + seeds; s++)); do
        if [ -n "${DENOISE_ONLY:-}" ] || [ ! -f "$d/low.$s.exr" ]; then
            run "$root/$scene" "${size[@]}" --spp "$spp" --seed "$s" --denoise \
                --layers albedo,normal,depth,caustic -o "$d/low.$s.exr"
        fi
        if [ "${P4:-1}" = 1 ] && { [ -n "${DENOISE_ONLY:-}" ] || [ ! -f "$d/p4.$s.exr" ]; }; then
            run "$root/$scene" "${size[@]}" --spp "$spp" --seed "$s" --denoise \
                --set "photons.caustic=$((4 * photons))" --layers albedo,normal,depth,caustic \
                -o "$d/p4.$s.exr"
        fi
        if [ ! -f "$d/high.$s.exr" ]; then
            run "$root/$scene" "${size[@]}" --spp $((16 * spp)) --seed "$s" --layers caustic \
                -o "$d/high.$s.exr"
        fi
    done
    echo "== $name (${size[*]}, $spp spp; 16x: $((16 * spp)) spp; $seeds seeds from $first)"
    "$py" "$here/denoise_bias.py" --dir "$d" --reference "$ref_dir/$name.ref.exr" \
        --seeds "$first" "$seeds" ${ratio[@]+"${ratio[@]}"} --json "$d/bias.json"
done
