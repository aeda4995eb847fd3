#!/usr/bin/env bash
# `footfall generate` end to end: identical walks from the embedded engine and a real footfalld
# (single characters, a path, a crowd, a walk that stops at a cliff), every output format, the
# exit status of a stopped walk, the messages of bad flags, and a mesh read by footfalld with
# the loading flags.
# Usage: generate_cli_test.sh FOOTFALL FOOTFALLD SOURCE_DIR
set -u
footfall=$1
footfalld=$2
src=$3
source "$(dirname "$0")/../support/cli_checks.sh"
chars=$src/data/characters
hills=$src/data/terrain/hills.pts

# A fine flat floor for insects (2.4 x 2.4 m, 1.2 cm spacing), and a plateau ending in a cliff
# at z = 6 (the ground below is 20 m lower).
awk 'BEGIN { for (k = 0; k < 200; k++) for (i = 0; i < 200; i++) printf "%.3f 0 %.3f 0 1 0\n", i * 0.012, k * 0.012 }' > "$work/floor.pts"
awk 'BEGIN { for (k = 0; k < 160; k++) for (i = 0; i < 100; i++) printf "%.2f %d %.2f 0 1 0\n", i * 0.05, (k * 0.05 < 6 ? 0 : -20), k * 0.05 }' > "$work/cliff.pts"

start_server "$footfalld"

both() {  # both NAME EXPECTED_EXIT ARGS...: embedded and RPC runs give identical JSON
  local name=$1 want=$2; shift 2
  "$footfall" generate "$@" --out "$work/$name-embedded.json" 2> "$work/$name-embedded.err"
  local rc_e=$?
  "$footfall" generate "$@" --server "$server" --out "$work/$name-rpc.json" 2> "$work/$name-rpc.err"
  local rc_r=$?
  check "$name: embedded exit $want" [ "$rc_e" -eq "$want" ]
  check "$name: rpc exit $want" [ "$rc_r" -eq "$want" ]
  check "$name: walk written" [ -s "$work/$name-embedded.json" ]
  check "$name: embedded and --server walks identical" cmp -s "$work/$name-embedded.json" "$work/$name-rpc.json"
}

# 1. Embedded and RPC give the same walk, byte for byte.
both biped-hills 0 --terrain "$hills" --character "$chars/biped.json" --steps 16
both biped-path 0 --terrain "$hills" --character "$chars/biped.json" --start 10,0,10 \
  --path "10,0,16 16,0,16"
both quadruped-hills 0 --terrain "$hills" --character "$chars/quadruped.json" --steps 16 --heading 1,0,1
both hexapod-crowd 0 --terrain "$work/floor.pts" --character "$chars/hexapod.json" --steps 12 \
  --crowd 9 --crowd-spacing 0.6 --start 1.2,0,0.8
both octopod-floor 0 --terrain "$work/floor.pts" --character "$chars/octopod.json" --steps 10 \
  --start 1.2,0,0.6 --start-frame 101
both biped-cliff 2 --terrain "$work/cliff.pts" --character "$chars/biped.json" --start 2.5,0,2 \
  --steps 100
# A crowd of bipeds going down wide stairs at a slant (the locators landing below their places).
"$footfall" terrain make stairs --width 8 --steps 12 --spacing 0.03 -o "$work/stairs.pts" > /dev/null
both biped-stairs-crowd 0 --terrain "$work/stairs.pts" --character "$chars/biped.json" --steps 10 \
  --crowd 4 --crowd-spacing 1.2 --start 3,1.98,3.4 --heading 1,0,-0.7
"$footfall" generate --terrain "$work/floor.pts" --character "$chars/hexapod.json" --steps 12 \
  --crowd 9 --crowd-spacing 0.6 --start 1.2,0,0.8 --threads 1 --out "$work/hexapod-crowd-1.json" 2> /dev/null
check "crowd: --threads 1 gives the same walk" cmp -s "$work/hexapod-crowd-1.json" "$work/hexapod-crowd-embedded.json"
check "path: reaches the goal without stopping" grep -q '"stopped":""' "$work/biped-path-embedded.json"
check "crowd: nine characters" [ "$(grep -o '"name":"body","character":"c[0-9]*"' "$work/hexapod-crowd-embedded.json" | wc -l)" -eq 9 ]
check "start frame" grep -q '{"frame":101,"phase":"start"' "$work/octopod-floor-embedded.json"
# A crowd larger than one embedded pass (1000 characters): the embedded run walks it in two
# passes, the RPC run all at once; same walk. --progress draws the bar to the end.
both big-crowd 0 --terrain "$work/floor.pts" --character "$chars/hexapod.json" --steps 4 \
  --crowd 1100 --crowd-spacing 0.04 --start 1.2,0,1.2 --progress
check "big crowd: 1100 characters" [ "$(grep -o '"name":"body","character":"c[0-9]*"' "$work/big-crowd-embedded.json" | wc -l)" -eq 1100 ]
check "big crowd: progress bar reaches 100%" grep -q '100%' "$work/big-crowd-embedded.err"

# Scene files: several characters in one walk, each with its own character file (beside the
# scene), start, path, steps, crowd and start frame; embedded and RPC identical, and each
# character walks exactly as it would alone.
mkdir -p "$work/scene"
cp "$chars/biped.json" "$chars/hexapod.json" "$work/scene/"
cat > "$work/scene/scene.json" <<JSON
{"format": "footfall-scene", "version": 1,
 "characters": [
  {"name": "walker", "character_file": "biped.json", "start": [0.6, 0, 0.4], "path": [[0.6, 0, 2]]},
  {"name": "bugs", "character_file": "hexapod.json", "start": [1.6, 0, 0.8], "steps": 8,
   "crowd": 4, "crowd_spacing": 0.5},
  {"character_file": "$chars/octopod.json", "start": [1.2, 0, 1.8], "heading": [1, 0, 0],
   "steps": 6, "start_frame": 11}
 ]}
JSON
both scene 0 --terrain "$work/floor.pts" --scene "$work/scene/scene.json"
"$footfall" generate --terrain "$work/floor.pts" --character "$chars/biped.json" --start 0.6,0,0.4 \
  --path 0.6,0,2 --out "$work/scene-walker-alone.json" 2> /dev/null
"$footfall" generate --terrain "$work/floor.pts" --character "$chars/hexapod.json" --start 1.6,0,0.8 \
  --steps 8 --crowd 4 --crowd-spacing 0.5 --out "$work/scene-bugs-alone.json" 2> /dev/null
scene_check() {  # scene_check SCENE.json: each character's tracks are its walk alone
  python3 - "$@" <<'PY'
import json, sys
scene = json.load(open(sys.argv[1]))
walker = json.load(open(sys.argv[2]))
bugs = json.load(open(sys.argv[3]))
names = sorted({t.get("character") for t in scene["tracks"]})
assert names == ["bugs/c1", "bugs/c2", "bugs/c3", "bugs/c4", "octopod3", "walker"], names
def tracks(walk, character, prefix=""):
    return [(t["name"], t["kind"], t["keys"]) for t in walk["tracks"]
            if t.get("character", "") == character]
assert tracks(scene, "walker") == tracks(walker, ""), "walker differs from the biped alone"
for c in ("c1", "c2", "c3", "c4"):
    assert tracks(scene, "bugs/" + c) == tracks(bugs, c), "bugs/" + c + " differs"
octopod = [t for t in scene["tracks"] if t.get("character") == "octopod3"]
assert len(octopod) == 9 and all(t["keys"][0]["frame"] == 11 for t in octopod), "octopod"
PY
}
check "scene: every character walks as it would alone" scene_check "$work/scene-embedded.json" "$work/scene-walker-alone.json" "$work/scene-bugs-alone.json"
"$footfall" generate --terrain "$work/floor.pts" --scene "$work/scene/scene.json" \
  --out "$work/scene.mel" --out "$work/scene.gltf" --out "$work/scene.pts" 2> /dev/null
check "scene: MEL, glTF and the terrain written" [ -s "$work/scene.mel" -a -s "$work/scene.gltf" -a -s "$work/scene.pts" ]
check "scene: a MEL group per character" [ "$(grep -c '^$footfall_groups\[' "$work/scene.mel")" -eq 6 ]
# --foot-rotations applies to the whole scene: every foot key of every character is turned, and
# the rest of the walk is the same.
"$footfall" generate --terrain "$work/floor.pts" --scene "$work/scene/scene.json" --foot-rotations \
  --out "$work/scene-turned.json" 2> /dev/null
check "scene: --foot-rotations turns every foot key, nothing else changes" python3 - "$work/scene-embedded.json" "$work/scene-turned.json" <<'PY'
import json, sys
plain, turned = (json.load(open(p)) for p in sys.argv[1:])
feet = [t for t in turned["tracks"] if t["kind"] == "foot"]
assert len({t.get("character") for t in feet}) > 2 and all("rotation" in k for t in feet for k in t["keys"])
for t in feet:
    for k in t["keys"]:
        del k["rotation"]
assert turned == plain
PY
# A character that stops after a crowd's 25 stops is named on stderr: the list of 20 stops was
# the scene's, and a biped stopped at the terrain's edge went unnamed.
"$footfall" terrain make flat --size 40 --spacing 0.25 -o "$work/flat40c.pts" > /dev/null
cat > "$work/scene/hidden.json" <<JSON
{"format": "footfall-scene", "version": 1, "characters": [
 {"name": "herd", "character_file": "biped.json", "start": [20, 0, 3], "heading": [0, 0, -1],
  "steps": 20, "crowd": 25, "crowd_spacing": 1.5},
 {"name": "loner", "character_file": "biped.json", "start": [35, 0, 37], "steps": 20}]}
JSON
scene_run() {  # scene_run NAME TERRAIN SCENE EXIT: the walk in $work/NAME.json, stderr NAME.err
  "$footfall" generate --terrain "$2" --scene "$3" --out "$work/$1.json" 2> "$work/$1.err"
  check "$1: exit $4" [ $? -eq "$4" ]
}
scene_run hidden "$work/flat40c.pts" "$work/scene/hidden.json" 2
check "scene stops: more than 20 listed from the crowd" [ "$(grep -c '^  herd: ' "$work/hidden.err")" -eq 20 ]
check "scene stops: the character after the crowd named" grep -q '^  loner: step ' "$work/hidden.err"
check "scene stops: the rest counted" grep -q '^  \.\.\. and [0-9]* more$' "$work/hidden.err"
# A scene character walking off the cliff: exit 2, its stop named, every character's keys kept.
cat > "$work/scene/cliff.json" <<JSON
{"format": "footfall-scene", "version": 1,
 "characters": [{"name": "safe", "character_file": "biped.json", "start": [2.5, 0, 1], "steps": 2},
                {"name": "faller", "character_file": "biped.json", "start": [2.5, 0, 2], "steps": 100}]}
