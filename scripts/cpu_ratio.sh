#!/usr/bin/env bash
# CPU time (user + sys) of two caustic binaries on the same command, alternated A B A B … so
# that both see the same machine state, and the ratio of their medians (B / A). For "the render
# speed is unchanged" checks between commits: build each commit's binary, then
#   scripts/cpu_ratio.sh OLD_BIN NEW_BIN ROUNDS render benches/scenes/cbox_caustic.ron --integrator path --spp 64
# (the output path is added: `-o` a temporary file). Run it on a quiet machine; CPU time is the
# robust figure when other jobs share it, wall time is not.
set -euo pipefail
a=$1 b=$2 rounds=$3
shift 3
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
cpu() { # prints user+sys seconds of one run
  local t0 t1
  /usr/bin/env time -f '%U %S' -o "$out/t" "$@" -o "$out/img.exr" --quiet > /dev/null
  awk '{printf "%.3f\n", $1 + $2}' "$out/t"
}
: > "$out/a"; : > "$out/b"
for i in $(seq "$rounds"); do
  cpu "$a" "$@" >> "$out/a"
  cpu "$b" "$@" >> "$out/b"
done
med() { sort -n "$1" | awk '{v[NR]=$1} END {print (NR % 2) ? v[(NR+1)/2] : (v[NR/2] + v[NR/2+1]) / 2}'; }
ma=$(med "$out/a"); mb=$(med "$out/b")
echo "A $a: $(tr '\n' ' ' < "$out/a")→ median $ma s"
echo "B $b: $(tr '\n' ' ' < "$out/b")→ median $mb s"
awk -v a="$ma" -v b="$mb" 'BEGIN {printf "B/A CPU time: %.4f\n", b / a}'
