#!/usr/bin/env bash
# footfalld's data root and file permissions: a file in a folder footfalld's user may not
# search, or one it may not read, is refused saying so (it was "no such file" and a bare
# "cannot open"), and a root it may not search is refused at start. footfalld runs as nobody
# when the test runs as root (root reads everything), else as the test's own user.
#   data_root_permissions_test.sh FOOTFALL FOOTFALLD SOURCE_DIR
set -u
footfall=$1
footfalld=$2
src=$3
source "$(dirname "$0")/../support/cli_checks.sh"
as_user=()
if [ "$(id -u)" -eq 0 ]; then
  as_user=(setpriv --reuid=65534 --regid=65534 --clear-groups)
fi
chmod 755 "$work"
mkdir -p "$work/root/locked" "$work/root/inner" "$work/run"
chmod 777 "$work/run"
# Run from a copy that nobody may execute wherever the build lies (under /root, say).
cp "$footfalld" "$work/run/footfalld"
chmod 755 "$work/run/footfalld"
footfalld=$work/run/footfalld
for f in locked/a.pts secret.pts open.pts; do cp "$src/data/terrain/stairs.pts" "$work/root/$f"; done
chmod 644 "$work/root/open.pts" "$work/root/locked/a.pts"
chmod 000 "$work/root/secret.pts"
chmod 700 "$work/root/locked"  # its owner (root) may search it, no one else
[ ${#as_user[@]} -eq 0 ] && chmod 000 "$work/root/locked"
"${as_user[@]}" "$footfalld" --listen 127.0.0.1:0 --port-file "$work/run/port" --no-rpcbind \
  --data-root "$work/root" 2> "$work/run/log" &
server_pid=$!
for _ in $(seq 100); do [ -s "$work/run/port" ] && break; sleep 0.05; done
server=127.0.0.1:$(cat "$work/run/port")
query() { echo "snap 0 0 0" | "$footfall" query --server "$server" --server-terrain "$1" 2>&1; }
out=$(query locked/a.pts)
check "unsearchable folder: exit 1" [ $? -eq 1 ]
check "unsearchable folder: said" grep -qF "'locked/a.pts': permission denied: footfalld's user may not search a folder on its way under the data root" <<< "$out"
out=$(query secret.pts)
check "unreadable file: exit 1" [ $? -eq 1 ]
check "unreadable file: said" grep -qF "'secret.pts': cannot open: Permission denied" <<< "$out"
out=$(query open.pts)
check "readable file: answered" grep -qF '"found":true' <<< "$out"
check "errors logged" grep -qF "error: load: access_denied: 'secret.pts': cannot open: Permission denied" "$work/run/log"
# The root renamed or removed while footfalld runs: said so (every path was "leads outside the
# data root", as a link escaping it is), and loads work again once it is back.
mv "$work/root" "$work/root.moved"
for f in open.pts nosuch.pts; do
  out=$(query "$f")
  check "root moved away, $f: exit 1" [ $? -eq 1 ]
  check "root moved away, $f: said" grep -qF "footfalld's data root is gone (No such file or directory): it loads no file until the folder is back where it was" <<< "$out"
done
mv "$work/root.moved" "$work/root"
out=$(query open.pts)
check "root back: answered" grep -qF '"found":true' <<< "$out"
kill "$server_pid"; wait "$server_pid" 2>/dev/null; server_pid=""
# A root its user may not search: refused at start, exit 2.
chmod 700 "$work/root"
[ ${#as_user[@]} -eq 0 ] && chmod 000 "$work/root"
err=$(timeout 20 "${as_user[@]}" "$footfalld" --listen 127.0.0.1:0 --no-rpcbind --data-root "$work/root" 2>&1)
check "unsearchable root: exit 2" [ $? -eq 2 ]
check "unsearchable root: said" grep -qF "footfalld: --data-root $work/root: this user (uid $(id -u "${as_user[@]:+nobody}")) may not search it (Permission denied), so no load could succeed" <<< "$err"
# A root inside a folder its user may not search: it is there, not "no such folder".
err=$(timeout 20 "${as_user[@]}" "$footfalld" --listen 127.0.0.1:0 --no-rpcbind --data-root "$work/root/inner" 2>&1)
check "root behind an unsearchable folder: exit 2" [ $? -eq 2 ]
check "root behind an unsearchable folder: said" grep -qF -- "--data-root: '$work/root/inner': cannot be reached (Permission denied)" <<< "$err"
err=$(timeout 20 "${as_user[@]}" "$footfalld" --listen 127.0.0.1:0 --no-rpcbind --data-root "$work/no/such" 2>&1)
check "missing root: said" grep -qF -- "--data-root: '$work/no/such': no such folder (No such file or directory)" <<< "$err"
chmod -R u+rwx "$work/root"
finish