JSON
both scene-cliff 2 --terrain "$work/cliff.pts" --scene "$work/scene/cliff.json"
check "scene cliff: the faller's stop named" grep -qE '"stopped":"faller: step [0-9]+: foot' "$work/scene-cliff-embedded.json"
check "scene cliff: the other character's keys kept" grep -q '"character":"safe"' "$work/scene-cliff-embedded.json"
# A scene character that cannot walk at all (its heading along the up): exit 1, the others
# (before and after it) walked and written, embedded as over RPC, and the walk file says who
# did not walk. (In process, the characters after it were left unwalked; the file's "stopped"
# was empty.) The others' stops are said too (a faller's at the hills' east edge was said
# nowhere: neither on stderr nor in the file).
cat > "$work/scene/upward.json" <<JSON
{"format": "footfall-scene", "version": 1,
 "characters": [{"name": "first", "character_file": "biped.json", "start": [10, 0, 10], "steps": 2},
                {"name": "upward", "character_file": "biped.json", "heading": [0, 1, 0], "steps": 2},
                {"name": "last", "character_file": "biped.json", "start": [14, 0, 14], "steps": 2},
                {"name": "faller", "character_file": "biped.json", "start": [39, 0, 20],
                 "heading": [1, 0, 0], "steps": 6}]}
JSON
both scene-failed 1 --terrain "$hills" --scene "$work/scene/upward.json"
check "scene failure: the others written" python3 -c "
import json, sys
walk = json.load(open(sys.argv[1]))
assert sorted({t['character'] for t in walk['tracks']}) == ['faller', 'first', 'last'], walk['tracks']
assert walk['stopped'].startswith('upward did not walk: the heading'), walk['stopped']
assert walk['stopped'].endswith('(and 1 more stopped)'), walk['stopped']
" "$work/scene-failed-embedded.json"
check "scene failure: said" grep -q '^footfall generate: upward: the heading' "$work/scene-failed-embedded.err"
check "scene failure: the others' stops said" grep -q '^footfall generate: stopped early: faller: step [0-9]*: foot' "$work/scene-failed-embedded.err"
# Failures listed up to 20, then counted (footfalld dying mid-scene failed each character not
# yet walked: 5,584 lines of one reason).
python3 - "$work/scene/upward25.json" <<'PY'
import json, sys
characters = [{"name": "first", "character_file": "biped.json", "start": [10, 0, 10], "steps": 2}]
characters += [{"name": "up%d" % i, "character_file": "biped.json", "heading": [0, 1, 0],
                "steps": 2} for i in range(25)]
json.dump({"format": "footfall-scene", "version": 1, "characters": characters},
          open(sys.argv[1], "w"))
PY
scene_run upward25 "$hills" "$work/scene/upward25.json" 1
check "25 failures: 20 said" [ "$(grep -c '^footfall generate: up[0-9]*: the heading' "$work/upward25.err")" -eq 20 ]
check "25 failures: the rest counted" grep -qx 'footfall generate: \.\.\. and 5 more characters did not walk' "$work/upward25.err"
check "25 failures: the one that walked written" grep -q '"character":"first"' "$work/upward25.json"
# A scene character whose walk memory cannot hold: said, exit 1, not an abort. (Its steps are
# a path's, only a bound: given steps would be refused up front, in 8. below.)
printf '{"format": "footfall-scene", "version": 1, "characters": [{"character_file": "biped.json", "steps": 5}, {"character_file": "hexapod.json", "crowd": 300000, "path": [[30, 0, 30]], "crowd_spacing": 0.01}]}' > "$work/scene/huge.json"
(ulimit -v 1500000; "$footfall" generate --terrain "$hills" --scene "$work/scene/huge.json" --out "$work/huge.json" 2> "$work/huge.err")
check "scene beyond memory: exit 1" [ $? -eq 1 ]
check "scene beyond memory: said" grep -q 'hexapod2: out of memory generating its walk' "$work/huge.err"
# Bad uses: per-character flags with --scene, neither --scene nor --character, a resampled
# mesh's samples (one per character), a bad scene file named with its character and field.
"$footfall" generate --terrain "$work/floor.pts" --scene "$work/scene/scene.json" --start 1,0,1 \
  --out "$work/bad.json" 2> "$work/bad.err"
check "scene with --start: refused" [ $? -ne 0 -a ! -e "$work/bad.json" ]
check "scene with --start: said" grep -q -- '--scene excludes --start' "$work/bad.err"
"$footfall" generate --terrain "$work/floor.pts" --out "$work/bad.json" 2> "$work/bad.err"
check "no --character or --scene: exit 1" [ $? -eq 1 -a ! -e "$work/bad.json" ]
check "no --character or --scene: said" grep -q 'give --character FILE .* or --scene FILE' "$work/bad.err"
printf 'v -3 0 -3\nv 3 0 -3\nv 3 0 3\nv -3 0 3\nf 1 4 3 2\n' > "$work/plane.obj"
"$footfall" generate --terrain "$work/plane.obj" --scene "$work/scene/cliff.json" --out "$work/bad.pts" 2> "$work/bad.err"
check "scene on a mesh with --out .pts: exit 1" [ $? -eq 1 -a ! -e "$work/bad.pts" ]
check "scene on a mesh with --out .pts: said" grep -q 'resampled for each character; give --separation' "$work/bad.err"
printf '{"format": "footfall-scene", "version": 1, "characters": [{"character_file": "biped.json", "fps": 30}]}' > "$work/scene/bad.json"
"$footfall" generate --terrain "$work/floor.pts" --scene "$work/scene/bad.json" --out "$work/bad.json" 2> "$work/bad.err"
check "bad scene file: exit 1" [ $? -eq 1 -a ! -e "$work/bad.json" ]
check "bad scene file: the character and field named" grep -qF "$work/scene/bad.json: characters[0]: unknown field 'fps'" "$work/bad.err"
check "bad scene file: the known fields listed, name among them, fps not" grep -qE "unknown field 'fps' \(known fields: .*crowd_spacing, .*name, path, .*up\)" "$work/bad.err"
check "bad scene file: fps not listed" sh -c "! grep -q 'known fields: .*fps' '$work/bad.err'"

# The default start moves to where the character can stand: the top centre of the bundled
# blocks is on a pile's edge (a foot on a vertical face, which stopped them at step 1); the
# biped and the quadruped start on a flat top nearby and walk on (until a 1 m block's face).
both biped-blocks 0 --terrain "$src/data/terrain/blocks.pts" --character "$chars/biped.json" --steps 2
both quadruped-blocks 0 --terrain "$src/data/terrain/blocks.pts" --character "$chars/quadruped.json" --steps 8
# A crowd member whose place snaps onto a block's side, where the heading runs along its up:
# the heading is judged at the crowd's start, and that member walks on that side (the whole
# crowd was refused, nothing written, with advice to change a heading that was fine; then the
# member stopped at step 3, until the tries aimed down by a whole max_rise).
both hexapod-blocks-crowd 0 --terrain "$src/data/terrain/blocks.pts" --character "$chars/hexapod.json" \
  --steps 3 --crowd 3
check "crowd with a member on a block's side: every member keyed" python3 -c "
import json, sys
walk = json.load(open(sys.argv[1]))
assert sorted({t['character'] for t in walk['tracks']}) == ['c1', 'c2', 'c3'], walk['stopped']
" "$work/hexapod-blocks-crowd-embedded.json"
first_keys=$(grep -c '{"frame":1,"phase"' "$work/biped-blocks-embedded.json")
level_keys=$(grep -c '{"frame":1,"phase".*"normal":\[0,1,0\]' "$work/biped-blocks-embedded.json")
check "blocks: both feet start on level ground" [ "$first_keys" -eq 2 -a "$level_keys" -eq 2 ]

# Directions with huge components are normalised without overflow: the same walk as 1,0,1.
"$footfall" generate --terrain "$hills" --character "$chars/quadruped.json" --steps 16 \
  --heading 1e300,0,1e300 --up 0,1e300,0 --out "$work/huge-heading.json" 2> /dev/null
check "heading 1e300,0,1e300: the walk of 1,0,1" cmp -s "$work/huge-heading.json" "$work/quadruped-hills-embedded.json"

# 2. A walk stopped at a cliff: the message names the step and the position; the keys so far
#    are written; exit 2.
check "cliff: message on stderr" grep -qE 'stopped early: step [0-9]+: foot [LR] at \([0-9.]+, [0-9.-]+, [0-9.]+\): .*cliff' "$work/biped-cliff-embedded.err"
check "cliff: message in the walk" grep -qE '"stopped":"step [0-9]+: foot' "$work/biped-cliff-embedded.json"
check "cliff: keys kept" [ "$(grep -c '"phase":"end"' "$work/biped-cliff-embedded.json")" -gt 8 ]
# A biped on a Z-up floor with the default world up (Y): it cannot stand there, and the stop
# says how to give the terrain's up.
awk 'BEGIN { for (k = 0; k < 60; k++) for (i = 0; i < 60; i++) printf "%.2f %.2f 0 0 0 1\n", i * 0.05, k * 0.05 }' > "$work/zup.pts"
"$footfall" generate --terrain "$work/zup.pts" --character "$chars/biped.json" --start 1.5,1.5,0 \
  --steps 4 --out "$work/zup.json" 2> "$work/zup.err"
check "Z-up terrain with the default up: exit 2" [ $? -eq 2 ]
check "Z-up terrain with the default up: the stop names --up" grep -q 'give the world up with --up (Z up: --up 0,0,1)' "$work/zup.err"
"$footfall" generate --terrain "$work/zup.pts" --character "$chars/biped.json" --start 1.5,1.5,0 \
  --up 0,0,1 --heading 0,1,0 --steps 4 --out "$work/zup.json" 2> "$work/zup.err"
check "Z-up terrain with --up 0,0,1: walks" [ $? -eq 0 ]
# In a scene, the up to give is written as the scene's field takes it (the flag form was
# suggested, which a scene file cannot hold); a character without 'up' takes --up, named so.
printf '{"format": "footfall-scene", "version": 1, "characters": [{"name": "b1", "character_file": "%s", "start": [1.5, 1.5, 0], "steps": 4, "up": [0, 1, 0]}, {"name": "b2", "character_file": "%s", "start": [1.5, 1.5, 0], "steps": 4}]}\n' \
  "$chars/biped.json" "$chars/biped.json" > "$work/zup-scene.json"
