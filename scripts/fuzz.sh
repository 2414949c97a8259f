#!/usr/bin/env bash
# Fuzz the scene loader and the OBJ loader with cargo-fuzz (needs a nightly toolchain and
# `cargo install cargo-fuzz`). Seeds the corpora from scenes/, tests/bad_scenes/ and assets/.
# Usage: scripts/fuzz.sh [seconds per target, default 300]
set -euo pipefail
cd "$(dirname "$0")/../fuzz"
secs=${1:-300}
mkdir -p corpus/scene_loader corpus/obj_loader
i=0
for f in ../scenes/*.ron ../tests/bad_scenes/*.ron; do i=$((i+1)); { printf '\x00'; cat "$f"; } > "corpus/scene_loader/seed_ron_$i"; done
for f in ../scenes/*.toml ../tests/bad_scenes/*.toml; do i=$((i+1)); { printf '\x01'; cat "$f"; } > "corpus/scene_loader/seed_toml_$i"; done
cp ../assets/*.obj ../tests/bad_scenes/assets/*.obj corpus/obj_loader/
for target in scene_loader obj_loader; do
  cargo +nightly fuzz run "$target" -- -max_total_time="$secs" -rss_limit_mb=4096 2>&1 | tail -n 12
done
