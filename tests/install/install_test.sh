#!/usr/bin/env bash
# `cmake --install` into a scratch prefix, then what a user does with the installed tree: run the
# installed programs on the installed data, build a program of their own against the installed
# C++ libraries (find_package) and C ABI (pkg-config), and use the installed Python package with
# nothing in the environment pointing at it (it finds the installed libfootfall.so and footfalld).
# The tree is then moved, and must still work where it lands.
# Usage: install_test.sh BUILD_DIR SOURCE_DIR
set -u
build=$1
source_dir=$2
source "$source_dir/tests/support/cli_checks.sh"
prefix=$work/prefix

cmake --install "$build" --prefix "$prefix" > "$work/install.log" 2>&1
check "cmake --install succeeds" [ $? -eq 0 ]
for program in footfall footfalld; do
  check "$program installed and executable" [ -x "$prefix/bin/$program" ]
done
check "libfootfall.so installed, with its SONAME's name" \
  [ -f "$prefix/lib/libfootfall.so" ] && [ -f "$prefix/lib/libfootfall.so.1" ]
check "the C ABI header installed" [ -f "$prefix/include/footfall/client/footfall_c.h" ]
check "the C++ headers installed" [ -f "$prefix/include/footfall/steps/generator.h" ]
check "no header of the protocol's stubs installed" [ ! -e "$prefix/include/footfall.h" ]
check "the Blender add-on installed" [ -s "$prefix/share/footfall/footfall_blender.zip" ]
data=$prefix/share/footfall/data
check "the sample data installed" [ -f "$data/terrain/hills.pts" ] && [ -f "$data/characters/biped.json" ]

# The installed command on the installed data, out of the build tree.
(cd "$work" && "$prefix/bin/footfall" generate --terrain "$data/terrain/hills.pts" \
  --character "$data/characters/biped.json" --steps 6 --out "$work/cli.json") 2> "$work/cli.err"
check "installed footfall generate runs" [ $? -eq 0 ]
check "installed footfall generate writes its walk" [ -s "$work/cli.json" ]

# A program of one's own: the C++ libraries and the C ABI, found in the prefix.
cmake -S "$source_dir/tests/install/consumer" -B "$work/consumer" -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$prefix" > "$work/consumer.log" 2>&1
check "a project configures with find_package(footfall) and pkg-config footfall" [ $? -eq 0 ]
cmake --build "$work/consumer" -j2 >> "$work/consumer.log" 2>&1
check "it builds against the installed libraries" [ $? -eq 0 ]
[ "$failures" -eq 0 ] || cat "$work/consumer.log" >&2

# Optional use: components by target name, an unknown one not found; libtirpc missing (no
# pkg-config file for it) is footfall not found, and the project configures on.
optional() {  # optional BUILD_NAME COMPONENTS [ENV...]: prints "footfall found: ..."
  local name=$1 components=$2; shift 2
  env "$@" cmake -S "$source_dir/tests/install/optional" -B "$work/$name" \
    -DCMAKE_PREFIX_PATH="$prefix" "-DFOOTFALL_COMPONENTS=$components" 2>&1 |
    sed -n 's/^-- footfall found: //p'
}
check "find_package(footfall COMPONENTS c steps export): found" \
  [ "$(optional opt1 "c;steps;export")" = "1" ]
check "find_package(footfall COMPONENTS nosuch): not found, configured" \
  [ "$(optional opt2 "nosuch")" = "0" ]
mkdir -p "$work/no_pc"
check "without libtirpc's pkg-config file: not found, configured" \
  [ "$(optional opt3 "" PKG_CONFIG_LIBDIR="$work/no_pc")" = "0" ]

printf '{"character_file": "%s", "steps": 6}\n' "$data/characters/biped.json" > "$work/request.json"
"$work/consumer/walk_consumer" "$data/terrain/hills.pts" "$work/request.json" > "$work/lib.json"
check "the C++ program generates a walk" [ $? -eq 0 ]
check "its walk is footfall generate's, byte for byte" cmp -s "$work/lib.json" "$work/cli.json"

# The C program's snap, against footfall query's answer for the same point.
point="3.3 9 -2.7"
c_answer=$(LD_LIBRARY_PATH="$prefix/lib" "$work/consumer/snap_consumer" "$data/terrain/hills.pts" $point)
check "the C program snaps" [ $? -eq 0 ]
query_answer=$(echo "snap $point" | "$prefix/bin/footfall" query --terrain "$data/terrain/hills.pts")
query_index=$(sed -n 's/.*"index":\([0-9]*\).*/\1/p' <<< "$query_answer")
check "its answer is footfall query's ($c_answer / $query_answer)" \
  [ -n "$query_index" ] && [ "${c_answer%% *}" = "$query_index" ]

# The installed Python package, with no FOOTFALL_LIB, no FOOTFALLD and the prefix not on PATH:
# it finds the installed library and server, starts footfalld and snaps over RPC.
python_check() {
  env -u FOOTFALL_LIB -u FOOTFALLD PATH=/usr/bin:/bin \
    PYTHONPATH="$1/share/footfall/python" python3 - "$1" "$1/share/footfall/data/terrain/hills.pts" <<'PY'
import os, sys
from footfall_client import library, server, Session
from footfall_client.server import LocalServer
prefix = os.path.realpath(sys.argv[1])
lib = os.path.realpath(library.find_library())
assert lib == os.path.realpath(os.path.join(prefix, "lib", "libfootfall.so")), lib
footfalld = os.path.realpath(server.find_footfalld())
assert footfalld == os.path.join(prefix, "bin", "footfalld"), footfalld
local = LocalServer().start()
try:
    with Session.rpc(port=local.port) as session:
        terrain = session.load_file(sys.argv[2])
        answer = session.snap(terrain, [[3.3, 9, -2.7]])[0]
        print(answer.index)
finally:
    local.stop()
PY
}
py_index=$(python_check "$prefix" 2> "$work/python.err")
check "the installed Python package finds its library and footfalld, and snaps over RPC" \
  [ "$py_index" = "$query_index" ]
[ -s "$work/python.err" ] && cat "$work/python.err" >&2

# Moved as a whole, the tree still works: paths in it are relative.
mv "$prefix" "$work/moved"
py_index=$(python_check "$work/moved" 2> "$work/python.err")
check "moved, the Python package still finds them" [ "$py_index" = "$query_index" ]
[ -s "$work/python.err" ] && cat "$work/python.err" >&2
pc_libdir=$(PKG_CONFIG_PATH="$work/moved/lib/pkgconfig" pkg-config --variable=libdir footfall)
check "moved, pkg-config names the moved libdir ($pc_libdir)" \
  [ "$(realpath "$pc_libdir")" = "$(realpath "$work/moved/lib")" ]
finish
