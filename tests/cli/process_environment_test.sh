#!/usr/bin/env bash
# footfall and footfalld in the environments a parent process may give them: standard streams
# closed, signals ignored (nohup, background jobs of scripts), too little memory to start a
# thread, a TMPDIR that cannot be written, a data root whose name is not UTF-8.
# Usage: process_environment_test.sh FOOTFALL FOOTFALLD SOURCE_DIR
set -u
footfall=$1
footfalld=$2
source_dir=$3
source "$(dirname "$0")/../support/cli_checks.sh"
hills=$source_dir/data/terrain/hills.pts
biped=$source_dir/data/characters/biped.json

# 1. footfalld started with stdin, stdout and stderr closed serves its clients: its log lines
#    went into the first client's connection, which hung for 300 s.
"$footfalld" --listen 127.0.0.1:0 --port-file "$work/port1" --no-rpcbind 0<&- 1>&- 2>&- &
server_pid=$!
port=$(wait_for_port "$work/port1")
for client in 1 2; do
  answer=$(echo "snap 10 0 10" | timeout 30 "$footfall" query --terrain "$hills" \
    --server "127.0.0.1:$port" --timeout 5 2> "$work/err.txt")
  check "closed streams: client $client answered (exit $?)" grep -q '"found":true' <<< "$answer"
done
kill "$server_pid"; wait "$server_pid" 2>/dev/null; server_pid=""

# 2. SIGHUP and SIGINT ignored when footfalld started (nohup, a script's background job) stay
#    ignored: it kept serving nobody after a hangup.
(trap '' HUP INT; exec "$footfalld" --listen 127.0.0.1:0 --port-file "$work/port2" \
  --no-rpcbind 2> "$work/server2.log") &
server_pid=$!
port=$(wait_for_port "$work/port2")
kill -HUP "$server_pid"; kill -INT "$server_pid"; sleep 0.3
answer=$(echo "snap 10 0 10" | timeout 30 "$footfall" query --terrain "$hills" \
  --server "127.0.0.1:$port" --timeout 5 2>&1)
check "footfalld under nohup: serves after SIGHUP and SIGINT" grep -q '"found":true' <<< "$answer"
kill -TERM "$server_pid"; wait "$server_pid"
check "footfalld under nohup: SIGTERM still stops it (exit 0)" [ $? -eq 0 ]
server_pid=""

# 3. footfall generate under nohup finishes its walk after a hangup (it died, writing nothing).
#    Its output is a FIFO, written once a reader opens it: the hangup comes while it waits.
mkfifo "$work/fifo.json"
(trap '' HUP; exec "$footfall" generate --terrain "$hills" --character "$biped" --steps 4 \
  --out "$work/fifo.json" 2> "$work/gen.err") &
gen_pid=$!
sleep 0.5
check "generate under nohup: still waiting for its reader" kill -0 "$gen_pid"
kill -HUP "$gen_pid"; sleep 0.3
check "generate under nohup: alive after SIGHUP" kill -0 "$gen_pid"
timeout 20 cat "$work/fifo.json" > "$work/walk.json"
wait "$gen_pid"
check "generate under nohup: exit 0" [ $? -eq 0 ]
check "generate under nohup: the whole walk written" \
  python3 -c 'import json, sys; assert json.load(open(sys.argv[1]))["tracks"]' "$work/walk.json"
# Not ignored, SIGHUP still ends it as before, leaving no temporary file.
"$footfall" generate --terrain "$hills" --character "$biped" --steps 4 \
  --out "$work/fifo.json" 2> "$work/gen.err" &
gen_pid=$!
sleep 0.5; kill -HUP "$gen_pid"; wait "$gen_pid"
check "generate: SIGHUP ends it when not ignored (exit 129)" [ $? -eq 129 ]

# 4. Too little memory to start a thread: a message and exit 1, never an abort.
(ulimit -v 20000; "$footfalld" --listen 127.0.0.1:0 --no-rpcbind) > /dev/null 2> "$work/err.txt"
check "no thread: footfalld exits 1" [ $? -eq 1 ]
check "no thread: footfalld says why" grep -q "a thread could not start" "$work/err.txt"
# Limits where some of its threads start and a later one cannot (the load queue's third
# thread aborted it: "terminate called without an active exception"): exit 1 with the
# message, or, where all start, it serves until SIGTERM and exits 0.
for limit in $(seq 24000 4000 60000); do
  (ulimit -v $limit; timeout --preserve-status 1 "$footfalld" --listen 127.0.0.1:0 --no-rpcbind) \
    > /dev/null 2> "$work/err.txt"
  status=$?
  check "ulimit -v $limit: footfalld exits 0 or 1, never aborts (exit $status)" \
    [ $status -eq 0 -o $status -eq 1 ]
  [ $status -eq 1 ] && check "ulimit -v $limit: footfalld says why" \
    grep -q "a thread could not start" "$work/err.txt"
done
(ulimit -v 20000; "$footfall" --version) > "$work/out.txt" 2> "$work/err.txt"
check "no thread: footfall --version works" grep -qx "footfall 0.1.0" "$work/out.txt"
for limit in 20000 40000 60000; do
  (ulimit -v $limit; "$footfall" generate --terrain "$hills" --character "$biped" --steps 4 \
    --out "$work/small.json") > /dev/null 2> "$work/err.txt"
  status=$?
  check "ulimit -v $limit: generate exits 0 or 1, never aborts (exit $status)" \
    [ $status -eq 0 -o $status -eq 1 ]
  check "ulimit -v $limit: no uncaught exception" bash -c '! grep -q "terminate called" "$1"' _ "$work/err.txt"
