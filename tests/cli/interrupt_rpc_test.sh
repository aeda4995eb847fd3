#!/usr/bin/env bash
# Ctrl-C (SIGINT) and SIGTERM end `footfall` at once while it waits on a server's reply:
# libtirpc blocks every signal for the length of a call, and Ctrl-C waited for a
# --server-terrain load to finish (up to its 300 s timeout), the terrain then left orphaned.
# Usage: interrupt_rpc_test.sh FOOTFALL SOURCE_DIR
set -u
footfall=$1
src=$2
source "$(dirname "$0")/../support/cli_checks.sh"

# A server that takes connections and never answers.
python3 - "$work" <<'PY' &
import os, socket, sys, time
work = sys.argv[1]
listener = socket.socket()
listener.bind(("127.0.0.1", 0))
listener.listen(8)
with open(os.path.join(work, "port.tmp"), "w") as f:
    f.write(str(listener.getsockname()[1]))
os.rename(os.path.join(work, "port.tmp"), os.path.join(work, "silent_port"))
held = []
while True:
    connection, _ = listener.accept()
    held.append(connection)
    open(os.path.join(work, "connected"), "a").close()
PY
silent_pid=$!
for _ in $(seq 100); do [ -s "$work/silent_port" ] && break; sleep 0.05; done
port=$(cat "$work/silent_port")

for signal in INT TERM; do
  rm -f "$work/connected"
  # (SIGINT at its default, as for a terminal's foreground job: a script's background job
  # starts with it ignored, which footfall keeps.)
  env --default-signal=INT "$footfall" query --server "127.0.0.1:$port" --timeout 300 \
    --terrain "$src/data/terrain/hills.pts" < /dev/null > /dev/null 2> "$work/err" &
  pid=$!
  for _ in $(seq 200); do [ -e "$work/connected" ] && break; sleep 0.05; done
  sleep 0.2  # in its call now, waiting on the reply
  kill "-$signal" "$pid"
  # Ended within 30 s, not after the 300-s timeout (polled: nothing here is timed closer).
  for _ in $(seq 300); do kill -0 "$pid" 2> /dev/null || break; sleep 0.1; done
  check "SIG$signal while waiting on the server ends footfall" bash -c "! kill -0 $pid 2> /dev/null"
  kill -KILL "$pid" 2> /dev/null
  wait "$pid"
  rc=$?
  want=$((128 + $(kill -l "$signal")))
  check "SIG$signal: ended by the signal (exit $rc, expected $want)" [ "$rc" -eq "$want" ]
done
kill "$silent_pid"
finish