"$footfall" generate --terrain "$work/zup.pts" --scene "$work/zup-scene.json" --out "$work/zup-scene.json.out.json" 2> "$work/zup-scene.err"
check "Z-up scene: exit 2" [ $? -eq 2 ]
check "Z-up scene: the stop names the character" grep -qF "b1: step 1: foot L cannot stand at" "$work/zup-scene.err"
check "Z-up scene: the field's up as JSON" grep -qF "give the world up with $work/zup-scene.json: characters[0]: 'up' (Z up: [0, 0, 1])" "$work/zup-scene.err"
check "Z-up scene: a character without 'up' names --up" grep -qF "give the world up with --up (Z up: --up 0,0,1)" "$work/zup-scene.err"
# The other way round: a Y-up terrain given --up 0,0,1 is told the up its ground faces, not the
# Z up it was given.
"$footfall" generate --terrain "$hills" --character "$chars/biped.json" --up 0,0,1 \
  --heading 1,0,0 --steps 4 --out "$work/yup.json" 2> "$work/yup.err"
check "Y-up terrain with --up 0,0,1: exit 2" [ $? -eq 2 ]
check "Y-up terrain with --up 0,0,1: the stop names --up 0,1,0" grep -q 'give the world up with --up (Y up: --up 0,1,0)' "$work/yup.err"
# A crowd walking toward the cliff: its front row (c4-c6) stops first. The walk names the
# earliest stop; stderr lists every character's.
"$footfall" generate --terrain "$work/cliff.pts" --character "$chars/biped.json" --crowd 6 \
  --start 2.5,0,4 --steps 40 --out "$work/crowd-cliff.json" 2> "$work/crowd-cliff.err"
check "crowd cliff: exit 2" [ $? -eq 2 ]
check "crowd cliff: the earliest stop named" grep -q '"stopped":"step 4 of c4: .*(and 5 more characters stopped)"' "$work/crowd-cliff.json"
check "crowd cliff: every stop listed" [ "$(grep -cE '^  step [0-9]+ of c[1-6]: foot' "$work/crowd-cliff.err")" -eq 6 ]
check "crowd cliff: the back row's stop listed" grep -qE '^  step [0-9]+ of c1: foot' "$work/crowd-cliff.err"
# A goal straight above the start: no steps, and a note that says why.
"$footfall" generate --terrain "$work/cliff.pts" --character "$chars/biped.json" --start 2.5,0,4 \
  --path 2.5,5,4 --out "$work/goal-above.json" 2> "$work/goal-above.err"
check "goal above the start: exit 0" [ $? -eq 0 ]
check "goal above the start: the note" grep -q "no steps: the path's goal is already reached where the character starts" "$work/goal-above.err"
"$footfall" generate --terrain "$work/cliff.pts" --character "$chars/biped.json" --start 2.5,0,1 \
  --path 2.5,0,4 --steps 0 --out "$work/steps0.json" 2> "$work/steps0.err"
check "--steps 0 with a path: no note about the goal" bash -c "! grep -q 'goal is already reached' '$work/steps0.err'"
# --steps too few for the path: the steps asked for (exit 0, no stop), and a note of how far the
# goal still is (it used to end short of it saying nothing).
"$footfall" generate --terrain "$work/cliff.pts" --character "$chars/biped.json" --start 2.5,0,1 \
  --path 2.5,0,4 --steps 2 --out "$work/short.json" 2> "$work/short.err"
check "--steps short of the goal: exit 0" [ $? -eq 0 ]
check "--steps short of the goal: no stop" grep -q '"stopped":""' "$work/short.json"
check "--steps short of the goal: the note" grep -qE "^footfall generate: note: the path's goal \(2.5000, 0.0000, 4.0000\) is still [0-9.]+ away after the 2 steps asked for" "$work/short.err"
# A --start past the plateau's side is said, with where the character starts instead (it was
# snapped there without a word); the walk is made (exit 0).
"$footfall" generate --terrain "$work/cliff.pts" --character "$chars/biped.json" --start 10,0,1 \
  --steps 2 --out "$work/far-start.json" 2> "$work/far-start.err"
check "--start off the terrain: exit 0" [ $? -eq 0 ]
check "--start off the terrain: the note" grep -qxF "footfall generate: note: the start (10.0000, 0.0000, 1.0000) (--start) snaps to the terrain's sample nearest it, (4.9500, 0.0000, 1.0000), 5.05 away across the up (more than a step, 0.7): the character starts there" "$work/far-start.err"
# A character whose step_length its reach cannot follow is said once, not shortened silently.
sed 's/"step_length": 0.7/"step_length": 5/' "$chars/biped.json" > "$work/long-step.json"
"$footfall" generate --terrain "$hills" --character "$work/long-step.json" --start 10,0,10 \
  --steps 4 --crowd 3 --out "$work/long-step.json.out.json" 2> "$work/long-step.err"
check "step_length beyond reach: exit 0" [ $? -eq 0 ]
check "step_length beyond reach: said once" [ "$(grep -c '^footfall generate: note: step_length 5 is longer than reach 1.2 lets a foot travel (about 2.89 on level ground, for the foot with the least room)' "$work/long-step.err")" -eq 1 ]
# Feet snapped at the start onto samples too far apart for the character (the octopod on the
# 25 cm hills) stood beyond reach with nothing said.
"$footfall" generate --terrain "$hills" --character "$chars/octopod.json" --steps 4 \
  --out "$work/coarse-start.json" 2> "$work/coarse-start.err"
check "start beyond reach: said" grep -q '^footfall generate: note: at the start, foot [A-Z0-9]* stands 0.3[0-9]* from the body, beyond reach 0.32: the terrain.s samples (about 0.2[0-9]* apart) are too far apart' "$work/coarse-start.err"
# A glTF output that cannot hold the walk's times is named; the JSON beside it is written (it
# keeps every key).
"$footfall" generate --terrain "$work/cliff.pts" --character "$chars/biped.json" --start 2.5,0,1 \
  --steps 4 --start-frame 1e9 --fps 1e6 --out "$work/far.json" --out "$work/far.gltf" 2> "$work/far.err"
check "glTF times collide: exit 1" [ $? -eq 1 ]
check "glTF times collide: the output named" grep -qF -- "--out $work/far.gltf: glTF times are float seconds" "$work/far.err"
check "glTF times collide: the JSON written" [ -s "$work/far.json" ]

# 3. Every output format at once; a stopped walk still writes them all.
"$footfall" generate --terrain "$work/cliff.pts" --character "$chars/biped.json" --start 2.5,0,2 \
  --steps 100 --out "$work/all.json" --out "$work/all.gltf" --out "$work/all.glb" --out "$work/all.mel" 2>/dev/null
check "formats: exit 2 for a stopped walk" [ $? -eq 2 ]
for f in all.json all.gltf all.glb all.mel; do check "formats: $f written" [ -s "$work/$f" ]; done
# Far from frame 0, glTF's float seconds move keys off their frames: a warning says by how much.
"$footfall" generate --terrain "$hills" --character "$chars/biped.json" --steps 4 \
  --start-frame 10000000 --out "$work/late.gltf" 2> "$work/late.err"
check "glTF late frames: exit 0" [ $? -eq 0 ]
check "glTF late frames: warned" grep -qF "$work/late.gltf: glTF stores times as float seconds, and at these frames keys move by up to 0.25 frames" "$work/late.err"
"$footfall" generate --terrain "$hills" --character "$chars/biped.json" --steps 4 \
  --out "$work/early.gltf" 2> "$work/early.err"
check "glTF early frames: no warning" [ ! -s "$work/early.err" ]
# A glTF the process has no memory left to write is refused up front (tinygltf aborted the
# process, losing the outputs after it); the others are written.
(ulimit -v 700000; "$footfall" generate --terrain "$hills" --character "$chars/biped.json" \
  --crowd 20000 --crowd-spacing 0.25 --steps 10 --out "$work/oom.gltf" --out "$work/oom.json" 2> "$work/oom.err")
check "glTF beyond memory: exit 1" [ $? -eq 1 ]
check "glTF beyond memory: said so" grep -qF -- "--out $work/oom.gltf: writing the walk as glTF needs about" "$work/oom.err"
check "glTF beyond memory: the JSON written" [ -s "$work/oom.json" ]
# Memory short while serialising glTF: a string stream that cannot grow dropped the rest of the
# file, and the cut file replaced the good one with exit 0. Whatever the machine's memory makes
# of it, the file is whole, or refused and the previous one kept.
"$footfall" terrain make flat --size 20 --spacing 0.05 -o "$work/flat20.pts" > /dev/null
# One name for the file to write in every command: `terrain make` and `convert` take --out as
# `generate` does, and `generate` takes -o as they do.
"$footfall" terrain make flat --size 20 --spacing 0.05 --out "$work/flat20-out.pts" > /dev/null
check "terrain make --out writes what -o does" cmp -s "$work/flat20.pts" "$work/flat20-out.pts"
"$footfall" terrain convert "$work/flat20.pts" --out "$work/flat20-convert.pts" > /dev/null
check "terrain convert --out writes the file" [ -s "$work/flat20-convert.pts" ]
"$footfall" generate --terrain "$work/flat20.pts" --character "$chars/biped.json" --steps 2 \
  -o "$work/short-o.json" 2> /dev/null
check "generate -o writes the walk" [ -s "$work/short-o.json" ]
"$footfall" generate --terrain "$work/flat20.pts" --character "$chars/biped.json" --steps 2 \
  --output "$work/short-output.json" 2> /dev/null
check "generate --output writes the walk" [ -s "$work/short-output.json" ]
# --heading with --path is not used for one character (the path gives the direction): said.
"$footfall" generate --terrain "$work/flat20.pts" --character "$chars/biped.json" --start 10,0,10 \
  --heading 0,1,0 --path 10,0,14 --out "$work/heading-path.json" 2> "$work/heading-path.err"
check "heading with path: exit 0" [ $? -eq 0 ]
check "heading with path: said unused" grep -qxF "footfall generate: note: --heading is not used with --path: the character starts facing its first waypoint" "$work/heading-path.err"
# A start beyond the reach of terrain queries is refused before the terrain is read (1e155 on
# a mesh was "no samples").
"$footfall" generate --terrain "$work/flat20.pts" --character "$chars/biped.json" \
  --start 1e155,0,0 --out "$work/far-start.json" 2> "$work/far-start.err"
