#!/usr/bin/env bash
# Times the README's two commands as a new user runs them: from a clean CARGO_TARGET_DIR, first
# the render command, then the test command (issue 17 §1). The commands are read from the
# README's "The two commands" section, so this measures whatever the README says today.
#
# Usage: scripts/first_build.sh [repository, default: this one]
#   FIRST_BUILD_TARGET=dir   target directory to use (must not exist yet; default: a new
#                            temporary directory, removed at the end)
#
# Crates are fetched first (`cargo fetch --locked`, not timed): download time depends on the
# network, not on the project. Prints wall time and user+sys CPU time of each command. On a
# machine shared with other jobs, wall time is noisy; CPU time is the robust figure.
set -euo pipefail
repo=$(cd "${1:-$(dirname "$0")/..}" && pwd)
cd "$repo"

# The ```sh blocks of the section "## The two commands", one command each, in order.
mapfile -t cmds < <(awk '
  /^## / { in_sec = ($0 == "## The two commands") }
  in_sec && /^```sh/ { in_block = 1; next }
  in_block && /^```/ { in_block = 0; next }
  in_sec && in_block && NF { print }' README.md)
if [ "${#cmds[@]}" -ne 2 ]; then
  echo "error: expected 2 commands in README.md's \"The two commands\" section, found ${#cmds[@]}" >&2
  exit 2
fi

if [ -n "${FIRST_BUILD_TARGET:-}" ]; then
  if [ -e "$FIRST_BUILD_TARGET" ]; then
    echo "error: FIRST_BUILD_TARGET \`$FIRST_BUILD_TARGET\` exists; the build must start clean" >&2
    exit 2
  fi
  target=$FIRST_BUILD_TARGET
else
  target=$(mktemp -d "${TMPDIR:-/tmp}/first_build.XXXXXX")
  trap 'rm -rf "$target"' EXIT
  rmdir "$target"
fi
export CARGO_TARGET_DIR=$target
log=$(mktemp "${TMPDIR:-/tmp}/first_build_log.XXXXXX")

cargo fetch --locked --quiet
echo "repository: $repo ($(git -C "$repo" rev-parse --short HEAD 2>/dev/null || echo 'not git'))"
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs); load average at start: $(cut -d' ' -f1-3 /proc/loadavg)"
echo "$(cargo --version); CARGO_TARGET_DIR=$target (clean)"

total_wall=0
total_cpu=0
for cmd in "${cmds[@]}"; do
  echo "== $cmd"
  # The command line exactly as written in the README, run through bash.
  /usr/bin/time -f '%e %U %S' -o "$log.time" bash -c "$cmd" >"$log" 2>&1 || {
    tail -n 30 "$log"
    echo "error: \`$cmd\` failed (full log: $log)" >&2
    exit 1
  }
  read -r wall user sys <"$log.time"
  cpu=$(awk -v u="$user" -v s="$sys" 'BEGIN { printf "%.0f", u + s }')
  printf '   wall %4.0f s (%s), CPU user+sys %5s s\n' "$wall" \
    "$(awk -v w="$wall" 'BEGIN { printf "%d min %02d s", w / 60, w % 60 }')" "$cpu"
  awk '/^test result:/ {p += $4; f += $6; i += $8; n++}
       END { if (n) printf "   tests: %d passed, %d failed, %d ignored\n", p, f, i }' "$log"
  total_wall=$(awk -v a="$total_wall" -v b="$wall" 'BEGIN { print a + b }')
  total_cpu=$(awk -v a="$total_cpu" -v b="$cpu" 'BEGIN { print a + b }')
done
printf '== both: wall %.0f s, CPU user+sys %.0f s; load average at end: %s\n' \
  "$total_wall" "$total_cpu" "$(cut -d' ' -f1-3 /proc/loadavg)"
rm -f "$log" "$log.time"
