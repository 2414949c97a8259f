#!/usr/bin/env bash
# Render-time cost of each texture kind (issue #3): renders scenes/noise.ron,
# scenes/texture_map.ron, scenes/bump_map.ron and scenes/water.ron with their textures, and
# with textures swapped for constant colours or bumps removed (via --set), interleaving the
# variants round-robin so machine load affects all alike, and prints the median render time of
# each and its ratio to the scene's untextured baseline.
# Usage: scripts/texture_cost.sh [runs] [extra caustic flags; default --spp 16]
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-7}
shift $(( $# > 0 ? 1 : 0 ))
if [ $# -eq 0 ]; then set -- --spp 16; fi
source scripts/caustic_bin.sh
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

grey='[0.6,0.6,0.6]'
# name | scene | --set overrides (space separated)
variants=(
  "noise: no textures|scenes/noise.ron|materials.marble_block.color=$grey materials.marble_ball.color=$grey materials.bumpy.bump=null materials.cloudy.color=$grey materials.floor.color=$grey materials.floor.bump=null materials.wall.color=$grey"
  "noise: marble colour only|scenes/noise.ron|materials.bumpy.bump=null materials.cloudy.color=$grey materials.floor.color=$grey materials.floor.bump=null"
  "noise: fBm + turbulence colour only|scenes/noise.ron|materials.marble_block.color=$grey materials.marble_ball.color=$grey materials.bumpy.bump=null materials.floor.bump=null materials.wall.color=$grey"
  "noise: noise bump only|scenes/noise.ron|materials.marble_block.color=$grey materials.marble_ball.color=$grey materials.cloudy.color=$grey materials.floor.color=$grey materials.wall.color=$grey"
  "noise: everything|scenes/noise.ron|"
  "texture_map: no textures|scenes/texture_map.ron|materials.floor.color=$grey materials.tiled.color=$grey materials.tiled_ball.color=$grey"
  "texture_map: bitmaps, bilinear|scenes/texture_map.ron|render.texture_filter=\"Bilinear\""
  "texture_map: bitmaps, trilinear|scenes/texture_map.ron|render.texture_filter=\"Trilinear\""
  "texture_map: bitmaps, anisotropic|scenes/texture_map.ron|"
  "bump_map: no bumps|scenes/bump_map.ron|materials.wall.bump=null materials.ball.bump=null materials.cube.bump=null materials.hammered_mirror.bump=null"
  "bump_map: height-map bumps only|scenes/bump_map.ron|materials.hammered_mirror.bump=null"
  "bump_map: everything|scenes/bump_map.ron|"
  "water: no ripples|scenes/water.ron|materials.water.bump=null"
  "water: ripples|scenes/water.ron|"
)

for i in $(seq "$runs"); do
  for k in "${!variants[@]}"; do
    IFS='|' read -r name scene sets <<<"${variants[$k]}"
    args=()
    for s in $sets; do args+=(--set "$s"); done
    "$caustic" render "$scene" -o "$out/img.png" --quiet "${args[@]}" "$@" 2>&1 \
      | grep -o 'in [0-9.]* s' | awk -v k="$k" '{print k, $2}' >>"$out/times"
  done
done

echo "median render time over $runs runs (machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs))"
for k in "${!variants[@]}"; do
  IFS='|' read -r name scene sets <<<"${variants[$k]}"
  awk -v k="$k" '$1 == k {print $2}' "$out/times" | sort -n \
    | awk -v name="$name" '{a[NR]=$1} END {printf "%-40s %7.3f s\n", name, a[int((NR+1)/2)]}'
done | awk '
  { n = $0; sub(/ +[0-9.]+ s$/, "", n); t = $(NF-1)
    split(n, p, ":"); if (p[2] ~ /^ no /) base[p[1]] = t
    printf "%s  (%.2fx)\n", $0, (p[1] in base) ? t / base[p[1]] : 1 }'