check "start out of reach: exit 1" [ $? -eq 1 ]
check "start out of reach: said" grep -qxF "footfall generate: the start (--start) is too far from the terrain to snap (queries reach 1e15 from it)" "$work/far-start.err"
python3 - "$work/centipede.json" <<'PY'
import json, sys
feet = [{"name": "%s%d" % (s, i), "rest": [0.06 if s == "L" else -0.06, 0, 0.3 - 0.03 * i]}
        for s in "LR" for i in range(20)]
odd = lambda f: (int(f["name"][1:]) + (f["name"][0] == "R")) % 2
json.dump({"format": "footfall-character", "version": 1, "name": "centipede", "feet": feet,
           "gait": [[f["name"] for f in feet if odd(f) == g] for g in (0, 1)],
           "step_length": 0.1, "step_height": 0.04, "body_height": 0.04, "frames_per_step": 6,
           "align_to_normal": True, "max_slope_deg": 100, "max_rise": 0.07, "reach": 0.6},
          open(sys.argv[1], "w"))
PY
for limit in 450000 550000; do
  for ext in gltf glb; do
    echo PREVIOUS > "$work/short.$ext"
    (ulimit -v $limit; "$footfall" generate --terrain "$work/flat20.pts" --character "$work/centipede.json" \
      --threads 1 --crowd 400 --crowd-spacing 0.45 --start 10,0,5 --steps 60 --out "$work/short.$ext" 2> /dev/null)
    rc=$?
    if [ $rc -eq 1 ]; then
      check "glTF with memory short ($ext, $limit): refused, the previous file kept" grep -qx PREVIOUS "$work/short.$ext"
    else
      check "glTF with memory short ($ext, $limit): written whole" python3 -c "
import json, struct, sys
d = open(sys.argv[1], 'rb').read()
if sys.argv[1].endswith('.glb'):
    assert struct.unpack('<4sII', d[:12])[2] == len(d)
else:
    json.loads(d)" "$work/short.$ext"
    fi
  done
done
# A crowd beyond memory says how large it is (it said "out of memory" alone): refused up front
# when its steps are given, else when memory runs out (a path's steps are only a bound).
(ulimit -v 500000; "$footfall" generate --terrain "$hills" --character "$chars/biped.json" \
  --crowd 100000 --crowd-spacing 0.1 --steps 100 --out "$work/oom-crowd.json" 2> "$work/oom-crowd.err")
check "crowd beyond memory: exit 1" [ $? -eq 1 ]
check "crowd beyond memory: said how large" grep -qF "100000 characters x 100 steps make about 4e+07 keys, 2.72 GB, more than the 0.512 GB of memory this process may use" "$work/oom-crowd.err"
(ulimit -v 500000; "$footfall" generate --terrain "$hills" --character "$chars/biped.json" \
  --crowd 100000 --crowd-spacing 0.1 --path 30,0,30 --out "$work/oom-crowd.json" 2> "$work/oom-crowd.err")
check "path crowd beyond memory: exit 1" [ $? -eq 1 ]
check "path crowd beyond memory: said how large" grep -qF "out of memory generating 100000 characters x up to 1e+04 steps: up to about 4e+09 keys, 272 GB" "$work/oom-crowd.err"
# A stopped walk with an output that could not be written is an error (1), not a stop (2), and
# the other outputs are written; glTF, serialised straight into its file, fails as JSON does.
for ext in json glb gltf; do
  ln -sf /dev/full "$work/full.$ext"
  "$footfall" generate --terrain "$work/cliff.pts" --character "$chars/biped.json" --start 2.5,0,2 \
    --steps 100 --out "$work/full.$ext" --out "$work/stopped-ok.$ext.json" 2> "$work/stopped-bad-$ext.err"
  check "stopped walk, unwritten .$ext: exit 1" [ $? -eq 1 ]
  check "stopped walk, unwritten .$ext: named" grep -qF "cannot write '$work/full.$ext': No space left on device" "$work/stopped-bad-$ext.err"
  check "stopped walk, unwritten .$ext: the other written" [ -s "$work/stopped-ok.$ext.json" ]
done
# An output that cannot be written at all is refused before the walk is generated.
"$footfall" generate --terrain "$work/cliff.pts" --character "$chars/biped.json" --start 2.5,0,2 \
  --steps 100 --out "$work/no/such/dir/walk.json" --out "$work/early-ok.json" 2> "$work/early-bad.err"
check "unwritable output: exit 1" [ $? -eq 1 ]
check "unwritable output: named before generating" grep -qF -- "--out $work/no/such/dir/walk.json: cannot open '$work/no/such/dir/walk.json' for writing: No such file or directory" "$work/early-bad.err"
check "unwritable output: nothing generated" bash -c "! grep -q 'stopped early' '$work/early-bad.err' && [ ! -e '$work/early-ok.json' ]"
check "formats: MEL keys the feet" grep -q 'setKeyframe' "$work/all.mel"
# --foot-rotations keys the feet's rotations too in glTF and MEL (the exporters' tests check
# their values); without it only bodies turn. The JSON gives each foot key its rotation, which
# stands the foot's up on the key's normal, and is otherwise the same.
"$footfall" generate --terrain "$work/cliff.pts" --character "$chars/biped.json" --start 2.5,0,2 \
  --steps 100 --foot-rotations --out "$work/turned.json" --out "$work/turned.gltf" \
  --out "$work/turned.mel" 2>/dev/null
check "foot rotations: exit 2 for the stopped walk" [ $? -eq 2 ]
check "foot rotations: the JSON has them, and is otherwise unchanged" python3 - "$work/all.json" "$work/turned.json" <<'PY'
import json, math, sys
plain, turned = (json.load(open(p)) for p in sys.argv[1:])
feet = 0
for track in turned["tracks"]:
    for key in track["keys"]:
        if track["kind"] != "foot":
            continue
        x, y, z, w = key.pop("rotation")
        assert abs(math.sqrt(x * x + y * y + z * z + w * w) - 1) < 1e-9, key
        # (0, 1, 0) turned by the quaternion, against the key's normal.
        up = (2 * (x * y - w * z), 1 - 2 * (x * x + z * z), 2 * (y * z + w * x))
        n = key["normal"]
        length = math.sqrt(sum(c * c for c in n))
        assert sum(u * c / length for u, c in zip(up, n)) > 1 - 1e-9, (key, up)
        feet += 1
assert feet > 10 and turned == plain, feet
PY
check "foot rotations: MEL turns 3 locators, not 1" [ "$(grep -c 'rotateOrder' "$work/turned.mel")" -eq 3 -a "$(grep -c 'rotateOrder' "$work/all.mel")" -eq 1 ]
check "foot rotations: glTF has 3 rotation channels, not 1" [ "$(grep -o '"path": *"rotation"' "$work/turned.gltf" | wc -l)" -eq 3 -a "$(grep -o '"path": *"rotation"' "$work/all.gltf" | wc -l)" -eq 1 ]
# The character file's walk settings given as flags walk as a character file with those values
# does, byte for byte (the plugins' panels override the same four); out of range, or with a
# scene, they are refused.
python3 - "$chars/biped.json" "$work/biped-set.json" "$work/biped-point.json" <<'PY'
import json, sys
c = json.load(open(sys.argv[1]))
c.update(step_length=0.45, step_height=0.2, frames_per_step=16, foot_length=0.3, foot_width=0.12)
json.dump(c, open(sys.argv[2], "w"))
c["foot_length"] = 0
c.pop("foot_width")  # point feet have no width
json.dump(c, open(sys.argv[3], "w"))
PY
"$footfall" generate --terrain "$hills" --character "$chars/biped.json" --start 12,0,8 --steps 6 \
  --step-length 0.45 --step-height 0.2 --frames-per-step 16 --foot-length 0.3 --foot-width 0.12 \
  --out "$work/flags-set.json" 2>/dev/null
check "walk settings as flags: exit 0" [ $? -eq 0 ]
"$footfall" generate --terrain "$hills" --character "$work/biped-set.json" --start 12,0,8 --steps 6 \
  --out "$work/file-set.json" 2>/dev/null
check "walk settings as flags: the walk of a file with those settings" cmp -s "$work/flags-set.json" "$work/file-set.json"
"$footfall" generate --terrain "$hills" --character "$chars/biped.json" --start 12,0,8 --steps 6 \
  --out "$work/file-own.json" 2>/dev/null
check "walk settings as flags: not the file's own walk" bash -c "! cmp -s '$work/flags-set.json' '$work/file-own.json'"
"$footfall" generate --terrain "$hills" --character "$work/biped-set.json" --start 12,0,8 --steps 6 \
  --foot-length 0 --out "$work/flags-point.json" 2>/dev/null
"$footfall" generate --terrain "$hills" --character "$work/biped-point.json" --start 12,0,8 --steps 6 \
  --out "$work/file-point.json" 2>/dev/null
check "--foot-length 0: point feet" cmp -s "$work/flags-point.json" "$work/file-point.json"
check "--foot-length 0: no foot_length written" bash -c "! grep -q foot_length '$work/flags-point.json'"
# A width needs a length: refused with point feet, named.
"$footfall" generate --terrain "$hills" --character "$chars/biped.json" --foot-length 0 --foot-width 0.1 \
  --out "$work/bad-width.json" 2> "$work/bad-width.err"
check "--foot-width without a foot length: exit 1" [ $? -eq 1 ]
check "--foot-width without a foot length: named" grep -q -- "--foot-width: 0.1 needs a foot length above 0" "$work/bad-width.err"
check "--foot-width without a foot length: no walk written" [ ! -e "$work/bad-width.json" ]
for bad in "--step-length 0" "--step-height -1" "--frames-per-step 1" "--frames-per-step 2.5" "--foot-length -0.1" "--foot-width -0.1" "--step-length nan"; do
  # shellcheck disable=SC2086
  "$footfall" generate --terrain "$hills" --character "$chars/biped.json" $bad --out "$work/bad-setting.json" 2> "$work/bad-setting.err"
  check "$bad: exit 1" [ $? -eq 1 ]
  check "$bad: the flag named" grep -qF -- "${bad%% *}: " "$work/bad-setting.err"
  check "$bad: nothing written" [ ! -e "$work/bad-setting.json" ]
