#!/usr/bin/env bash
# Renders the images under docs/images/ (shown in README.md and docs/) from the table in
# docs/images/manifest.txt: one `caustic render` per line. A line with `--layers` also writes its
# layer pictures beside the image (`bath.png` → `bath.direct.png`, …), from the same render.
# Regenerate them all after a change to the renderer; `tests/it/doc_images.rs` fails until they
# match it again. (Images made by scripts of their own, such as scripts/bath_hq.sh, are not
# rendered here.)
# Usage: scripts/doc_images.sh [file ...]   (default: every image in the manifest; a layer
# picture's name renders its line)
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/caustic_bin.sh
manifest=docs/images/manifest.txt
found=0
while read -r file args; do
  case "$file" in '' | '#'*) continue ;; esac
  read -ra argv <<<"$args"
  # The files this line makes: the image, and `<stem>.<layer>.<ext>` per layer of `--layers`.
  files=("$file")
  for ((i = 0; i + 1 < ${#argv[@]}; i++)); do
    if [ "${argv[i]}" = --layers ]; then
      IFS=, read -ra layers <<<"${argv[i + 1]}"
      for layer in "${layers[@]}"; do files+=("${file%.*}.$layer.${file##*.}"); done
    fi
  done
  if [ $# -gt 0 ]; then
    named=0
    for f in "${files[@]}"; do
      if printf '%s\n' "$@" | grep -qxF "$f"; then named=$((named + 1)); fi
    done
    [ "$named" -gt 0 ] || continue
    found=$((found + named))
  fi
  echo "caustic render ${argv[*]} -o docs/images/$file"
  "$caustic" render "${argv[@]}" -o "docs/images/$file" --quiet --no-denoise
  if [ "${#files[@]}" -gt 1 ]; then echo "  and its layers: ${files[*]:1}"; fi
done <"$manifest"
if [ $# -gt 0 ] && [ "$found" -ne $# ]; then
  echo "error: $(( $# - found )) of the images named are not in $manifest" >&2
  exit 2
fi
