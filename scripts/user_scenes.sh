#!/usr/bin/env bash
# The user scenes of issue #43 (benches/scenes/user/*.ron: an outdoor pool under sun and sky, a
# glass of water under a spot light, a jewel under a small lamp, a room lit through a window),
# measured the way the issue asks. Two modes:
#
#   scripts/user_scenes.sh reference DIR [TIME]   long references (default 30m each): the
#       default estimator (path-ppm) and, as the cross-check, `--integrator ppm` for the same
#       time; prints their relMSE against each other and their mean ratio. DIR/<scene>.ref.exr
#       is the default's, DIR/<scene>.ppm.exr the cross-check.
#   scripts/user_scenes.sh equal DIR [TIME] [COUNTS]   at TIME each (default 20s): the default
#       as it chooses, then `--caustic-photons N` for each N of COUNTS (default
#       "20000 50000 100000 200000 500000"), scored against DIR/<scene>.ref.exr; prints relMSE,
#       spp and the summary's photon lines, and which count was best by hand.
#
# The times are wall-clock: run it on a quiet machine (2 threads). Everything is written to
# DIR; the summary lines go to DIR/<scene>.<run>.log.
set -euo pipefail
cd "$(dirname "$0")/.."
mode=${1:?usage: scripts/user_scenes.sh reference|equal DIR [TIME] [COUNTS]}
dir=${2:?usage: scripts/user_scenes.sh reference|equal DIR [TIME] [COUNTS]}
source scripts/caustic_bin.sh
mkdir -p "$dir"
scenes=(pool_noon glass_of_water jewel window_room)
relmse() { "$caustic" compare "$1" "$2" | sed -n 's/.*relMSE \([0-9.e+-]*\).*/\1/p' | head -1; }
echo "load before: $(cut -d' ' -f1-3 /proc/loadavg)"
case "$mode" in
  reference)
    time=${3:-30m}
    for s in "${scenes[@]}"; do
      "$caustic" render "benches/scenes/user/$s.ron" --threads 2 --time "$time" --seed 101 \
        -o "$dir/$s.ref.exr" >"$dir/$s.ref.log" 2>&1
      "$caustic" render "benches/scenes/user/$s.ron" --threads 2 --time "$time" --seed 102 \
        --integrator ppm -o "$dir/$s.ppm.exr" >"$dir/$s.ppm.log" 2>&1
      echo "$s: default vs ppm relMSE $(relmse "$dir/$s.ppm.exr" "$dir/$s.ref.exr"); $("$caustic" compare "$dir/$s.ppm.exr" "$dir/$s.ref.exr" | head -1)"
    done
    ;;
  equal)
    time=${3:-20s}
    read -ra counts <<<"${4:-20000 50000 100000 200000 500000}"
    for s in "${scenes[@]}"; do
      ref="$dir/$s.ref.exr"
      [ -f "$ref" ] || { echo "error: no $ref; run the reference mode first" >&2; exit 2; }
      "$caustic" render "benches/scenes/user/$s.ron" --threads 2 --time "$time" --seed 1 \
        -o "$dir/$s.default.exr" >"$dir/$s.default.log" 2>&1
      best=""
      best_rel=""
      line="$s: default $(relmse "$dir/$s.default.exr" "$ref") ($(grep -o '[0-9]* spp' "$dir/$s.default.log" | head -1))"
      for n in "${counts[@]}"; do
        "$caustic" render "benches/scenes/user/$s.ron" --threads 2 --time "$time" --seed 1 \
          --integrator path-ppm --caustic-photons "$n" -o "$dir/$s.$n.exr" >"$dir/$s.$n.log" 2>&1
        r=$(relmse "$dir/$s.$n.exr" "$ref")
        line="$line, $n: $r"
        if [ -z "$best_rel" ] || awk -v a="$r" -v b="$best_rel" 'BEGIN { exit !(a < b) }'; then
          best=$n
          best_rel=$r
        fi
      done
      echo "$line; best by hand: $best ($best_rel)"
    done
    ;;
  *)
    echo "error: the mode is \`reference\` or \`equal\`, found \`$mode\`" >&2
    exit 2
    ;;
esac
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