done
"$footfall" generate --terrain "$hills" --scene "$work/none.json" --foot-length 0.2 --out "$work/bad-setting.json" 2> "$work/bad-setting.err"
check "--foot-length with --scene: exit 1" [ $? -eq 1 ]
check "--foot-length with --scene: said" grep -qF -- "--scene excludes --foot-length" "$work/bad-setting.err"
# --scale 100: the biped (a file in metres) on the hills in centimetres walks its walk on the
# hills in metres, 100 times larger (to 1e-6 of its size); the walk settings' flags after it are
# in the terrain's units; unscaled, a note says which scale fits; out of range, or with a scene,
# it is refused before anything is written.
awk '/^#/ || NF == 0 { next } { printf "%.10g %.10g %.10g %s %s %s\n", $1 * 100, $2 * 100, $3 * 100, $4, $5, $6 }' "$hills" > "$work/hills-cm.pts"
"$footfall" generate --terrain "$work/hills-cm.pts" --character "$chars/biped.json" --scale 100 \
  --start 1200,0,800 --steps 6 --out "$work/scaled.json" 2> "$work/scaled.err"
check "--scale 100: exit 0" [ $? -eq 0 ]
check "--scale 100: nothing said" [ ! -s "$work/scaled.err" ]
"$footfall" generate --terrain "$work/hills-cm.pts" --character "$chars/biped.json" --scale 100 \
  --start 1200,0,800 --steps 6 --step-length 45 --step-height 20 --frames-per-step 16 \
  --foot-length 30 --out "$work/scaled-set.json" 2>/dev/null
check "--scale 100 with the walk settings' flags: exit 0" [ $? -eq 0 ]
scaled_like() {  # scaled_like METRES.json CENTIMETRES.json: the second is the first times 100
  python3 - "$1" "$2" <<'PY'
import json, sys
a, b = (json.load(open(p)) for p in sys.argv[1:3])
assert [t["name"] for t in a["tracks"]] == [t["name"] for t in b["tracks"]]
for ta, tb in zip(a["tracks"], b["tracks"]):
    assert abs(ta.get("foot_length", 0) * 100 - tb.get("foot_length", 0)) <= 1e-9
    assert len(ta["keys"]) == len(tb["keys"]), ta["name"]
    for ka, kb in zip(ta["keys"], tb["keys"]):
        assert ka["frame"] == kb["frame"] and ka.get("phase") == kb.get("phase")
        for x, y in zip(ka["position"], kb["position"]):
            assert abs(x * 100 - y) <= 1e-6 * max(1.0, abs(y)), (ta["name"], ka, kb)
PY
}
check "--scale 100: the walk in metres, 100 times larger" scaled_like "$work/file-own.json" "$work/scaled.json"
check "--scale 100: --step-length 45 and the others in centimetres" scaled_like "$work/flags-set.json" "$work/scaled-set.json"
"$footfall" generate --terrain "$work/hills-cm.pts" --character "$chars/biped.json" \
  --start 1200,0,800 --steps 6 --out "$work/unscaled.json" 2> "$work/unscaled.err"
check "no --scale on a terrain in centimetres: the scale that fits said" grep -qF -- "(--scale; 100 from metres to centimetres)" "$work/unscaled.err"
for bad in "--scale 0" "--scale 2e6" "--scale nan" "--scale -1"; do
  # shellcheck disable=SC2086
  "$footfall" generate --terrain "$hills" --character "$chars/biped.json" $bad --out "$work/bad-scale.json" 2> "$work/bad-scale.err"
  check "$bad: exit 1" [ $? -eq 1 ]
  check "$bad: the flag named" grep -qF -- "--scale: " "$work/bad-scale.err"
  check "$bad: nothing written" [ ! -e "$work/bad-scale.json" ]
done
python3 - "$chars/biped.json" "$work/biped-long-reach.json" <<'PY'
import json, sys
c = json.load(open(sys.argv[1]))
c["reach"] = 2000
json.dump(c, open(sys.argv[2], "w"))
PY
"$footfall" generate --terrain "$hills" --character "$work/biped-long-reach.json" --scale 1e6 --out "$work/bad-scale.json" 2> "$work/bad-scale.err"
check "--scale past a character's lengths: exit 1" [ $? -eq 1 ]
check "--scale past a character's lengths: the file and the length named" grep -qF -- "--scale: $work/biped-long-reach.json: scale 1e+06 makes 'reach' 2e+09, out of a character's range" "$work/bad-scale.err"
check "--scale past a character's lengths: nothing written" [ ! -e "$work/bad-scale.json" ]
"$footfall" generate --terrain "$hills" --scene "$work/none.json" --scale 2 --out "$work/bad-scale.json" 2> "$work/bad-scale.err"
check "--scale with --scene: said" grep -qF -- "--scene excludes --scale" "$work/bad-scale.err"
"$footfall" terrain convert "$hills" --scale 2 -o "$work/bad-scale.pts" 2> "$work/bad-scale.err"
check "terrain convert --scale without --character: exit 1" [ $? -eq 1 ]
check "terrain convert --scale without --character: said" grep -qF -- "--scale requires --character" "$work/bad-scale.err"
# --unit cm: the walk JSON says it; the glTF of the walk in centimetres is written in metres,
# its nodes where the walk in metres puts them; a unit it does not know is refused.
"$footfall" generate --terrain "$work/hills-cm.pts" --character "$chars/biped.json" --scale 100 \
  --start 1200,0,800 --steps 6 --unit cm --out "$work/scaled.gltf" --out "$work/scaled-unit.json" 2>/dev/null
check "--unit cm: exit 0" [ $? -eq 0 ]
check "--unit cm: said in the walk JSON" grep -q '^{"format":"footfall-walk","version":1,"fps":24,"unit":"cm",' "$work/scaled-unit.json"
check "--unit cm: the walk's keys as without it" cmp -s <(tail -n +2 "$work/scaled.json") <(tail -n +2 "$work/scaled-unit.json")
check "no --unit: no unit in the walk JSON" bash -c "! grep -q '\"unit\"' '$work/scaled.json'"
"$footfall" generate --terrain "$hills" --character "$chars/biped.json" --start 12,0,8 --steps 6 \
  --out "$work/metres.gltf" 2>/dev/null
check "--unit cm: the glTF's nodes those of the walk in metres" python3 - "$work/metres.gltf" "$work/scaled.gltf" <<'PY'
import json, sys
a, b = (json.load(open(p))["nodes"] for p in sys.argv[1:3])
assert [n["name"] for n in a] == [n["name"] for n in b]
for na, nb in zip(a, b):
    for x, y in zip(na["translation"], nb["translation"]):
        assert abs(x - y) <= 1e-5 * max(1.0, abs(x)), (na, nb)
PY
# --unit m: the MEL keys the same numbers with the scene's linear unit set to metres while it
# keys (Maya converts), the user's put back after; a unit Maya does not know is refused before
# anything is written.
"$footfall" generate --terrain "$work/cliff.pts" --character "$chars/biped.json" --start 2.5,0,2 \
  --steps 100 --unit m --out "$work/metres.mel" 2>/dev/null
check "--unit m: exit 2 for the stopped walk" [ $? -eq 2 ]
check "--unit m: the unit set, after the user's is kept" grep -qx 'currentUnit -linear "m";' "$work/metres.mel"
check "--unit m: the user's unit put back" grep -qx 'currentUnit -linear $footfall_linear_unit;' "$work/metres.mel"
check "--unit m: the same keys" cmp -s <(grep setKeyframe "$work/all.mel") <(grep setKeyframe "$work/metres.mel")
check "no --unit: no unit set" bash -c "! grep -q 'currentUnit -linear' '$work/all.mel'"
"$footfall" generate --terrain "$work/cliff.pts" --character "$chars/biped.json" --start 2.5,0,2 \
  --steps 2 --unit furlong --out "$work/furlong.mel" --out "$work/furlong.json" 2> "$work/furlong.err"
check "--unit furlong: exit 1" [ $? -eq 1 ]
check "--unit furlong: the units named" grep -qF -- "--unit: expected mm, cm, m, km, in, ft, yd or mi" "$work/furlong.err"
check "--unit furlong: nothing written" [ ! -e "$work/furlong.mel" -a ! -e "$work/furlong.json" ]
# At UTM-like coordinates glTF's floats would move keys visibly: the writer puts the tracks under
# a root origin node, so nothing is lost and there is no warning; none near the origin either.
awk '{ printf "%.3f %s %.3f %s %s %s\n", $1 + 500000, $2, $3 + 4000000, $4, $5, $6 }' "$work/floor.pts" > "$work/utm.pts"
"$footfall" generate --terrain "$work/utm.pts" --character "$chars/hexapod.json" --steps 4 \
  --start 500001.2,0,4000001.2 --out "$work/utm.gltf" 2> "$work/utm.err"
check "glTF at UTM coordinates: written" [ -s "$work/utm.gltf" ]
check "glTF at UTM coordinates: no float rounding to report" [ ! -s "$work/utm.err" ]
check "glTF at UTM coordinates: the tracks under a root origin node" grep -q '"name": "footfall_origin"' "$work/utm.gltf"
"$footfall" generate --terrain "$work/floor.pts" --character "$chars/hexapod.json" --steps 4 \
  --start 1.2,0,1.2 --out "$work/near.gltf" 2> "$work/near.err"
check "glTF near the origin: no warning" [ ! -s "$work/near.err" ]
# A glTF refused after the walk is made (float seconds cannot tell frames near 1e9 apart) keeps
# the file of that name from before, and says so: it no longer matches the other outputs.
cp "$work/near.gltf" "$work/stale.gltf"
"$footfall" generate --terrain "$work/floor.pts" --character "$chars/hexapod.json" --steps 4 \
  --start 1.2,0,1.2 --start-frame 1e9 --out "$work/stale.json" --out "$work/stale.gltf" 2> "$work/stale.err"
check "glTF refused late: exit 1" [ $? -eq 1 ]
check "glTF refused late: the other output written" [ -s "$work/stale.json" ]
check "glTF refused late: no warning about a glTF not written" bash -c "! grep -qF 'warning: $work/stale.gltf' '$work/stale.err'"
check "glTF refused late: the old file kept and said so" bash -c "cmp -s '$work/near.gltf' '$work/stale.gltf' && grep -qF '$work/stale.gltf is left as it was, from before this walk' '$work/stale.err'"

