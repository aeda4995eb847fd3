#!/usr/bin/env bash
# `footfall generate` with several --out replaces them as a set: Ctrl-C while they are written
# leaves every older file as it was (and no temporary file), never some new and some old; a
# run that finishes replaces them all.
# Usage: generate_interrupt_test.sh FOOTFALL SOURCE_DIR
set -u
footfall=$1
src=$2
source "$(dirname "$0")/../support/cli_checks.sh"
walk=(--terrain "$src/data/terrain/hills.pts" --character "$src/data/characters/biped.json")

"$footfall" generate "${walk[@]}" --steps 4 --out "$work/walk.json" --out "$work/walk.mel" 2> /dev/null
cp "$work/walk.json" "$work/old.json"
cp "$work/walk.mel" "$work/old.mel"

# A FIFO among the outputs is written in place once a process reads it (waited for up to 5 s):
# the JSON before it is written and waits; Ctrl-C then. (A script's background job starts with
# SIGINT ignored, which footfall keeps, as under nohup: a terminal's Ctrl-C finds it at its
# default, as env --default-signal sets it here.)
mkfifo "$work/pipe.json"
env --default-signal=INT "$footfall" generate "${walk[@]}" --steps 8 --out "$work/walk.json" --out "$work/pipe.json" \
  --out "$work/walk.mel" 2> "$work/interrupted.err" &
pid=$!
for _ in $(seq 100); do
  compgen -G "$work/.walk.json.*" > /dev/null && break
  sleep 0.05
done
check "the JSON waits in its temporary file while the FIFO has no reader" \
  bash -c "compgen -G '$work/.walk.json.*' > /dev/null"
kill -INT "$pid"
wait "$pid"
rc=$?
check "Ctrl-C ends the run by the signal (exit $rc)" [ "$rc" -eq 130 ]
check "the older JSON is as it was" cmp -s "$work/walk.json" "$work/old.json"
check "the older MEL is as it was" cmp -s "$work/walk.mel" "$work/old.mel"
check "no temporary file is left" bash -c "! compgen -G '$work/.walk*' > /dev/null"

# With a reader, the run replaces both files (a walk twice as long as the older one).
cat "$work/pipe.json" > "$work/piped.json" &
"$footfall" generate "${walk[@]}" --steps 8 --out "$work/walk.json" --out "$work/pipe.json" \
  --out "$work/walk.mel" 2> /dev/null
check "a finished run exits 0" [ $? -eq 0 ]
wait
check "the JSON is replaced" bash -c "! cmp -s '$work/walk.json' '$work/old.json'"
check "the MEL is replaced" bash -c "! cmp -s '$work/walk.mel' '$work/old.mel'"
check "the FIFO got the same walk as the JSON" cmp -s "$work/walk.json" "$work/piped.json"
finish
