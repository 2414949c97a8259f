#!/usr/bin/env bash
# Rebuilds the glTF test room with Blender (Debian: `apt-get install -y blender python3-numpy`, 3.4; the exporter needs numpy) and writes
# tests/data/gltf/room.glb and room.gltf. CI has no Blender: the files it writes are committed.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
out="${1:-$here/../../tests/data/gltf}"
blender -b --factory-startup --python "$here/make_gltf_assets.py" -- "$out"