# 4. A real DEM (Kootenai river banks, ../shared/data): its 1 m cells are coarser than every
#    shipped character's step. Unless --separation says otherwise, generate resamples it for the
#    character (a quarter of its step) around where the walk goes, so every character walks.
dem=$src/../shared/data/terrain/terrain_kootenai_1m_50x37.asc
if [ -f "$dem" ]; then
  for c in biped quadruped hexapod octopod; do
    both "dem-$c" 0 --terrain "$dem" --character "$chars/$c.json" --steps 10
    check "dem-$c: resampled for the character" grep -q "resampled for $c at a separation of" "$work/dem-$c-embedded.err"
    check "dem-$c: ten steps" [ "$(grep -o '"phase":"end"' "$work/dem-$c-embedded.json" | wc -l)" -ge 10 ]
  done
  check "dem-hexapod: cropped around the walk" grep -q "within (.*samples; --separation S resamples all of it at S" "$work/dem-hexapod-embedded.err"
  # --separation is taken as given: at the file's own metre an insect finds no foothold, and
  # the message says at what separation to resample.
  "$footfall" generate --terrain "$dem" --separation 1 --character "$chars/hexapod.json" \
    --out "$work/dem-own.json" 2> "$work/dem-own.err"
  check "dem --separation 1: stopped early (exit 2)" [ $? -eq 2 ]
  check "dem --separation 1: not resampled for the character" bash -c "! grep -q 'resampled for' '$work/dem-own.err'"
  check "dem --separation 1: advice to resample at a quarter step" grep -q "too far for this character: resample it at a separation of 0.03" "$work/dem-own.err"
  check "dem --separation 1: how to resample" grep -qF "(a mesh or height map: --separation; a point file is used as it is: sample its surface that finely)" "$work/dem-own.err"
  # Where the terrain simply ends (a goal far off it), no advice to resample.
  "$footfall" generate --terrain "$hills" --character "$chars/biped.json" --start 8,0,8 \
    --path "8,0,12 100,0,100" --out "$work/off-edge.json" 2> "$work/off-edge.err"
  check "terrain ends: the stop says so" grep -qF "the terrain ends, or rises as a wall at its bounds, before it" "$work/off-edge.err"
  check "terrain ends: no advice to resample" bash -c "! grep -q resample '$work/off-edge.err'"
  # A --start is snapped as given, as on point files: one beyond the queries' reach is refused.
  err=$("$footfall" generate --terrain "$dem" --character "$chars/biped.json" --start 1e20,0,0 --out "$work/x.json" 2>&1)
  check "dem far start: exit 1" [ $? -eq 1 ]
  check "dem far start: message" grep -qF "the start (--start) is too far from the terrain to snap" <<< "$err"
  # The same resampling as a point file, for footfalld's --data-root or a plugin's point file:
  # terrain convert --character (the whole file), then walked as points.
  "$footfall" terrain convert "$dem" --character "$chars/quadruped.json" -o "$work/dem-q.pts" > "$work/dem-q.out"
  check "convert --character: exit 0" [ $? -eq 0 ]
  check "convert --character: a quarter of the quadruped's step" grep -q "(separation 0.1)" "$work/dem-q.out"
  "$footfall" generate --terrain "$work/dem-q.pts" --character "$chars/quadruped.json" --steps 10 \
    --out "$work/dem-q.json" 2> /dev/null
  check "convert --character: the quadruped walks the point file" [ $? -eq 0 ]
  # A --start straight below the ground (y = 0 under banks at 537 m) starts on the ground above
  # it, biped or multiped, on the height map or its points, embedded or over RPC: the nearest
  # sample was the lowest bank nearby, 17 m aside, and a multiped's note said 10 m.
  for c in biped quadruped; do
    for t in "$dem" "$work/dem-q.pts"; do
      name=below-$c-$(basename "$t" | tr . _)
      both "$name" 0 --terrain "$t" --character "$chars/$c.json" --start 8,0,8 --steps 3
      check "$name: no note of a start off the terrain" bash -c "! grep -q 'snaps to the terrain' '$work/$name-embedded.err'"
      check "$name: the body starts above (8, 8)" python3 -c '
import json, math, sys
w = json.load(open(sys.argv[1]))
step = json.load(open(sys.argv[2]))["step_length"]
x, y, z = next(t for t in w["tracks"] if t["kind"] == "body")["keys"][0]["position"]
sys.exit(not (math.hypot(x - 8, z - 8) < step and y > 537))' "$work/$name-embedded.json" "$chars/$c.json"
    done
  done
  # A scene on the DEM resamples it for each character, saying so: with --progress each such
  # line is a line of its own (they were written after the bar's "25%").
  cat > "$work/scene/dem-scene.json" <<JSON
{"format": "footfall-scene", "version": 1, "characters": [
 {"character_file": "biped.json", "start": [10, 0, 10], "steps": 2},
 {"character_file": "$chars/quadruped.json", "start": [20, 0, 10], "steps": 2}]}
JSON
  "$footfall" generate --terrain "$dem" --scene "$work/scene/dem-scene.json" --progress \
    --out "$work/dem-scene.json" 2> "$work/dem-scene.err"
  check "dem scene with --progress: exit 0" [ $? -eq 0 ]
  check "dem scene with --progress: two resampling lines" [ "$(grep -c 'resampled for' "$work/dem-scene.err")" -eq 2 ]
  check "dem scene with --progress: each on a line of its own" [ "$(grep -c '^footfall generate: .* resampled for' "$work/dem-scene.err")" -eq 2 ]
  err=$("$footfall" terrain convert "$dem" --character "$chars/quadruped.json" --separation 1 -o "$work/x.pts" 2>&1)
  check "convert --character --separation: exit 1" [ $? -eq 1 ]
  check "convert --character --separation: message" grep -qF "give --separation or --character, not both" <<< "$err"
elif [ -n "${CI:-}" ]; then
  check "shared data present in CI ($dem)" false
else
  echo "skipped the DEM walks: $dem is absent (../shared is not beside this checkout)"
fi

# 5. Bad flags: a message naming the flag, exit 1, no output.
bad() {  # bad NAME EXPECTED_MESSAGE ARGS...: exit 1
  local name=$1 want=$2; shift 2
  local err
  err=$("$footfall" generate "$@" 2>&1 >/dev/null)
  local rc=$?
  check "$name: exit 1" [ "$rc" -eq 1 ]
  check "$name: message '$want'" grep -qF -- "$want" <<< "$err"
}
bad start "--start '1,2': expected X,Y,Z" --terrain "$hills" --character "$chars/biped.json" --start 1,2 --out "$work/x.json"
bad start-comma "--start '8,0,12,': expected X,Y,Z" --terrain "$hills" --character "$chars/biped.json" --start 8,0,12, --out "$work/x.json"
bad heading "--heading 'a,0,1': 'a' is not a finite number" --terrain "$hills" --character "$chars/biped.json" --heading a,0,1 --out "$work/x.json"
bad heading-bytes "--heading '1,0?,1': '0?' (bytes 30 01) is not a finite number" --terrain "$hills" --character "$chars/biped.json" --heading $'1,0\x01,1' --out "$work/x.json"
bad path "--path '3,4': expected X,Y,Z" --terrain "$hills" --character "$chars/biped.json" --path "1,0,1 3,4" --out "$work/x.json"
bad path-spaces "each waypoint X,Y,Z without spaces" --terrain "$hills" --character "$chars/biped.json" --path "20, 0, 25" --out "$work/x.json"
bad extension "unsupported output extension" --terrain "$hills" --character "$chars/biped.json" --out "$work/x.csv"
bad character "$work/none.json: cannot open character file" --terrain "$hills" --character "$work/none.json" --out "$work/x.json"
printf '{"format": "footfall-character", "version": 1, "feet": []}' > "$work/bad.json"
bad character-content "$work/bad.json: 'feet': expected a non-empty array" --terrain "$hills" --character "$work/bad.json" --out "$work/x.json"
# A field of the wrong JSON type is a message, not an abort.
sed 's/"footfall-character"/5/' "$chars/biped.json" > "$work/format5.json"
bad character-type "$work/format5.json: 'format' must be a string, found number" --terrain "$hills" --character "$work/format5.json" --out "$work/x.json"
sed 's/"version": 1/"version": 4294967297/' "$chars/biped.json" > "$work/version.json"
bad character-version "$work/version.json: 'version' 4294967297 is not supported" --terrain "$hills" --character "$work/version.json" --out "$work/x.json"
bad zero-heading "--heading '0,0,0': expected a direction DX,DY,DZ of non-zero length" --terrain "$hills" --character "$chars/biped.json" --heading 0,0,0 --out "$work/x.json"
# Refused before the terrain is read (a missing file would be named first otherwise).
bad zero-up "--up '0,0,-0': expected a direction DX,DY,DZ of non-zero length" --terrain "$work/none.pts" --character "$chars/biped.json" --up 0,0,-0 --out "$work/x.json"
# A waypoint past the terrain queries' reach: its squared distance overflowed and the walk
# turned away from it.
bad far-waypoint "path waypoint 2 (20, 0, 1e+155) is not a finite point with each coordinate within +-1e+15" --terrain "$hills" --character "$chars/biped.json" --path "20,0,30 20,0,1e155" --out "$work/x.json"
bad empty-path "--path: expected at least one waypoint X,Y,Z" --terrain "$hills" --character "$chars/biped.json" --path " " --out "$work/x.json"
bad empty-heading "--heading: expected DX,DY,DZ" --terrain "$hills" --character "$chars/biped.json" --heading "" --out "$work/x.json"
bad heading-up "the heading (0.0000, 1.0000, 0.0000) is along the up (0.0000, 1.0000, 0.0000) where the character starts" --terrain "$hills" --character "$chars/biped.json" --heading 0,1,0 --out "$work/x.json"
bad gltf-negative-frame "--out $work/neg.gltf: glTF animation times must be >= 0, and --start-frame is -100" --terrain "$hills" --character "$chars/biped.json" --start-frame -100 --out "$work/neg.json" --out "$work/neg.gltf"
check "gltf-negative-frame: nothing written" [ ! -e "$work/neg.json" ]
# A mesh resampled for the character is checked against the other terrain flags first (a
# --server-terrain beside it was ignored, and a bad --server said only after the resampling).
printf 'v -3 0 -3\nv 3 0 -3\nv 3 0 3\nv -3 0 3\nf 1 4 3 2\n' > "$work/flat-mesh.obj"
bad mesh-and-server-terrain "give exactly one of --terrain FILE or --server-terrain PATH" --terrain "$work/flat-mesh.obj" --server-terrain elsewhere.obj --character "$chars/biped.json" --out "$work/x.json"
bad mesh-bad-server "'nocolon': expected HOST:PORT" --terrain "$work/flat-mesh.obj" --server nocolon --character "$chars/biped.json" --out "$work/x.json"
# Whole numbers with leading zeros are decimal (CLI11 read "010" as octal 8 and refused "08").
for pair in "010 10" "08 8"; do
  read -r zeros plain <<< "$pair"
  "$footfall" generate --terrain "$hills" --character "$chars/biped.json" --steps "$zeros" --out "$work/steps-$zeros.json" 2> /dev/null
  "$footfall" generate --terrain "$hills" --character "$chars/biped.json" --steps "$plain" --out "$work/steps-$plain.json" 2> /dev/null
  check "--steps $zeros is --steps $plain" cmp -s "$work/steps-$zeros.json" "$work/steps-$plain.json"
  "$footfall" terrain make rocks --size "$zeros" --seed "$zeros" -o "$work/rocks-$zeros.pts" > /dev/null 2>&1
  "$footfall" terrain make rocks --size "$plain" --seed "$plain" -o "$work/rocks-$plain.pts" > /dev/null 2>&1
  check "terrain make --size $zeros --seed $zeros is --size $plain --seed $plain" cmp -s "$work/rocks-$zeros.pts" "$work/rocks-$plain.pts"
