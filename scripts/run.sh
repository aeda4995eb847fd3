#!/usr/bin/env bash
# The main job on bundled data, with the embedded engine (no server needed): builds footfall
# (installing its Debian dependencies when missing) and generates a biped's walk across the
# bundled hills, written as JSON (the interchange), glTF and a Maya MEL script under out/.
# Extra arguments go to `footfall generate` (e.g. --steps 40, --path "10,0,10 30,0,30"); a flag
# given there replaces this script's own (scripts/main-job-args.sh: --terrain, and with it the
# hills' start and path; --character, --start, --path or --heading; --out: then only the files
# asked for are written).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh core
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DFOOTFALL_BUILD_TESTS=OFF \
  -DFOOTFALL_BUILD_BENCH=OFF -DFOOTFALL_BUILD_VIEWER=OFF >/dev/null
cmake --build build -j"$(nproc)" --target footfall >/dev/null
mkdir -p out
source scripts/main-job-args.sh
main_job_arguments "$@"
build/client/cli/footfall generate "${main_job_args[@]}"
if $main_job_own_out; then
  echo "walk written to out/walk.json (also out/walk.gltf, out/walk.mel)" >&2
fi
exit 0
