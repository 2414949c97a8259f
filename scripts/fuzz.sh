#!/usr/bin/env bash
# Fuzz the scene loader, the OBJ loader and the texture image loader with cargo-fuzz (needs a
# nightly toolchain and `cargo install cargo-fuzz`). Seeds the corpora from scenes/,
# tests/bad_scenes/ and assets/, then runs the targets one after another on one core.
# Usage: scripts/fuzz.sh [seconds per target, default 300] [target ...]  (default: all three)
#
# scene_loader compiles scenes against the repository's scenes/ directory, so the demo scenes'
# `../assets/…` textures and meshes load; the bad-scene seeds have their `assets/…` paths
# rewritten to resolve from there too. Crashes land in fuzz/artifacts/<target>/, the corpora in
# fuzz/corpus/<target>/ and the logs in fuzz/logs/ (all ignored by git).
set -euo pipefail
cd "$(dirname "$0")/../fuzz"
secs=${1:-300}
if [ $# -gt 1 ]; then targets=("${@:2}"); else targets=(scene_loader obj_loader texture_loader); fi
mkdir -p corpus/scene_loader corpus/obj_loader corpus/texture_loader

# Scene seeds: a selector byte (0 = RON, 1 = TOML) and the file. Paths in tests/bad_scenes are
# relative to that directory; rewrite them to be relative to scenes/.
rebase() { sed -e 's|"\.\./\.\./assets/|"../assets/|g' -e 's|"assets/|"../tests/bad_scenes/assets/|g' "$1"; }
i=0
for f in ../scenes/*.ron; do i=$((i+1)); { printf '\x00'; cat "$f"; } > "corpus/scene_loader/seed_ron_$i"; done
for f in ../tests/bad_scenes/*.ron; do i=$((i+1)); { printf '\x00'; rebase "$f"; } > "corpus/scene_loader/seed_ron_$i"; done
for f in ../scenes/*.toml; do i=$((i+1)); { printf '\x01'; cat "$f"; } > "corpus/scene_loader/seed_toml_$i"; done
for f in ../tests/bad_scenes/*.toml; do i=$((i+1)); { printf '\x01'; rebase "$f"; } > "corpus/scene_loader/seed_toml_$i"; done

cp ../assets/*.obj ../tests/bad_scenes/assets/*.obj corpus/obj_loader/

# Texture seeds: the image files as they are, plus tiny JPEG and EXR files kept in fuzz/seeds/
# (the loader reads those formats too).
cp ../assets/*.png ../tests/bad_scenes/assets/*.png seeds/texture_loader/* corpus/texture_loader/

# One libFuzzer process per target, in turn (cargo fuzz's default of one job; libFuzzer's own
# -jobs/-workers would only move the same single process's output into fuzz-0.log). A unit
# slower than 30 s counts as a hang. Full logs go to fuzz/logs/<target>.log.
mkdir -p logs
status=0
for target in "${targets[@]}"; do
  echo "== $target: ${secs}s"
  cargo +nightly fuzz run --jobs 1 "$target" -- \
    -max_total_time="$secs" -rss_limit_mb=4096 -timeout=30 > "logs/$target.log" 2>&1 || status=1
  grep -E '^#[0-9]+[[:space:]]+DONE|Slowest unit|^Done [0-9]+ runs|ERROR|panicked|SUMMARY|Test unit written' "logs/$target.log" || true
  echo "corpus: $(ls "corpus/$target" | wc -l) files; artifacts: $(ls "artifacts/$target" 2>/dev/null | wc -l)"
done
exit $status
