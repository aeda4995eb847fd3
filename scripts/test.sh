#!/usr/bin/env bash
# Builds footfall and runs its whole test suite. Installs what it needs on Debian first.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh core test viewer blender
# The Khronos glTF validator for the export tests, in a local npm prefix (nothing global).
# All gltf-validator 2.x releases on npm are pre-releases, so the version is pinned exactly.
if [ ! -f build/node/node_modules/gltf-validator/package.json ]; then
  npm install --prefix build/node --no-audit --no-fund --loglevel=error \
    gltf-validator@2.0.0-dev.3.10 >/dev/null
fi
# The options explicitly: scripts/run.sh configures the same build directory without tests.
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DFOOTFALL_BUILD_TESTS=ON \
  -DFOOTFALL_BUILD_BENCH=ON -DFOOTFALL_BUILD_VIEWER=ON >/dev/null
cmake --build build -j"$(nproc)"
cd build
ctest --output-on-failure -j"$(nproc)" --timeout 600 --no-tests=error