done
# In a scene, --start-frame is the default of the characters that give none: a negative one
# refuses glTF only when a character takes it.
cat > "$work/scene/framed.json" <<JSON
{"format": "footfall-scene", "version": 1,
 "characters": [
  {"name": "a", "character_file": "biped.json", "start": [0.6, 0, 0.4], "steps": 2, "start_frame": 5},
  {"name": "b", "character_file": "biped.json", "start": [1.8, 0, 0.4], "steps": 2, "start_frame": 0}
 ]}
JSON
"$footfall" generate --terrain "$work/floor.pts" --scene "$work/scene/framed.json" --start-frame -3 \
  --out "$work/framed.gltf" 2> /dev/null
check "scene gltf: a negative --start-frame no character takes is no matter" [ -s "$work/framed.gltf" ]
sed 's/, "start_frame": 0//' "$work/scene/framed.json" > "$work/scene/unframed.json"
bad scene-gltf-negative-frame "--out $work/unframed.gltf: glTF animation times must be >= 0, and b starts at frame -3 (--start-frame)" --terrain "$work/floor.pts" --scene "$work/scene/unframed.json" --start-frame -3 --out "$work/unframed.gltf"
bad far-start "the start (--start) is too far from the terrain to snap" --terrain "$hills" --character "$chars/biped.json" --start 1e20,0,0 --out "$work/x.json"
bad steps-fraction "--steps: '1.5' is not a whole number from 0 to 1000000" --terrain "$hills" --character "$chars/biped.json" --steps 1.5 --out "$work/x.json"
bad crowd-fraction "--crowd: '1.5' is not a whole number from 1 to 1000000" --terrain "$hills" --character "$chars/biped.json" --crowd 1.5 --out "$work/x.json"
bad crowd-0 "--crowd: '0' is not a whole number from 1 to 1000000" --terrain "$hills" --character "$chars/biped.json" --crowd 0 --out "$work/x.json"
bad threads-fraction "--threads: '2.5' is not a whole number from 1 to 256" --terrain "$hills" --character "$chars/biped.json" --threads 2.5 --out "$work/x.json"
bad heading-up-flag "it gives no clear direction on the ground; give a heading along the ground (--heading)" --terrain "$hills" --character "$chars/biped.json" --heading 0,1,0 --out "$work/x.json"
# A scene's character: its start, heading and up named by the scene file and field (--scene
# refuses those flags).
scene_with() {  # scene_with FIELDS: a scene of one biped with these extra fields
  printf '{"format": "footfall-scene", "version": 1, "characters": [{"name": "biped1", "character_file": "%s", %s}]}\n' \
    "$chars/biped.json" "$1" > "$work/bad-scene.json"
}
scene_with '"heading": [0, 1, 0]'
bad scene-heading-up "biped1: the heading (0.0000, 1.0000, 0.0000) is along the up (0.0000, 1.0000, 0.0000) where the character starts (within 10 deg of it): it gives no clear direction on the ground; give a heading along the ground ($work/bad-scene.json: characters[0]: 'heading')" --terrain "$hills" --scene "$work/bad-scene.json" --out "$work/x.json"
scene_with '"heading": [0, 0, 0]'
bad scene-zero-heading "biped1: $work/bad-scene.json: characters[0]: 'heading' must be a non-zero finite vector" --terrain "$hills" --scene "$work/bad-scene.json" --out "$work/x.json"
scene_with '"up": [0, 0, 0]'
bad scene-zero-up "biped1: $work/bad-scene.json: characters[0]: 'up' must be a non-zero finite vector" --terrain "$hills" --scene "$work/bad-scene.json" --out "$work/x.json"
scene_with '"start": [1e300, 0, 0]'
bad scene-far-start "$work/bad-scene.json: characters[0]: 'start' is too far from the terrain to snap (queries reach 1e15 from it) (line " --terrain "$hills" --scene "$work/bad-scene.json" --out "$work/x.json"
# Numbers: finite, within readable bounds, one check for every float flag.
bad fps-tiny "--fps: '1e-300' is not a finite number from 0.001 to 1e+06" --terrain "$hills" --character "$chars/biped.json" --fps 1e-300 --out "$work/x.json"
bad start-frame "--start-frame: '-1e300' is not a finite number from -1e+09 to 1e+09" --terrain "$hills" --character "$chars/biped.json" --start-frame -1e300 --out "$work/x.json"
bad crowd-spacing "--crowd-spacing: 'nan' is not a finite number > 0 and <= 1e+06" --terrain "$hills" --character "$chars/biped.json" --crowd-spacing nan --out "$work/x.json"
bad seed-negative "--seed: '-1' is not a whole number from 0 to 18446744073709551615" --terrain "$hills" --character "$chars/biped.json" --seed -1 --out "$work/x.json"
bad crowd-spacing-0 "--crowd-spacing: '0' is not a finite number > 0 and <= 1e+06" --terrain "$hills" --character "$chars/biped.json" --crowd-spacing 0 --out "$work/x.json"
# Two outputs that are one file (by a link, or the same path spelt twice) are refused before
# anything is generated.
ln -sf "$work/alias-target.json" "$work/alias.mel"
bad out-aliased "--out $work/alias-target.json and --out $work/alias.mel are the same file" --terrain "$hills" --character "$chars/biped.json" --out "$work/alias-target.json" --out "$work/alias.mel"
bad out-twice "are the same file" --terrain "$hills" --character "$chars/biped.json" --out "$work/twice.json" --out "$work/./twice.json"
check "out-twice: nothing written" [ ! -e "$work/twice.json" ]
# The walk never overwrites what it is made from (the same file by another name too).
cp "$chars/biped.json" "$work/me.json"
bad out-is-character "--out $work/../$(basename "$work")/me.json is the character file this walk reads" --terrain "$hills" --character "$work/me.json" --out "$work/../$(basename "$work")/me.json"
check "out-is-character: the character file is intact" cmp -s "$chars/biped.json" "$work/me.json"
awk 'NR <= 400' "$hills" > "$work/t.txt"
cp "$work/t.txt" "$work/t-copy.txt"
ln -s "$work/t.txt" "$work/link.json"
bad out-is-terrain "--out $work/link.json is the terrain file this walk reads" --terrain "$work/t.txt" --character "$chars/biped.json" --out "$work/t.json" --out "$work/link.json"
check "out-is-terrain: the terrain file is intact" cmp -s "$work/t.txt" "$work/t-copy.txt"
check "bad flags: no output written" [ ! -e "$work/x.json" ]

stop_server

# 6. A mesh under footfalld's data root, read by the server with the loading flags given and,
#    without --separation, at a quarter of the character's step: the walk is the one on the same
#    file resampled locally at that separation (0.175 for the biped), crease angle included.
mkdir -p "$work/root"
printf 'v 0 0 0\nv 4 0 0\nv 4 0.7 4\nv 0 0.7 4\nf 1 3 2\nf 1 4 3\n' > "$work/root/ramp.obj"
start_server "$footfalld" --data-root "$work/root"
"$footfall" generate --server-terrain ramp.obj --server "$server" --crease-angle 30 --seed 3 \
  --character "$chars/biped.json" --start 2,0.1,0.5 --steps 6 --out "$work/server-ramp.json" 2> "$work/server-ramp.err"
check "server-terrain mesh: exit 0" [ $? -eq 0 ]
check "server-terrain mesh: the server's resampling said" grep -qE "footfalld loaded ramp.obj: [0-9]+ samples at separation 0.175$" "$work/server-ramp.err"
"$footfall" generate --terrain "$work/root/ramp.obj" --separation 0.175 --crease-angle 30 --seed 3 \
  --character "$chars/biped.json" --start 2,0.1,0.5 --steps 6 --out "$work/local-ramp.json" 2> /dev/null
check "server-terrain mesh: the walk on the file resampled at a quarter step" cmp -s "$work/server-ramp.json" "$work/local-ramp.json"
"$footfall" generate --terrain "$work/root/ramp.obj" --character "$chars/biped.json" --start 2,0.1,0.5 \
  --steps 2 --out "$work/local-ramp2.json" 2> "$work/local-ramp2.err"
check "local mesh sampled whole: no word of 'all of it'" grep -qE "resampled for biped at a separation of 0.175 \(its own spacing [0-9.]+, a quarter of the step 0.175\): [0-9]+ samples; --separation S resamples it at S$" "$work/local-ramp2.err"
"$footfall" generate --server-terrain ramp.obj --server "$server" --seed 4 \
  --character "$chars/biped.json" --start 2,0.1,0.5 --steps 6 --out "$work/server-ramp4.json" 2> /dev/null
