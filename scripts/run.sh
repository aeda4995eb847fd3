#!/usr/bin/env bash
# The main job on bundled data, with the embedded engine (no server needed): builds footfall
# (installing its Debian dependencies when missing) and generates a biped's walk across the
# bundled hills, written as JSON (the interchange), glTF and a Maya MEL script under out/.
# Extra arguments go to `footfall generate` (e.g. --steps 40, --path "10,0,10 30,0,30"); a flag
# given there replaces this script's own (--terrain, --character, --start, --path or --heading,
# and --out: then only the files asked for are written).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh core
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DFOOTFALL_BUILD_TESTS=OFF \
  -DFOOTFALL_BUILD_BENCH=OFF -DFOOTFALL_BUILD_VIEWER=OFF >/dev/null
cmake --build build -j"$(nproc)" --target footfall >/dev/null
mkdir -p out
given() {  # given FLAG...: true when an extra argument is one of the flags (or FLAG=VALUE)
  local arg flag
  for arg in "${extra[@]}"; do
    for flag in "$@"; do [[ $arg == "$flag" || $arg == "$flag="* ]] && return 0; done
  done
  return 1
}
extra=("$@")
args=()
given --terrain --server-terrain || args+=(--terrain data/terrain/hills.pts)
given --character || args+=(--character data/characters/biped.json)
given --start || args+=(--start 8,0,8)
given --path --heading || args+=(--path "8,0,30 30,0,30")
own_out=true
given --out && own_out=false
$own_out && args+=(--out out/walk.json --out out/walk.gltf --out out/walk.mel)
build/client/cli/footfall generate "${args[@]}" "$@"
$own_out && echo "walk written to out/walk.json (also out/walk.gltf, out/walk.mel)" >&2
exit 0
