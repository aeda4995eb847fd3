#!/usr/bin/env bash
# Every program and plugin names the same release: the project() version of CMakeLists.txt.
# A script or a pipeline checking which footfall it runs reads `PROGRAM --version`.
# Usage: version_test.sh SOURCE_DIR PROGRAM...   (footfall, footfalld, footfall-view)
set -u
source_dir=$1; shift
source "$(dirname "$0")/../support/cli_checks.sh"
version=$(sed -nE 's/^project\(footfall VERSION ([0-9]+\.[0-9]+\.[0-9]+).*/\1/p' "$source_dir/CMakeLists.txt")
check "CMakeLists.txt names a version" grep -qxE '[0-9]+\.[0-9]+\.[0-9]+' <<< "$version"
for program in "$@"; do
  name=$(basename "$program")
  # No display needed: footfall-view answers --version before it opens a window.
  out=$(env -u DISPLAY -u WAYLAND_DISPLAY "$program" --version 2> "$work/err.txt")
  check "$name --version: exit 0" [ $? -eq 0 ]
  check "$name --version: \"$name $version\" (got \"$out\")" [ "$out" = "$name $version" ]
  check "$name --version: nothing on stderr" [ ! -s "$work/err.txt" ]
done
# The Blender add-on's bl_info carries the same numbers (Blender shows them in Preferences).
blender_version=$(sed -nE 's/^ *"version": \(([0-9]+), ([0-9]+), ([0-9]+)\),.*/\1.\2.\3/p' \
  "$source_dir/plugins/blender/footfall_blender/__init__.py")
check "Blender add-on version $blender_version is $version" [ "$blender_version" = "$version" ]
finish
