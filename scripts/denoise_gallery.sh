#!/usr/bin/env bash
# The denoiser's pictures in docs/gallery.md (issue 46): for the caustic Cornell box (256×256)
# and the bath (200×150), the noisy default render, caustic's `--denoise` of it, Intel Open Image
# Denoise's on the same inputs and the reference, whole and as 4× enlarged crops around the
# caustic's hot spot. Runs scripts/denoise_bench.sh (the box, 16 spp) and
# scripts/denoise_scenes.sh (the bath, 8 spp; its reference is `--integrator ppm` at 1284 passes
# unless REF_DIR holds bath.ref.exr), then copies their pictures into docs/images.
#
#   scripts/denoise_gallery.sh [BIN] [OUT]     (OUT default target/denoise-gallery)
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(dirname "$here")"
bin="${1:-$root/target/release/caustic}"
out="${2:-$root/target/denoise-gallery}"
mkdir -p "$out"
out="$(cd "$out" && pwd)"
"$here/denoise_bench.sh" "$bin" "$out/cbox"
SCENES=bath "$here/denoise_scenes.sh" "$bin" "$out/scenes"
c="$out/cbox" b="$out/scenes"
cd "$root"
cp "$c/noisy.png" "docs/images/denoise_cbox_noisy.png"
cp "$c/denoised.png" "docs/images/denoise_cbox_denoised.png"
cp "$c/oidn.png" "docs/images/denoise_cbox_oidn.png"
cp "$c/reference.png" "docs/images/denoise_cbox_reference.png"
cp "$c/crop_noisy.png" "docs/images/denoise_cbox_crop_noisy.png"
cp "$c/crop_denoised.png" "docs/images/denoise_cbox_crop_denoised.png"
cp "$c/crop_oidn.png" "docs/images/denoise_cbox_crop_oidn.png"
cp "$c/crop_reference.png" "docs/images/denoise_cbox_crop_reference.png"
cp "$b/bath.noisy.png" "docs/images/denoise_bath_noisy.png"
cp "$b/bath.denoised.png" "docs/images/denoise_bath_denoised.png"
cp "$b/bath.oidn.png" "docs/images/denoise_bath_oidn.png"
cp "$b/bath.reference.png" "docs/images/denoise_bath_reference.png"
cp "$b/bath.crop.noisy.png" "docs/images/denoise_bath_crop_noisy.png"
cp "$b/bath.crop.denoised.png" "docs/images/denoise_bath_crop_denoised.png"
cp "$b/bath.crop.oidn.png" "docs/images/denoise_bath_crop_oidn.png"
cp "$b/bath.crop.reference.png" "docs/images/denoise_bath_crop_reference.png"
