#!/usr/bin/env bash
# Renders the images under docs/images/ (shown in README.md and docs/) from the table in
# docs/images/manifest.txt: one `caustic render` per line. Regenerate them all after a change to
# the renderer; `tests/it/doc_images.rs` fails until they match it again.
# Usage: scripts/doc_images.sh [file ...]   (default: every image in the manifest)
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/caustic_bin.sh
manifest=docs/images/manifest.txt
found=0
while read -r file args; do
  case "$file" in '' | '#'*) continue ;; esac
  if [ $# -gt 0 ] && ! printf '%s\n' "$@" | grep -qxF "$file"; then continue; fi
  found=$((found + 1))
  read -ra argv <<<"$args"
  echo "caustic render ${argv[*]} -o docs/images/$file"
  "$caustic" render "${argv[@]}" -o "docs/images/$file" --quiet
done <"$manifest"
if [ $# -gt 0 ] && [ "$found" -ne $# ]; then
  echo "error: $(( $# - found )) of the images named are not in $manifest" >&2
  exit 2
fi