done

# 5. A TMPDIR footfalld cannot write: said at start, and each server-side load names it.
mkdir -p "$work/root"
cp "$hills" "$work/root/hills.pts"
TMPDIR=$work/missing "$footfalld" --listen 127.0.0.1:0 --port-file "$work/port5" --no-rpcbind \
  --data-root "$work/root" 2> "$work/server5.log" &
server_pid=$!
port=$(wait_for_port "$work/port5")
check "TMPDIR missing: a warning at start" \
  grep -q "warning: server-side loads will fail: cannot make a private directory to read it from in $work/missing: No such file or directory" "$work/server5.log"
echo "snap 10 0 10" | "$footfall" query --server-terrain hills.pts --server "127.0.0.1:$port" \
  > /dev/null 2> "$work/err.txt"
check "TMPDIR missing: the load's error names the folder and why" \
  grep -q "in $work/missing: No such file or directory" "$work/err.txt"
kill "$server_pid"; wait "$server_pid" 2>/dev/null; server_pid=""

# 6. A data root whose name is not UTF-8 is logged escaped (the log stays UTF-8).
odd=$work/$'root\xff'
mkdir -p "$odd"
"$footfalld" --listen 127.0.0.1:0 --port-file "$work/port6" --no-rpcbind --data-root "$odd" \
  2> "$work/server6.log" &
server_pid=$!
wait_for_port "$work/port6" > /dev/null
check "data root logged escaped" grep -qF 'data root '"$work"'/root\xff' "$work/server6.log"
check "the log is UTF-8" iconv -f UTF-8 -t UTF-8 "$work/server6.log" -o /dev/null
kill "$server_pid"; wait "$server_pid" 2>/dev/null; server_pid=""

# 7. Output that cannot be written fails the command (it exited 0 with nothing written).
for command in "--version" "terrain info $hills" \
    "bench --terrain $hills --queries 1000 --min-time 0.01 --json"; do
  $footfall $command > /dev/full 2> "$work/err.txt"
  check "footfall $command > /dev/full: exit 1" [ $? -eq 1 ]
  check "footfall $command > /dev/full: said" grep -Eq "cannot write (standard output|to stdout)" "$work/err.txt"
done

for flag in --version --help; do
  "$footfalld" $flag > /dev/full 2> "$work/err.txt"
  check "footfalld $flag > /dev/full: exit 1" [ $? -eq 1 ]
  check "footfalld $flag > /dev/full: said" grep -q "footfalld: cannot write standard output" "$work/err.txt"
done

# 7b. ... and so does a standard output closed at start (it went to /dev/null, exit 0).
echo "snap 10 0 10" | "$footfall" query --terrain "$hills" >&- 2> "$work/err.txt"
check "footfall query >&-: exit 1" [ $? -eq 1 ]
check "footfall query >&-: said" grep -qF "cannot write the answers to stdout (line 1 read): Bad file descriptor" "$work/err.txt"
"$footfall" generate --terrain "$hills" --character "$biped" --steps 4 --out - >&- 2> "$work/err.txt"
check "footfall generate --out - >&-: exit 1" [ $? -eq 1 ]
check "footfall generate --out - >&-: said" grep -qF "cannot write the walk JSON to standard output: Bad file descriptor" "$work/err.txt"
"$footfall" generate --terrain "$hills" --character "$biped" --steps 4 --out "$work/closed.json" >&- 2> "$work/err.txt"
check "footfall generate --out FILE >&-: exit 0 (nothing for stdout)" [ $? -eq 0 ]
check "footfall generate --out FILE >&-: the walk written" grep -q '"tracks"' "$work/closed.json"

# 8. An output past the file size limit (ulimit -f) is refused and the file from before is kept,
#    said so; "it does not match the other outputs" only when there are others.
echo old > "$work/kept.json"
(ulimit -f 1; "$footfall" generate --terrain "$hills" --character "$biped" --steps 4 \
  --out "$work/kept.json") 2> "$work/err.txt"
check "ulimit -f: exit 1" [ $? -eq 1 ]
check "ulimit -f: the old file kept" grep -qx old "$work/kept.json"
check "ulimit -f, one output: said kept" \
  grep -qx "footfall generate: $work/kept.json is left as it was, from before this walk" "$work/err.txt"
(ulimit -f 1; "$footfall" generate --terrain "$hills" --character "$biped" --steps 4 \
  --out "$work/kept.json" --out "$work/small.mel") 2> "$work/err.txt"
check "ulimit -f, two outputs: said it does not match the others" grep -qF \
  "$work/kept.json is left as it was, from before this walk (it does not match the other outputs)" \
  "$work/err.txt"

# 9. A --port-file that cannot be written (past the file size limit, as on a full disk): exit 1,
#    and no empty file left for a supervisor to read.
err=$( (ulimit -f 0; "$footfalld" --listen 127.0.0.1:0 --no-rpcbind --port-file "$work/port9") 2>&1)
check "port file past the size limit: exit 1" [ $? -eq 1 ]
check "port file past the size limit: said" grep -qF -- "--port-file $work/port9: cannot write the port there" <<< "$err"
check "port file past the size limit: no file left" [ ! -e "$work/port9" ]
check "port file past the size limit: no temporary file left" \
  bash -c '[ -z "$(ls -A "$1" | grep port9)" ]' _ "$work"
finish
