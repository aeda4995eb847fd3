#!/usr/bin/env bash
# Installs footfall's Debian dependencies when they are missing.
# Usage: scripts/install-deps.sh [core|test|viewer|blender|all]...   (default: core)
set -euo pipefail

# python3 packs the Blender add-on's zip, which every build makes.
core=(cmake g++ make pkg-config cpp libtirpc-dev rpcsvc-proto nlohmann-json3-dev libcli11-dev
      libopenmesh-dev libtinygltf-dev libstb-dev python3)
test=(catch2 libbenchmark-dev libnanoflann-dev rpcbind nodejs npm clang-format git locales)
viewer=(libglfw3-dev libglm-dev libgl-dev libgl1-mesa-dri xvfb xauth)
blender=(blender python3 python3-numpy)

wanted=()
[ $# -eq 0 ] && set -- core
for group in "$@"; do
  case "$group" in
    core) wanted+=("${core[@]}") ;;
    test) wanted+=("${test[@]}") ;;
    viewer) wanted+=("${viewer[@]}") ;;
    blender) wanted+=("${blender[@]}") ;;
    all) wanted+=("${core[@]}" "${test[@]}" "${viewer[@]}" "${blender[@]}") ;;
    *) echo "install-deps: unknown group '$group' (core, test, viewer, blender, all)" >&2; exit 2 ;;
  esac
done

# Packages whose command may come from elsewhere (a newer Node.js ships its own npm).
provided_by_command() {
  case "$1" in
    nodejs) command -v node >/dev/null ;;
    npm) command -v npm >/dev/null ;;
    *) return 1 ;;
  esac
}

missing=()
for pkg in "${wanted[@]}"; do
  provided_by_command "$pkg" && continue
  dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "ok installed" || missing+=("$pkg")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "install-deps: installing ${missing[*]}"
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# The tests write and read files with the C and C++ locales set as a host program's may be: a
# decimal comma (German), a two-byte decimal point (Pashto), Turkish letter case. Those locales
# must be installed: generated when the test packages are wanted.
test_locales=(de_DE ps_AF tr_TR)
if [[ " ${wanted[*]} " == *" locales "* ]]; then
  generate=()
  for name in "${test_locales[@]}"; do
    locale -a 2>/dev/null | grep -qix "${name}\.utf-\?8" || generate+=("$name")
  done
  if [ ${#generate[@]} -gt 0 ]; then
    echo "install-deps: generating the ${generate[*]} UTF-8 locales"
    SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
    for name in "${generate[@]}"; do
      grep -qx "$name.UTF-8 UTF-8" /etc/locale.gen 2>/dev/null ||
        echo "$name.UTF-8 UTF-8" | $SUDO tee -a /etc/locale.gen >/dev/null
    done
    $SUDO locale-gen >/dev/null
  fi
fi