check "server-terrain mesh: the seed reaches the server" bash -c "! cmp -s '$work/server-ramp.json' '$work/server-ramp4.json'"
stop_server
# 7. A scene of 400 one-step bipeds takes memory in proportion to its keys (each character's
#    keys once took a huge page of their own, backed whole: 2 MiB each, about 850 MB here).
python3 - "$work/many.scene.json" "$chars/biped.json" <<'PY'
import json, sys
chars = [{"character_file": sys.argv[2], "name": "w%d" % i, "steps": 1,
          "start": [2 + 1.8 * (i % 20), 0, 2 + 1.8 * (i // 20)]} for i in range(400)]
json.dump({"format": "footfall-scene", "version": 1, "characters": chars}, open(sys.argv[1], "w"))
PY
peak_kib=$(python3 -c 'import resource, subprocess, sys
r = subprocess.run(sys.argv[1:], stderr=subprocess.DEVNULL)
print(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss if r.returncode == 0 else -1)' \
  "$footfall" generate --terrain "$hills" --scene "$work/many.scene.json" --out "$work/many.json")
check "400-character scene: exit 0" [ "$peak_kib" -ge 0 ]
check "400-character scene: peak memory under 200 MB ($peak_kib KiB)" [ "$peak_kib" -lt 204800 ]
check "400-character scene: every character walked" [ "$(grep -o '"name":"body"' "$work/many.json" | wc -l)" -eq 400 ]
# 8. A walk whose keys alone need more memory than the process may use is refused before the
#    terrain loads (a million characters x a million steps grew until the system stopped it).
err=$(timeout 20 "$footfall" generate --terrain "$hills" --character "$chars/hexapod.json" \
  --steps 1000000 --crowd 1000000 --out "$work/huge.json" 2>&1)
check "keys beyond memory: exit 1" [ $? -eq 1 ]
check "keys beyond memory: message" grep -qE "^footfall generate: 1000000 characters x 1000000 steps make about 1e\+13 keys, 6.8e\+05 GB, more than the [0-9.e+]+ GB of memory this process may use; nothing was generated" <<< "$err"
err=$( (ulimit -v 2000000; timeout 20 "$footfall" generate --terrain "$hills" --character "$chars/hexapod.json" \
  --steps 100000 --crowd 1000 --out "$work/huge.json") 2>&1)
check "keys beyond a 2 GB limit: exit 1" [ $? -eq 1 ]
check "keys beyond a 2 GB limit: message" grep -qF "1000 characters x 100000 steps make about 1e+09 keys, 68 GB, more than the 2.05 GB of memory this process may use" <<< "$err"
printf '{"format":"footfall-scene","version":1,"characters":[{"character_file":"%s","steps":1000000,"crowd":1000000},{"character_file":"%s","steps":5}]}' \
  "$chars/hexapod.json" "$chars/biped.json" > "$work/huge.scene.json"
err=$(timeout 20 "$footfall" generate --terrain "$hills" --scene "$work/huge.scene.json" --out "$work/huge.json" 2>&1)
check "scene keys beyond memory: exit 1" [ $? -eq 1 ]
check "scene keys beyond memory: message" grep -qE "^footfall generate: the scene's characters make about 1e\+13 keys" <<< "$err"
check "keys beyond memory: nothing written" [ ! -e "$work/huge.json" ]
# 9. A walk whose footfalld dies mid-walk exits 1, not 2 (a stop at the terrain), says so, and
#    writes its keys so far with the failed call as its stop (a crowd's stop named only a
#    character that had stopped earlier at the terrain's edge).
awk 'BEGIN { for (k = 0; k <= 400; k++) for (i = 0; i <= 400; i++) printf "%.1f 0 %.1f 0 1 0\n", i * 0.1, k * 0.1 }' > "$work/flat40.pts"
loop=""
for _ in $(seq 12); do loop="$loop 35,0,5 35,0,35 5,0,35 5,0,5"; done
start_server "$footfalld"
"$footfall" generate --server "$server" --terrain "$work/flat40.pts" --character "$chars/biped.json" \
  --start 5,0,5 --path "${loop# }" --crowd 16 --steps 4000 --progress --out "$work/died.json" 2> "$work/died.err" &
walk_pid=$!
# Killed once the walk is under way: its progress bar past 0%.
for _ in $(seq 600); do
  tr '\r' '\n' < "$work/died.err" | grep -qE '\] +[1-9][0-9]?%' && break
  sleep 0.05
done
kill -9 "$server_pid"; wait "$server_pid" 2>/dev/null; server_pid=""
wait "$walk_pid"
check "server dies mid-walk: exit 1" [ $? -eq 1 ]
check "server dies mid-walk: said" grep -qF "footfall generate: footfalld failed mid-walk (not the terrain): the keys up to its failure are written; exit status 1" "$work/died.err"
# (Its bar was filled to 100% as the failure stopped every character.)
check "server dies mid-walk: the progress bar left short of 100%" bash -c \
  'tr "\r" "\n" < "$1" | grep -E "\] +[0-9]+%" | tail -1 | grep -qvF "100%"' _ "$work/died.err"
check "server dies mid-walk: the keys so far written, the failed call their stop" python3 -c '
import json, sys
w = json.load(open(sys.argv[1]))
sys.exit(not ("footfalld at 127.0.0.1:" in w["stopped"] and len(w["tracks"]) == 48
              and all(len(t["keys"]) > 3 for t in w["tracks"])))' "$work/died.json"
# 11. A dead end: a body that settles within half a step of a spot stops a window (100 steps)
#     after it settled. An 8-legged spider that cannot climb a bare wall mills at its foot from
#     about step 20; fixed windows stopped it at step 201, and a 150-step walk ended "complete".
#     (It climbs the wall, or stops beyond reach, from other starts or spacings: the test needs
#     the milling, which this floor spacing of 0.5/62 gives.)
awk 'BEGIN { for (i = 0; i <= 100; i++) { x = i * 0.008
  for (k = 0; k < 62; k++) printf "%.9g 0 %.9g 0 1 0\n", x, -0.5 + 0.5 * k / 62
  for (k = 1; k <= 100; k++) printf "%.9g %.9g 0 0 0 -1\n", x, k * 0.008 } }' > "$work/bare_wall.pts"
cat > "$work/spider.json" <<'JSON'
{"format": "footfall-character", "version": 1, "name": "spider",
 "feet": [{"name": "L1", "rest": [0.1, 0, 0.2]}, {"name": "L2", "rest": [0.22, 0, 0.07]},
          {"name": "L3", "rest": [0.16, 0, -0.06]}, {"name": "L4", "rest": [0.09, 0, -0.18]},
          {"name": "R1", "rest": [-0.1, 0, 0.2]}, {"name": "R2", "rest": [-0.22, 0, 0.07]},
          {"name": "R3", "rest": [-0.16, 0, -0.06]}, {"name": "R4", "rest": [-0.09, 0, -0.18]}],
 "gait": [["L1", "R2", "L3", "R4"], ["R1", "L2", "R3", "L4"]],
 "pairs": [["L1", "R1"], ["L2", "R2"], ["L3", "R3"], ["L4", "R4"]],
 "step_length": 0.1, "step_height": 0.04, "body_height": 0.04, "frames_per_step": 7,
 "align_to_normal": true, "reach": 0.36, "max_slope_deg": 100, "max_rise": 0.07,
 "slope_threshold_deg": 25, "slope_step_scale": 0.7}
JSON
"$footfall" generate --terrain "$work/bare_wall.pts" --character "$work/spider.json" \
  --start 0.4,0,-0.35 --steps 150 --out "$work/dead_end.json" 2> "$work/dead_end.err"
check "dead end: exit 2" [ $? -eq 2 ]
check "dead end: said" grep -qF "steps (a dead end)" "$work/dead_end.err"
check "dead end: stopped a window after the body settled" python3 -c '
import json, math, sys
w = json.load(open(sys.argv[1]))
body = next(t for t in w["tracks"] if t["kind"] == "body")["keys"]  # one key a step
# Settled: from the first step whose body stays within a step (the half-step ball across,
# 0.1) of where it stopped.
near = [math.dist(k["position"], body[-1]["position"]) < 0.1 for k in body]
settled = len(near) - next(i for i, n in enumerate(reversed(near)) if not n)
stayed = len(body) - settled
print("settled at step", settled, "stayed", stayed, "steps", file=sys.stderr)
sys.exit(not (settled < 60 and 95 <= stayed <= 105))' "$work/dead_end.json"
# 10. `--out -` writes the walk JSON to standard output, the bytes a .json file gets, beside
#     file outputs and after them; messages stay on stderr. Twice is refused; standard output
#     that cannot be written fails the command.
walk=(--terrain "$hills" --character "$chars/quadruped.json" --steps 4)
"$footfall" generate "${walk[@]}" --out "$work/file.json" 2> /dev/null
"$footfall" generate "${walk[@]}" --out - --out "$work/beside.gltf" > "$work/stdout.json" 2> "$work/stdout.err"
check "--out -: exit 0" [ $? -eq 0 ]
check "--out -: the .json file's bytes" cmp -s "$work/stdout.json" "$work/file.json"
check "--out -: the other output written too" [ -s "$work/beside.gltf" ]
check "--out -: no file named -" [ ! -e ./- ]
"$footfall" generate "${walk[@]}" --out - --out - > "$work/twice.json" 2> "$work/twice.err"
check "--out - twice: exit 1" [ $? -eq 1 ]
check "--out - twice: said" grep -qF "footfall generate: --out - is given twice" "$work/twice.err"
check "--out - twice: nothing generated" [ ! -s "$work/twice.json" ]
"$footfall" generate "${walk[@]}" --out - > /dev/full 2> "$work/full.err"
check "--out - on a full disk: exit 1" [ $? -eq 1 ]
check "--out - on a full disk: said" grep -qF "footfall generate: --out -: cannot write the walk JSON to standard output: No space left on device" "$work/full.err"

# glTF is written first, whatever the order of --out: JSON and MEL written on several threads
# before it left the allocator's per-thread pools counted as used, and a glTF that fits alone
# under a memory limit was refused after a .json. At the lowest limit (of these) where the glTF
# alone is written, it is written after a .json and a .mel too.
"$footfall" terrain make flat --size 40 --spacing 0.1 -o "$work/flat40.pts" > /dev/null
crowd=(generate --terrain "$work/flat40.pts" --character "$chars/quadruped.json" --steps 50
       --crowd 1000 --crowd-spacing 0.8 --start 20,0,5 --threads 2)
limit=""
for kb in 160000 180000 200000 220000 260000 300000 400000; do
  rm -f "$work/m.gltf"
  (ulimit -v $kb; "$footfall" "${crowd[@]}" --out "$work/m.gltf" > /dev/null 2>&1)
  if [ -s "$work/m.gltf" ]; then limit=$kb; break; fi
done
check "glTF under a memory limit: a limit found where it is written" [ -n "$limit" ]
rm -f "$work/m.gltf" "$work/m.json" "$work/m.mel"
(ulimit -v ${limit:-400000}; "$footfall" "${crowd[@]}" --out "$work/m.json" --out "$work/m.mel" --out "$work/m.gltf" > /dev/null 2> "$work/m.err")
check "glTF after .json and .mel under that limit: written" [ -s "$work/m.gltf" ]
check "glTF after .json and .mel under that limit: the JSON too" [ -s "$work/m.json" ]
check "glTF after .json and .mel under that limit: the MEL too" [ -s "$work/m.mel" ]
finish
