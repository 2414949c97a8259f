#!/usr/bin/env bash
# caustic's default estimator against Mitsuba 3 at equal time on the caustic Cornell box (issue
# #24's table): per round, Mitsuba `path` + `ldsampler` at SPP samples (2 threads; its
# mi.render time is T), then caustic's default with `--time T` (2 threads), each twice (seeds 1
# and 2, for scripts/mitsuba/z8.py's per-pixel variances), alternating, ROUNDS times. Prints each
# round's figures against ../shared/bench/mitsuba/cbox_caustic.ref.exr and the medians. Run it
# on a quiet machine: the times are wall-clock. Extra arguments go to caustic (e.g.
# `--integrator path` for the plain path tracer).
#
# Usage: scripts/mitsuba_equal_time.sh [ROUNDS] [SPP] [caustic flags...]
set -euo pipefail
cd "$(dirname "$0")/.."
rounds=${1:-3}
spp=${2:-256}
shift $(( $# > 2 ? 2 : $# ))
source scripts/caustic_bin.sh
M=../shared/bench/mitsuba
PY=${MITSUBA_PY:-/root/.cache/mitsuba3-venv/bin/python}
[ -x "$PY" ] || PY=$(bash "$M/setup.sh")
REF=$M/cbox_caustic.ref.exr
CB=benches/scenes/cbox_caustic.ron
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
echo "load before: $(cut -d' ' -f1-3 /proc/loadavg); $(nproc) CPUs: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2)"
for r in $(seq "$rounds"); do
  times=()
  for seed in 1 2; do
    line=$("$PY" "$M/render.py" --spp "$spp" --sampler ldsampler --threads 2 --seed "$seed" -o "$out/m$seed.exr")
    t=$(echo "$line" | grep -o 'render_s[= ]*[0-9.]*' | grep -o '[0-9.]*$')
    times+=("$t")
    "$caustic" render "$CB" --threads 2 --seed "$seed" --time "${t}s" -o "$out/c$seed.exr" "$@" 2>/dev/null \
      | sed -n 's/.*, \([0-9]*\) spp.*/\1/p' > "$out/spp$seed"
  done
  echo "round $r: mitsuba $spp spp in ${times[*]} s"
  echo "  mitsuba: $("$PY" scripts/mitsuba/z8.py "$out/m1.exr" "$out/m2.exr" "$REF")" | tee -a "$out/mitsuba.txt"
  echo "  caustic ($(cat "$out/spp1") / $(cat "$out/spp2") spp): $("$PY" scripts/mitsuba/z8.py "$out/c1.exr" "$out/c2.exr" "$REF")" | tee -a "$out/caustic.txt"
done
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
for who in mitsuba caustic; do
  for key in rmse relmse mean_ratio z8; do
    v=$(grep -o "$key=[0-9.]*" "$out/$who.txt" | cut -d= -f2 | sort -n | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}')
    printf '%s median %s %s\n' "$who" "$key" "$v"
  done
done
