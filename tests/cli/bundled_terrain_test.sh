#!/usr/bin/env bash
# The bundled terrains of data/terrain are what data/README.md says made them: each documented
# `footfall terrain make ... -o NAME.pts` command, run here, writes the shipped file byte for
# byte (a change to a generator or the sampler shows here, and the file is made again).
#   bundled_terrain_test.sh FOOTFALL SOURCE_DIR
set -u
footfall=$(realpath "$1")
src=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
commands=$(grep -o '`footfall terrain make [^`]*-o [a-z]*\.pts`' "$src/data/README.md" | tr -d '`')
count=$(printf '%s\n' "$commands" | grep -c .)
if [ "$count" -lt 5 ]; then
  echo "FAIL: expected the commands of at least 5 bundled terrains in data/README.md, found $count"
  exit 1
fi
failed=0
while read -r -a words; do
  out=${words[${#words[@]}-1]}
  (cd "$work" && "$footfall" "${words[@]:1}" > /dev/null)
  status=$?
  if [ "$status" -ne 0 ]; then
    echo "FAIL: ${words[*]}: exit status $status"
    failed=$((failed + 1))
  elif ! cmp -s "$work/$out" "$src/data/terrain/$out"; then
    echo "FAIL: ${words[*]} does not re-create data/terrain/$out" \
      "($(grep -vc '^#' "$work/$out") samples against $(grep -vc '^#' "$src/data/terrain/$out"))"
    failed=$((failed + 1))
  fi
done <<< "$commands"
echo "$count bundled terrains checked, $failed failed"
[ "$failed" -eq 0 ]
