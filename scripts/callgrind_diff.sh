#!/usr/bin/env bash
# Instruction counts (valgrind's callgrind) of two caustic binaries on the same command, and the
# functions whose own counts changed most. Counts do not depend on machine load, so this finds
# where a CPU-time regression comes from while other jobs share the machine (the figure of
# record stays CPU time on a quiet machine: scripts/cpu_ratio.sh). Keep the render small and on
# one thread (valgrind runs it ~50x slower), e.g.
#   scripts/callgrind_diff.sh OLD_BIN NEW_BIN render benches/scenes/cbox_caustic.ron \
#       --integrator path --spp 16 --width 128 --height 128 --threads 1
# (the output path is added). Needs valgrind (apt install valgrind). Function names need no debug
# info; for per-line counts build with `cargo build --profile profiling` (line tables) and pass
# target/profiling/caustic.
set -euo pipefail
a=$1 b=$2
shift 2
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
valgrind --tool=callgrind --callgrind-out-file="$out/a.cg" "$a" "$@" -o "$out/a.exr" --quiet \
    > "$out/a.log" 2>&1 &
valgrind --tool=callgrind --callgrind-out-file="$out/b.cg" "$b" "$@" -o "$out/b.exr" --quiet \
    > "$out/b.log" 2>&1
wait
cmp -s "$out/a.exr" "$out/b.exr" && echo "same EXR bytes" || echo "EXR bytes differ"
python3 "$(dirname "$0")/callgrind_symbols.py" "$out/a.cg" "$out/b.cg" "${TOP:-25}"
