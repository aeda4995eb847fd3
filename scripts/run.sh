#!/usr/bin/env bash
# The main job on bundled data, with the embedded engine (no server needed): builds footfall
# (installing its Debian dependencies when missing) and answers sample queries on a bundled
# terrain. Extra arguments go to `footfall query`.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh core
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DFOOTFALL_BUILD_TESTS=OFF \
  -DFOOTFALL_BUILD_BENCH=OFF -DFOOTFALL_BUILD_VIEWER=OFF >/dev/null
cmake --build build -j"$(nproc)" --target footfall >/dev/null
mkdir -p out
build/client/cli/footfall query --terrain data/terrain/hills.pts "$@" <<'QUERIES' | tee out/queries.jsonl
snap 10 5 10
normal 10 5 10
next 10 0 10 0 0 0.8
next 10 0 10 0.8 0 0
QUERIES
echo "answers written to out/queries.jsonl" >&2
