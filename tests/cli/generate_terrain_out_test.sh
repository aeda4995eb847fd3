#!/usr/bin/env bash
# `footfall generate --out FILE.pts`: the samples the walk was placed on, written as a point file
# (a mesh as resampled for the character; a point file as read), so that footfall-view and the
# plugins can show the walk on exactly its terrain; refused, before any walk, for a
# --server-terrain, whose samples are footfalld's.
# Usage: generate_terrain_out_test.sh FOOTFALL SOURCE_DIR
set -u
footfall=$1
source_dir=$2
source "$(dirname "$0")/../support/cli_checks.sh"
quadruped=$source_dir/data/characters/quadruped.json
hills=$source_dir/data/terrain/hills.pts

# A 24 x 24 m mesh of gentle bumps with 1 m faces: far coarser than the quadruped's steps, so
# generate resamples it for the character, only around the walk.
python3 - "$work/bumps.obj" <<'PY'
import math, sys
n = 25
with open(sys.argv[1], "w") as f:
    for j in range(n):
        for i in range(n):
            f.write(f"v {i} {0.3 * math.sin(0.7 * i) * math.cos(0.5 * j)} {j}\n")
    for j in range(n - 1):
        for i in range(n - 1):
            a = j * n + i + 1
            f.write(f"f {a} {a + n} {a + 1}\nf {a + 1} {a + n} {a + n + 1}\n")
PY

# Every start and end key of every foot lies on a sample of the point file (to float storage).
keys_on_samples() {  # keys_on_samples WALK.json POINTS.pts
  python3 - "$1" "$2" <<'PY'
import json, sys
walk = json.load(open(sys.argv[1]))
samples = {}
for line in open(sys.argv[2]):
    line = line.split("#")[0].split()
    if line:
        p = tuple(float(v) for v in line[:3])
        samples.setdefault(tuple(round(v, 2) for v in p), []).append(p)
def near(p):
    for dx in (-0.01, 0, 0.01):
        for dy in (-0.01, 0, 0.01):
            for dz in (-0.01, 0, 0.01):
                for s in samples.get((round(p[0] + dx, 2), round(p[1] + dy, 2), round(p[2] + dz, 2)), []):
                    if max(abs(a - b) for a, b in zip(p, s)) <= 1e-4:
                        return True
    return False
keys = [k for t in walk["tracks"] if t["kind"] == "foot" for k in t["keys"] if k["phase"] in ("start", "end")]
assert len(keys) > 20, len(keys)
missing = [k["position"] for k in keys if not near(k["position"])]
assert not missing, (len(missing), missing[:3])
PY
}

# 1. A mesh resampled for the character: the point file holds the samples stderr counts, and
#    the feet stand on them.
"$footfall" generate --terrain "$work/bumps.obj" --character "$quadruped" --start 12,0,6 \
  --steps 12 --out "$work/walk.json" --out "$work/terrain.pts" 2> "$work/mesh.err"
check "mesh: exit 0" [ $? -eq 0 ]
said=$(grep -o '[0-9]* samples; --separation' "$work/mesh.err" | cut -d' ' -f1)
written=$("$footfall" terrain info "$work/terrain.pts" | sed -n 's/^samples: //p')
check "mesh: resampled and cropped ('$said' samples said)" [ -n "$said" ]
check "mesh: the point file holds the samples said ($written, $said)" [ "$written" = "$said" ]
check "mesh: the feet stand on the written samples" keys_on_samples "$work/walk.json" "$work/terrain.pts"

# 2. A point file: written as read (every sample, the feet on them).
"$footfall" generate --terrain "$hills" --character "$quadruped" --start 8,0,8 --steps 6 \
  --out "$work/hills_walk.json" --out "$work/hills_copy.xyz" 2> "$work/hills.err"
check "points: exit 0" [ $? -eq 0 ]
check "points: every sample written" [ "$("$footfall" terrain info "$work/hills_copy.xyz" | sed -n 's/^samples: //p')" = \
  "$("$footfall" terrain info "$hills" | sed -n 's/^samples: //p')" ]
check "points: the feet stand on the written samples" keys_on_samples "$work/hills_walk.json" "$work/hills_copy.xyz"

# 2b. terrain info says the spacing a flat terrain was made at, coarse or fine.
for spacing in 0.25 0.04; do
  "$footfall" terrain make flat --spacing $spacing --size 20 -o "$work/flat.pts" > /dev/null
  said=$("$footfall" terrain info "$work/flat.pts" | sed -n 's/^sample spacing: about \([^ ]*\) .*/\1/p')
  check "terrain info: sample spacing about $spacing (said '$said')" \
    python3 -c "import sys; s = float(sys.argv[1]); sys.exit(not abs(s - $spacing) < 0.1 * $spacing)" "$said"
done

# 3. A --server-terrain's samples are not here: refused before anything is read or written.
"$footfall" generate --server-terrain hills.pts --server 127.0.0.1:1 --character "$quadruped" \
  --out "$work/s.json" --out "$work/s.pts" 2> "$work/server.err"
check "server terrain: exit 1" [ $? -eq 1 ]
check "server terrain: the message says why" grep -q "s.pts: the terrain is read by footfalld" "$work/server.err"
check "server terrain: no walk written" [ ! -e "$work/s.json" ]
check "server terrain: no terrain written" [ ! -e "$work/s.pts" ]

# 4. Never over the terrain the walk reads.
cp "$hills" "$work/own.pts"
"$footfall" generate --terrain "$work/own.pts" --character "$quadruped" --start 8,0,8 \
  --steps 2 --out "$work/own.pts" 2> "$work/own.err"
check "own terrain: exit 1" [ $? -eq 1 ]
check "own terrain: left whole" cmp -s "$hills" "$work/own.pts"
finish
