#!/usr/bin/env bash
# README.md's scene example walks whole as the README says: its scene file, saved beside copies
# of the shipped characters, and its two commands, run here as written.
#   readme_scene_test.sh FOOTFALL SOURCE_DIR
set -u
footfall=$(realpath "$1")
src=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/data/characters"
cp "$src"/data/characters/*.json "$work/data/characters/"
# The first ```json block holding a footfall-scene, and the first ```sh block after it.
awk '/^```json$/ {on = 1; text = ""; next}
     on && /^```$/ {on = 0; if (text ~ /footfall-scene/) {printf "%s", text; exit}; next}
     on {text = text $0 "\n"}' "$src/README.md" > "$work/data/characters/scene.json"
commands=$(awk '/footfall-scene/ {seen = 1}
                seen && /^```sh$/ {on = 1; next}
                on && /^```$/ {exit}
                on {print}' "$src/README.md")
if ! grep -q '"footfall-scene"' "$work/data/characters/scene.json" ||
   [ "$(printf '%s\n' "$commands" | grep -c '^footfall ')" -ne 2 ]; then
  echo "FAIL: README.md has no scene example followed by its two footfall commands"
  exit 1
fi
while read -r -a words; do
  (cd "$work" && "$footfall" "${words[@]:1}" 2> "$work/stderr")
  status=$?
  if [ "$status" -ne 0 ]; then
    echo "FAIL: ${words[*]}: exit status $status"
    cat "$work/stderr"
    exit 1
  fi
done <<< "$commands"
out=$(printf '%s\n' "$commands" | grep -o -- '--out [^ ]*' | cut -d' ' -f2)
python3 - "$work/$out" <<'PY' || exit 1
import json, sys
walk = json.load(open(sys.argv[1]))
names = {t["character"] for t in walk["tracks"]}
expected = {"walker"} | {f"spiders/c{i}" for i in range(1, 7)}
if walk.get("stopped") or names != expected:
    sys.exit(f"FAIL: the scene walk stopped ({walk.get('stopped')!r}) or has characters {sorted(names)}")
print(f"README scene: {len(walk['tracks'])} tracks of {sorted(names)}, walked whole")
PY
