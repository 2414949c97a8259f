#!/usr/bin/env bash
# The pool scene's reference (issue #24): two different estimators rendered long, and the
# residual between them. Renders are not timed, so this may run on a loaded machine.
#
#   scripts/pool_reference.sh [OUT_DIR]          (default ../pool_ref, kept out of git)
#
# 1. `path-ppm` with 100 000 caustic photons per pass (k = 20, no global map; the default
#    estimator traces 23 000 per pass at 320×240), seed 777, 8192 passes, as four shards of
#    2048 passes (`--shard i/4`, 1 thread each, two at a time) merged into OUT/pool_ref.exr:
#    THE REFERENCE. OUT/pool_ref_h1.exr and _h2.exr are its two halves (shards 1+2, 3+4), for
#    its own noise.
# 2. `path` (unbiased, no photon map: every caustic found by chance), seed 901, 16 384 spp, four
#    shards of 4096, merged into OUT/pool_path.exr (halves OUT/pool_path_h1.exr, _h2.exr): the
#    independent cross-check.
# 3. Prints each image's sha256 and the residual between the two estimators: `caustic
#    compare`'s RMSE / relMSE / bias, the image-mean ratio, the reference's own noise (RMSE of
#    the mean of its halves: √(mean (h1 − h2)² / 4)), and z8 of the path render against the
#    reference with BOTH estimators' per-pixel variances from their halves
#    (scripts/mitsuba/z8.py --ref2), 8×8 and 32×32 blocks.
# Shards already present are kept (the script can be stopped and restarted). Cost: 3.7·10⁹ rays
# (path-ppm) + 6.0·10⁹ (path), about an hour of one core for each estimator (made on a loaded
# machine, so not a timing). Renders of the same commit, seed and flags are the same bytes on any
# machine and thread count; the sha256s in docs/convergence.md are of caustic 80ce43c. The first
# half of the reference (shards 1 + 2) is byte for byte the 4096-pass render `--spp 4096`.
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${1:-../pool_ref}
source scripts/caustic_bin.sh
M=../shared/bench/mitsuba
PY=${MITSUBA_PY:-/root/.cache/mitsuba3-venv/bin/python}
[ -x "$PY" ] || PY=$(bash "$M/setup.sh")
SCENE=benches/scenes/pool.ron
mkdir -p "$OUT"
REF_FLAGS=(--integrator path-ppm --set photons.caustic=100000 --set photons.caustic_gather=20
  --set photons.global=0 --spp 8192 --seed 777)
PATH_FLAGS=(--integrator path --spp 16384 --seed 901)
echo "caustic $(git rev-parse --short HEAD), scene sha256 $(sha256sum "$SCENE" | cut -c1-16)…"
echo "reference: caustic render $SCENE ${REF_FLAGS[*]} --threads 1 --shard i/4 -o OUT/ref_i.part"
echo "cross-check: caustic render $SCENE ${PATH_FLAGS[*]} --threads 1 --shard i/4 -o OUT/path_i.part"

shard() { # name i flags...
  local name=$1 i=$2
  shift 2
  local f="$OUT/${name}_$i.part"
  if [ -s "$f" ]; then return 0; fi
  local t0 t1
  t0=$(date +%s)
  nice -n 10 "$caustic" render "$SCENE" "$@" --threads 1 --quiet --shard "$i/4" -o "$f" | tail -1
  t1=$(date +%s)
  echo "  $name shard $i/4: $((t1 - t0)) s wall (load $(cut -d' ' -f1 /proc/loadavg))"
}
# Two workers, one per estimator, each through its four shards.
(for i in 1 2 3 4; do shard ref "$i" "${REF_FLAGS[@]}"; done) &
w1=$!
(for i in 1 2 3 4; do shard path "$i" "${PATH_FLAGS[@]}"; done) &
w2=$!
wait "$w1"
wait "$w2"

for name in ref path; do
  dst=pool_$name
  [ "$name" = ref ] && dst=pool_ref
  "$caustic" merge "$OUT/${name}"_{1,2,3,4}.part -o "$OUT/$dst.exr" | tail -1
  "$caustic" merge --partial "$OUT/${name}"_{1,2}.part -o "$OUT/${dst}_h1.exr" | tail -1
  "$caustic" merge --partial "$OUT/${name}"_{3,4}.part -o "$OUT/${dst}_h2.exr" | tail -1
done
(cd "$OUT" && sha256sum pool_ref.exr pool_ref_h1.exr pool_ref_h2.exr pool_path.exr)

echo "residual, path (16384 spp) against the reference (path-ppm, 8192 passes):"
"$caustic" compare "$OUT/pool_path.exr" "$OUT/pool_ref.exr" | sed -n 1p
for b in 8 32; do
  echo "  ${b}x${b} blocks: $("$PY" scripts/mitsuba/z8.py "$OUT/pool_path_h1.exr" "$OUT/pool_path_h2.exr" \
    "$OUT/pool_ref_h1.exr" --ref2 "$OUT/pool_ref_h2.exr" --light 1000 --block "$b")"
done
echo "the reference's own noise (its halves against each other):"
"$PY" scripts/mitsuba/z8.py "$OUT/pool_ref_h1.exr" "$OUT/pool_ref_h2.exr" "$OUT/pool_ref.exr" --light 1000 --noise
# The reference's own bias (progressive photon mapping blurs by the radius, which shrinks as
# r_i² ∝ i^(−1/3) for α = 2/3): with bias b_i ∝ r_i², the mean over passes [0, N) has bias
# ≈ 1.5·c·N^(−1/3); the halves (passes [0, N/2) and [N/2, N)) then differ by ≈ 0.52·B(N), so the whole
# render's bias is B(N) ≈ 1.92 × (h1 − h2) in expectation. Printed per 8×8 block (where the
# halves' noise is small): the RMS of (h1 − h2), its noise part (from the pixel noise of the
# halves, which here includes the drift, so an upper bound), and the bias's range: 1.92× the
# systematic rest (a lower bound) to 1.92× the whole RMS (an upper bound).
echo "the reference's bias, estimated from the drift between its halves (8×8 block means):"
"$PY" - "$OUT/pool_ref_h1.exr" "$OUT/pool_ref_h2.exr" <<'PYEOF'
import sys
import mitsuba as mi
import numpy as np
mi.set_variant("scalar_rgb")
h1, h2 = (np.array(mi.Bitmap(p).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, False))
          .astype(np.float64)[..., :3] for p in sys.argv[1:3])
b = 8
H, W = (h1.shape[0] // b) * b, (h1.shape[1] // b) * b
blocks = lambda x: x[:H, :W].reshape(H // b, b, W // b, b, 3).mean(axis=(1, 3))
d = h1 - h2
rms = np.sqrt((blocks(d) ** 2).mean())
# Noise of a block mean of d: sum of its pixels' d^2 / 64^2 (d's pixel variance <= d^2).
noise = np.sqrt((blocks(d**2) / (b * b)).mean())
sys_part = np.sqrt(max(rms**2 - noise**2, 0.0))
mean = ((h1 + h2) / 2).mean()
lo, hi = 1.92 * sys_part, 1.92 * rms
print(f"  rms(h1 - h2) = {rms:.5f}, its noise <= {noise:.5f}, systematic >= {sys_part:.5f}; "
      f"estimated bias of the reference per 8x8 block: {lo:.5f} to {hi:.5f} RMS "
      f"({lo / mean * 100:.2f} to {hi / mean * 100:.2f} % of the image mean {mean:.5f})")
PYEOF
