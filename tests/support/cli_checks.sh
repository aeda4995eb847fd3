# Shared by the command-line tests (source it): a scratch folder removed on exit, named checks
# counted and reported, and a real footfalld on a free loopback port.
#   check NAME COMMAND...      passes when COMMAND succeeds; prints FAILED: NAME otherwise
#   start_server FOOTFALLD [FLAGS...]   sets server_pid, port and server (127.0.0.1:PORT)
#   stop_server                 stops it (SIGTERM) and waits for it
#   wait_for_port FILE          waits up to 5 s for a port file, then prints the port
#   finish                      prints the counts; its status is the test's
work=$(mktemp -d)
server_pid=""
trap '[ -n "$server_pid" ] && kill "$server_pid" 2>/dev/null; rm -rf "$work"' EXIT
failures=0
passes=0
check() {
  local name=$1; shift
  if "$@"; then passes=$((passes + 1)); else echo "FAILED: $name" >&2; failures=$((failures + 1)); fi
}
start_server() {
  local footfalld=$1; shift
  rm -f "$work/port"
  "$footfalld" --listen 127.0.0.1:0 --port-file "$work/port" --no-rpcbind "$@" 2> "$work/server.log" &
  server_pid=$!
  port=$(wait_for_port "$work/port")
  server=127.0.0.1:$port
}
wait_for_port() {
  for _ in $(seq 100); do [ -s "$1" ] && break; sleep 0.05; done
  cat "$1"
}
stop_server() {
  kill "$server_pid"; wait "$server_pid" 2>/dev/null; server_pid=""
}
finish() {
  echo "$passes checks passed, $failures failed"
  [ "$failures" -eq 0 ]
}
