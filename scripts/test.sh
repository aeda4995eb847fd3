#!/usr/bin/env bash
# Builds footfall and runs its whole test suite. Installs what it needs on Debian first.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh core test viewer blender
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$(nproc)"
cd build
ctest --output-on-failure -j"$(nproc)" --timeout 600
