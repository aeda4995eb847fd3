#!/usr/bin/env bash
# `footfall query` end to end: answers, per-line errors, bad terrain files, and identical answers
# from the embedded engine and a real footfalld.
# Usage: query_cli_test.sh FOOTFALL FOOTFALLD
set -u
footfall=$1
footfalld=$2
source "$(dirname "$0")/../support/cli_checks.sh"

# A 5 x 5 flat terrain at y = 0, samples at integer x, z.
for z in 0 1 2 3 4; do for x in 0 1 2 3 4; do echo "$x 0 $z 0 1 0"; done; done > "$work/flat.pts"

# 0. No command, or a word that names none: the commands are listed, exit 1.
"$footfall" > /dev/null 2> "$work/err.txt"
check "no command: exit 1" [ $? -eq 1 ]
check "no command: the commands listed" grep -qx 'footfall: a command is required: query, terrain, generate, bench (footfall --help)' "$work/err.txt"
"$footfall" qeury --terrain "$work/flat.pts" > /dev/null 2> "$work/err.txt"
check "unknown command: exit 1" [ $? -eq 1 ]
check "unknown command: named" grep -qF "footfall: unknown command 'qeury': expected one of query, terrain, generate, bench" "$work/err.txt"
"$footfall" terrain > /dev/null 2> "$work/err.txt"
check "no terrain command: exit 1" [ $? -eq 1 ]
check "no terrain command: its commands listed" grep -qx 'footfall terrain: a command is required: convert, info, make (footfall terrain --help)' "$work/err.txt"
"$footfall" terrain mkae > /dev/null 2> "$work/err.txt"
check "unknown terrain command: named" grep -qF "footfall terrain: unknown command 'mkae': expected one of convert, info, make" "$work/err.txt"
"$footfall" -v > /dev/null 2> "$work/err.txt"
check "an option before any command: exit 1" [ $? -eq 1 ]
check "an option before any command: named" grep -qF "footfall: unknown option '-v' where a command is expected: query, terrain, generate, bench" "$work/err.txt"
# An option missing its value is told so: CLI11 took the next option as the value ("--out
# --steps" wrote a walk to a file named --steps, and the step count was lost).
"$footfall" terrain make flat -o --size 2 > /dev/null 2> "$work/err.txt"
check "-o followed by an option: exit 1" [ $? -eq 1 ]
check "-o followed by an option: told" grep -qxF "footfall terrain make: -o needs a value, found the option --size (footfall terrain make --help)" "$work/err.txt"
check "-o followed by an option: no file written" [ ! -e ./--size ]
"$footfall" query --tolerance --terrain "$work/flat.pts" < /dev/null > /dev/null 2> "$work/err.txt"
check "--tolerance followed by an option: told" grep -qF "footfall query: --tolerance needs a value, found the option --terrain" "$work/err.txt"
echo "snap 0 0 0" | "$footfall" query --terrain "$work/flat.pts" --tolerance=1 > /dev/null 2> "$work/err.txt"
check "--tolerance=1: taken" [ $? -eq 0 ]
# A word written as an option that is none is named (a file "-flat.pts" was "input is
# required"); after '--' it is a file name; a negative number and --name=value are values.
cp "$work/flat.pts" "$work/-flat.pts"
(cd "$work" && "$footfall" terrain info -flat.pts) > /dev/null 2> "$work/err.txt"
check "file name starting with '-': exit 1" [ $? -eq 1 ]
check "file name starting with '-': told" grep -qxF "footfall terrain info: unknown option '-flat.pts' (footfall terrain info --help lists them; a file whose name starts with '-' goes after '--')" "$work/err.txt"
(cd "$work" && "$footfall" terrain info -- -flat.pts) > /dev/null
# A misspelt option is named with the one it was most likely meant to be.
"$footfall" generate --terrain "$work/flat.pts" --setps 3 > /dev/null 2> "$work/err.txt"
check "misspelt option: exit 1" [ $? -eq 1 ]
check "misspelt option: the near one suggested" grep -qF "footfall generate: unknown option '--setps': did you mean --steps? (" "$work/err.txt"
"$footfall" terrain make flat --outptu "$work/x.pts" > /dev/null 2> "$work/err.txt"
check "misspelt option of terrain make: suggested" grep -qF "unknown option '--outptu': did you mean --output?" "$work/err.txt"
"$footfall" generate --terrain "$work/flat.pts" --xyz 3 > /dev/null 2> "$work/err.txt"
check "an option near none: no suggestion" grep -qF "unknown option '--xyz' (footfall generate --help" "$work/err.txt"
# generate takes no file arguments: no hint of '--' for file names starting with '-'.
check "generate: no '--' hint" grep -qxF "footfall generate: unknown option '--xyz' (footfall generate --help lists them)" "$work/err.txt"
# A long option written with one dash was a one-letter option with the rest as its value
# ("-out w.json" wrote a file "ut"), and "-o=w.json" wrote a file "=w.json".
(cd "$work" && "$footfall" generate --terrain flat.pts -out w.json) > /dev/null 2> "$work/err.txt"
check "-out: exit 1" [ $? -eq 1 ]
check "-out: told as --out" grep -qF "footfall generate: unknown option '-out': did you mean --out?" "$work/err.txt"
check "-out: no file 'ut' written" [ ! -e "$work/ut" ]
(cd "$work" && "$footfall" terrain make flat -o=eq.pts) > /dev/null 2> "$work/err.txt"
check "-o=FILE: exit 1" [ $? -eq 1 ]
check "-o=FILE: told" grep -qF "footfall terrain make: '-o=eq.pts' would give -o the value '=eq.pts': write -o eq.pts" "$work/err.txt"
check "-o=FILE: no file '=eq.pts' written" [ ! -e "$work/=eq.pts" ]
check "file name starting with '-' after '--': read" [ $? -eq 0 ]
echo "next 0 0 0 1 0 0" | "$footfall" query --terrain="$work/flat.pts" --tolerance=-1 > /dev/null 2> "$work/err.txt"
check "--tolerance=-1: refused as a value" grep -qF -- "--tolerance: '-1' is not a finite number >= 0" "$work/err.txt"
echo "snap 0 0 0" | "$footfall" query --terrain="$work/flat.pts" --tolerance=$'1\x01' > /dev/null 2> "$work/err.txt"
check "--tolerance with a control byte: its bytes shown" grep -qF -- "--tolerance: '1?' (bytes 31 01) is not a finite number >= 0" "$work/err.txt"
# --version prints the version and exits 0, as a script checking which footfall it runs expects.
out=$("$footfall" --version 2> "$work/err.txt")
check "--version: exit 0" [ $? -eq 0 ]
check "--version: footfall and its version" grep -qxE 'footfall [0-9]+\.[0-9]+\.[0-9]+' <<< "$out"

# `footfall help [COMMAND...]` prints that command's help, as `--help` does, and exits 0.
out=$("$footfall" help 2> "$work/err.txt")
check "help: exit 0" [ $? -eq 0 ]
check "help: the commands listed" grep -q '^  generate  ' <<< "$out"
out=$("$footfall" help terrain make 2> "$work/err.txt")
check "help terrain make: exit 0" [ $? -eq 0 ]
check "help terrain make: the make command's help" [ "$out" = "$("$footfall" terrain make --help)" ]
"$footfall" help walk > /dev/null 2> "$work/err.txt"
check "help of an unknown command: exit 1" [ $? -eq 1 ]
check "help of an unknown command: named" grep -qF "footfall: unknown command 'walk'" "$work/err.txt"

# 1. Answers, in order, one JSON object per line.
printf 'snap 1.2 3 2.9\nnormal 4 4 4\nnext 1 0 1 0 0 2\nnext 1 0 4 0 0 2\n' |
  "$footfall" query --terrain "$work/flat.pts" > "$work/out.jsonl"
rc=$?
check "valid queries exit 0" [ "$rc" -eq 0 ]
check "snap answer" grep -qx '{"op":"snap","found":true,"index":16,"point":\[1.0,0.0,3.0\],"normal":\[0.0,1.0,0.0\]}' <(sed -n 1p "$work/out.jsonl")
check "normal answer" grep -q '"op":"normal","found":true,"index":24' <(sed -n 2p "$work/out.jsonl")
check "next answer" grep -qx '{"op":"next","found":true,"index":16,"point":\[1.0,0.0,3.0\],"normal":\[0.0,1.0,0.0\]}' <(sed -n 3p "$work/out.jsonl")
check "no foothold" grep -qx '{"op":"next","found":false}' <(sed -n 4p "$work/out.jsonl")

# 2. Malformed lines give an error object with the line number; the run goes on; exit non-zero.
printf 'snap 1 0 1\nsnap 1 x 1\n\njump 1 2 3\nnext 0 0 0 0 0 0\nsnap 2 0 2\nnormal 4 4 # short\nsnap 2,0, 2\n' |
  "$footfall" query --terrain "$work/flat.pts" > "$work/out.jsonl"
rc=$?
check "malformed lines exit 1" [ "$rc" -eq 1 ]
check "eight lines give seven answers" [ "$(wc -l < "$work/out.jsonl")" -eq 7 ]
check "bad number" grep -q '{"op":"error","line":2,"message":"snap: argument 2 '"'"'x'"'"' is not a finite number"}' "$work/out.jsonl"
check "unknown command" grep -qF '"line":4,"message":"unknown command '"'"'jump'"'"' (expected snap X Y Z, normal X Y Z or next X Y Z DX DY DZ)"}' "$work/out.jsonl"
check "zero direction" grep -q '"line":5,"message":"next: direction DX DY DZ must be non-zero' "$work/out.jsonl"
check "answers after errors" grep -q '"op":"snap","found":true,"index":12' <(sed -n 5p "$work/out.jsonl")
check "count" grep -qF '{"op":"error","line":7,"message":"normal: expected 3 numbers, found 2"}' <(sed -n 6p "$work/out.jsonl")
check "commas separate numbers" grep -q '"op":"snap","found":true,"index":12' <(sed -n 7p "$work/out.jsonl")
# Input that starts with a UTF-8 byte order mark (a file saved by a Windows editor): line 1 is
# answered (it was "unknown command 'snap'", the mark unseen); a mark on a later line is an error.
printf '\xEF\xBB\xBFsnap 2 0 2\r\n\xEF\xBB\xBFsnap 2 0 2\r\n' | "$footfall" query --terrain "$work/flat.pts" > "$work/bom.jsonl"
check "byte order mark: exit 1 for the second line" [ $? -eq 1 ]
check "byte order mark: the first line answered" grep -q '"op":"snap","found":true,"index":12' <(sed -n 1p "$work/bom.jsonl")
check "byte order mark: not on a later line" grep -q '"op":"error","line":2,"message":"unknown command' <(sed -n 2p "$work/bom.jsonl")
# Lines ended by CR alone (classic Mac OS) are refused saying so (they ran together as one
# line, "snap: expected 3 numbers, found 7"); CRLF and a lone CR before the newline are read.
printf 'snap 1 0 1\rsnap 2 0 2\r\nsnap 2 0 2 \r \r\n' | "$footfall" query --terrain "$work/flat.pts" > "$work/cr.jsonl"
check "CR-only line ends: exit 1" [ $? -eq 1 ]
check "CR-only line ends: said" grep -qxF '{"op":"error","line":1,"message":"carriage return within the line: lines ended by CR alone (classic Mac OS) are not read (end lines with LF or CRLF)"}' <(sed -n 1p "$work/cr.jsonl")
check "CR-only line ends: CRLF read" grep -q '"op":"snap","found":true,"index":12' <(sed -n 2p "$work/cr.jsonl")
printf '# queries\rsnap 1 0 1\r' | "$footfall" query --terrain "$work/flat.pts" > "$work/cr.jsonl"
check "CR-only line ends after a comment: exit 1" [ $? -eq 1 ]
check "CR-only line ends after a comment: said" grep -q '"line":1,"message":"carriage return within the line' "$work/cr.jsonl"
# A query beyond the query range says how that range is measured: per axis from the terrain's
# centre (it said "farther than 1e15 from the terrain" of a point 7e14 from a sample).
printf '0 0 0 0 1 0\n1 0 0 0 1 0\n2 0 0 0 1 0\n3 0 0 0 1 0\n5e14 0 0 0 1 0\n' > "$work/far.pts"
printf 'snap 1.2e15 0 0\nnext 0 0 0 1.2e15 0 0\n' | "$footfall" query --terrain "$work/far.pts" > "$work/far.jsonl"
check "beyond the query range: said from the centre" grep -qF '{"op":"error","line":1,"message":"snap: invalid query (a coordinate more than 1e15 from the terrain'"'"'s centre)"}' <(sed -n 1p "$work/far.jsonl")
check "an ideal point beyond it: said" grep -qF 'invalid query (a zero direction, one too long to square, or a foot or ideal point' <(sed -n 2p "$work/far.jsonl")
# A byte that is not UTF-8 in a line: that line's error (the byte replaced), and the run goes on
# (the JSON writer threw, and no later line was answered).
printf 'snap \xff 0 0\nsnap 2 0 2\n' | "$footfall" query --terrain "$work/flat.pts" > "$work/utf8.jsonl"
check "non-UTF-8 byte: exit 1" [ $? -eq 1 ]
check "non-UTF-8 byte: the line's error" grep -q '"op":"error","line":1,"message":"snap: argument 1' <(sed -n 1p "$work/utf8.jsonl")
check "non-UTF-8 byte: the next line answered" grep -q '"op":"snap","found":true,"index":12' <(sed -n 2p "$work/utf8.jsonl")
# A line longer than 4096 characters (here 5 MB, no newline after it at first) is an error of
# its own, skipped without being held; the next lines are answered; the last line may lack its
# newline.
{ printf 'snap 1 0 1\nsnap 1 0 '; head -c 5000000 /dev/zero | tr '\0' '7'; printf '\nsnap 2 0 2\nsnap 1 0 1'; } |
  "$footfall" query --terrain "$work/flat.pts" > "$work/long.jsonl"
rc=$?
check "long line: exit 1" [ "$rc" -eq 1 ]
check "long line: four answers" [ "$(wc -l < "$work/long.jsonl")" -eq 4 ]
check "long line: an error naming the line" grep -qx '{"op":"error","line":2,"message":"line longer than 4096 characters"}' <(sed -n 2p "$work/long.jsonl")
check "long line: the lines after it are answered" grep -q '"op":"snap","found":true,"index":12' <(sed -n 3p "$work/long.jsonl")
check "long line: a last line without newline is answered" grep -q '"op":"snap","found":true' <(sed -n 4p "$work/long.jsonl")
# Lines of exactly 4096 characters are read whether LF or CRLF ends them (the CR was counted,
# and the CRLF one refused as too long); 4097 are too long either way.
line4096=$(printf 'snap 1 0 1%*s' 4086 '')
line4097="$line4096 "
printf '%s\n%s\r\n%s\n%s\r\n' "$line4096" "$line4096" "$line4097" "$line4097" |
  "$footfall" query --terrain "$work/flat.pts" > "$work/edge.jsonl"
check "4096-character lines, LF and CRLF: answered" [ "$(grep -c '"op":"snap","found":true' "$work/edge.jsonl")" -eq 2 ]
check "4097-character lines, LF and CRLF: too long" [ "$(grep -c 'line longer than 4096 characters' "$work/edge.jsonl")" -eq 2 ]
# An empty --terrain, --server-terrain or --server (a script's unset variable) is refused, naming
# the flag: --server "" ran the embedded engine and --server-terrain "" was ignored, silently.
for flag in --terrain --server --server-terrain; do
  given=(--terrain "$work/flat.pts")
  [ "$flag" = --terrain ] && given=()
  err=$(echo "snap 1 0 1" | "$footfall" query "${given[@]}" "$flag" "" 2>&1 >/dev/null)
  check "query $flag '': exit 1" [ $? -eq 1 ]
  check "query $flag '': the flag named" grep -qF -- "$flag: expected a" <<< "$err"
done
# The consumer closing stdout early (head): a clean exit 1 saying so, no signal, no hang.
{ for i in $(seq 20000); do echo "snap 1 0 1"; done; } | "$footfall" query --terrain "$work/flat.pts" 2> "$work/err.txt" | head -1 > /dev/null
check "stdout closed early: exit 1, no signal" [ "${PIPESTATUS[1]}" -eq 1 ]
check "stdout closed early: message" grep -qF "footfall query: cannot write the answers to stdout" "$work/err.txt"
# stdin that cannot be read (a directory) is an error, not an empty input answered with exit 0.
err=$("$footfall" query --terrain "$work/flat.pts" 2>&1 >/dev/null < "$work")
check "unreadable stdin: exit 1" [ $? -eq 1 ]
check "unreadable stdin: message" grep -qF "footfall query: cannot read stdin after line 0: Is a directory" <<< "$err"
# Answers that cannot be written (a full disk; SIGPIPE is ignored) are an error, not exit 0.
err=$(printf 'snap 1 0 1\nsnap 2 0 2\n' | "$footfall" query --terrain "$work/flat.pts" 2>&1 > /dev/full)
check "unwritable stdout: exit 1" [ $? -eq 1 ]
check "unwritable stdout: message" grep -qF "footfall query: cannot write the answers to stdout (line " <<< "$err"
check "unwritable stdout: why" grep -qF "No space left on device" <<< "$err"

# 3. Bad terrain files: the documented message and a non-zero exit, never a crash.
bad() {  # bad NAME CONTENT EXPECTED_MESSAGE
  printf "$2" > "$work/$1.pts"
  local err rc
  err=$(echo "snap 0 0 0" | "$footfall" query --terrain "$work/$1.pts" 2>&1 >/dev/null)
  rc=$?
  check "$1: exit 1" [ "$rc" -eq 1 ]
  check "$1: message '$3'" grep -qF "$3" <<< "$err"
}
err=$(echo "snap 0 0 0" | "$footfall" query --terrain "$work/flat.pts" --tolerance nan 2>&1 >/dev/null)
check "nan tolerance refused" [ $? -ne 0 ]
check "nan tolerance: message" grep -qF -- "--tolerance: 'nan' is not a finite number >= 0" <<< "$err"
bad count '0 0 0 0 1 0\n1 2 3\n' "$work/count.pts:2: expected 6 numbers (x y z nx ny nz), found 3"
bad nan '# header\n0 0 nan 0 1 0\n' "$work/nan.pts:2: column 3: 'nan' is NaN or infinite"
bad inf '0 0 0 0 1 0\n0 -inf 0 0 1 0\n' "$work/inf.pts:2: column 2: '-inf' is NaN or infinite"
bad word '0 0 0 0 1 0\n\n0 0 0 up 1 0\n' "$work/word.pts:3: column 4: 'up' is not a number"
bad zero '0 0 0 0 0 0\n' "$work/zero.pts:1: normal has zero length"
err=$(echo "snap 0 0 0" | "$footfall" query --terrain "$work/missing.pts" 2>&1 >/dev/null)
check "missing file: exit 1" [ $? -eq 1 ]
check "missing file: message" grep -qF "$work/missing.pts: cannot open file" <<< "$err"

# 4. The same answers over RPC from a real footfalld, by upload and by server-side path.
start_server "$footfalld" --data-root "$work"
{ for i in $(seq 0 200); do echo "snap $((i % 7)).3 0.$i $((i % 5)).6"; echo "next $((i % 5)) 0 $((i % 4)) 0.$i 0 1.$i"; done; } > "$work/queries"
"$footfall" query --terrain "$work/flat.pts" < "$work/queries" > "$work/embedded.jsonl"
"$footfall" query --terrain "$work/flat.pts" --server "127.0.0.1:$port" < "$work/queries" > "$work/rpc.jsonl"
"$footfall" query --server-terrain flat.pts --server "127.0.0.1:$port" < "$work/queries" > "$work/rpc-path.jsonl"
check "RPC upload answers equal embedded" cmp -s "$work/embedded.jsonl" "$work/rpc.jsonl"
check "RPC server-side load answers equal embedded" cmp -s "$work/embedded.jsonl" "$work/rpc-path.jsonl"
check "402 answers" [ "$(wc -l < "$work/rpc.jsonl")" -eq 402 ]
err=$(echo "snap 0 0 0" | "$footfall" query --server-terrain ../../etc/passwd --server "127.0.0.1:$port" 2>&1 >/dev/null)
check "escape refused: exit 1" [ $? -eq 1 ]
check "escape refused: message" grep -qF "'../../etc/passwd' leads outside the data root" <<< "$err"
err=$(echo "snap 0 0 0" | "$footfall" query --server-terrain sub/../flat.pts --server "127.0.0.1:$port" 2>&1 >/dev/null)
check "'..' within the root refused: exit 1" [ $? -eq 1 ]
check "'..' within the root refused: message" grep -qF "'sub/../flat.pts': '..' is not allowed in a path under the data root" <<< "$err"
check "server logs loads" grep -q "loaded terrain" "$work/server.log"
# Each load and error line names its client, so an operator can tell who caused it.
check "load lines name the client" grep -qE "loaded terrain [0-9]+ from 'flat.pts': .* \(client 127\.0\.0\.1:[0-9]+\)$" "$work/server.log"
check "upload lines name the client" grep -qE "loaded terrain [0-9]+ '.*' \(uploaded\): .* \(client 127\.0\.0\.1:[0-9]+\)$" "$work/server.log"
check "error lines name the client" grep -qE "error: load: access_denied: '\.\./\.\./etc/passwd' leads outside the data root \(client 127\.0\.0\.1:[0-9]+\)$" "$work/server.log"
stop_server
err=$(echo "snap 0 0 0" | "$footfall" query --terrain "$work/flat.pts" --server "127.0.0.1:$port" 2>&1 >/dev/null)
check "server gone: exit 1" [ $? -eq 1 ]
check "server gone: message" grep -qF "footfalld at 127.0.0.1:$port" <<< "$err"
# footfalld's own flags: timeouts are finite numbers of seconds (NaN used to pass).
for flag in "--orphan-timeout nan" "--unread-timeout inf" "--unread-timeout 0"; do
  err=$(timeout 5 "$footfalld" --listen 127.0.0.1:0 --no-rpcbind $flag 2>&1)
  check "footfalld $flag: exit non-zero" [ $? -ne 0 ]
  check "footfalld $flag: message" grep -qE "is not a number of seconds (from|above) 0 to 1e\+09" <<< "$err"
done
# A budget is a whole number of samples ("-5" read as a huge budget); a bad flag exits 2.
for value in -5 99999999999999999999999 1.5 0x10 1e13; do
  err=$(timeout 5 "$footfalld" --listen 127.0.0.1:0 --no-rpcbind --max-samples "$value" 2>&1)
  check "footfalld --max-samples $value: exit 2" [ $? -eq 2 ]
  check "footfalld --max-samples $value: message" grep -qF "'$value' is not a whole number of samples from 0 to 1e12" <<< "$err"
done
# Written with an exponent, as its own message writes the bound: 2e1 samples hold no 25-sample
# terrain.
start_server "$footfalld" --max-samples 2e1
err=$(echo "snap 0 0 0" | "$footfall" query --terrain "$work/flat.pts" --server "$server" 2>&1 >/dev/null)
check "footfalld --max-samples 2e1: a 25-sample upload refused" grep -qF "(--max-samples 20," <<< "$err"
stop_server
# Without --max-samples, the default 2^28 is lowered to what the memory the process may use
# holds (100 bytes per sample): a 2 GB limit holds 20,480,000.
err=$( (ulimit -v 2000000; timeout 2 "$footfalld" --listen 127.0.0.1:0 --no-rpcbind) 2>&1)
check "footfalld default budget: lowered to memory" grep -qF "footfalld: sample budget 20480000 (this machine's memory at 100 bytes per sample" <<< "$err"
err=$( (ulimit -v 2000000; timeout 2 "$footfalld" --listen 127.0.0.1:0 --no-rpcbind --max-samples 1e9) 2>&1)
check "footfalld --max-samples: kept as given" bash -c '! grep -q "sample budget" <<< "$1"' _ "$err"
# A port file it cannot write is an error (a supervisor waiting for it would wait forever).
err=$(timeout 5 "$footfalld" --listen 127.0.0.1:0 --no-rpcbind --port-file "$work/no/such/dir/port" 2>&1)
check "footfalld unwritable --port-file: exit 1" [ $? -eq 1 ]
check "footfalld unwritable --port-file: message" grep -qF -- "--port-file $work/no/such/dir/port: cannot write the port there" <<< "$err"
# A height map larger than the memory the process may use is refused from its header (it ran
# out of memory after a minute of work); here 25 M pixels (a sparse file) under a 2 GB limit.
printf 'P5\n5000 5000\n255\n' > "$work/huge.pgm"
truncate -s $(( $(stat -c %s "$work/huge.pgm") + 25000000 )) "$work/huge.pgm"
err=$( (ulimit -v 2000000; "$footfall" terrain info "$work/huge.pgm") 2>&1)
check "height map beyond memory: exit 1" [ $? -eq 1 ]
check "height map beyond memory: message" grep -qF "huge.pgm:2: the header declares 5000 x 5000 pixels: reading it needs about 3.25 GB, more than the 2.05 GB of memory this process may use" <<< "$err"

# terrain make: ramps and rocks whose coordinates would pass 5e14 are refused before they are
# sampled (a ramp 1e300 long ended in "cannot create std::vector larger than max_size()",
# rocks 1e300 high asked for "a separation of at least -nan", rocks 1e40 high at a spacing of
# 1e38 were sampled for minutes before their samples were refused).
for args in "ramp --length 1e300 --spacing 1e299" "ramp --length 1e14 --slope 80 --spacing 1e13" \
    "rocks --amplitude 1e300" "rocks --amplitude -6e14 --spacing 1e13" \
    "rocks --amplitude 1e40 --spacing 1e38" "rocks --amplitude 1e150 --spacing 1e148"; do
  err=$(timeout 20 "$footfall" terrain make $args -o "$work/made.pts" 2>&1 >/dev/null)
  check "make $args: exit 1" [ $? -eq 1 ]
  check "make $args: out of range" grep -qE "^footfall terrain make: (ramp|rocks): the parameters give coordinates beyond 5e\+14 \([0-9.e+]+\), out of the grid's range$" <<< "$err"
done
check "make: nothing written" [ ! -e "$work/made.pts" ]
"$footfall" terrain make ramp --length 1e13 --slope 80 --spacing 1e12 -o "$work/made.pts" > /dev/null
check "make: a ramp within range written" [ -s "$work/made.pts" ]

# Sizes beyond the memory the process may use are refused before anything is made (rocks of
# 9 million samples under a 2 GB limit sampled for a minute, then ran out of memory).
err=$( (ulimit -v 2000000; timeout 20 "$footfall" terrain make rocks --size 300 --spacing 0.1 -o "$work/made.pts") 2>&1)
check "make beyond memory: exit 1" [ $? -eq 1 ]
check "make beyond memory: message" grep -qxF "footfall terrain make: rocks: these sizes at --spacing 0.1 give about 9006001 samples: making them needs about 4.5 GB, more than the 2.05 GB of memory this process may use (raise --spacing or give smaller sizes)" <<< "$err"
# Rocks whose relief adds surface the plan's estimate leaves out (3.7 times the samples at
# --amplitude 5) are refused by the sampler's own count, held to what memory holds (they passed
# the estimate and ended in a bare "out of memory").
err=$( (ulimit -v 1000000; timeout 60 "$footfall" terrain make rocks --size 40 --spacing 0.05 --amplitude 5 -o "$work/made.pts") 2>&1)
check "relief beyond memory: exit 1" [ $? -eq 1 ]
check "relief beyond memory: message" grep -qE "^footfall terrain make: rocks: separation 0.05 would give about [0-9]+ samples \(limit [0-9]+\); choose a separation of at least 0\.0[0-9]+ \(the limit is what the 1.02 GB of memory this process may use holds, at about 500 bytes a sample\)$" <<< "$err"
# A side whose ratio to the spacing rounds just below a whole number keeps its last row (7 /
# 0.07 is 99.99999999999999: 100 x 100 samples over 6.93 m).
for kind in flat hills; do
  "$footfall" terrain make $kind --size 7 --spacing 0.07 -o "$work/side.pts" > "$work/side.out"
  check "make $kind --size 7 --spacing 0.07: 101 x 101 samples" grep -qxF "wrote 10201 samples to $work/side.pts" "$work/side.out"
done

# A low soft limit on descriptors is raised to the hard one (at the limit libtirpc closes the
# least recently active connections, an idle client's among them).
hard=$(ulimit -Hn)
[ "$hard" = unlimited ] && hard=1048576
if [ "$hard" -gt 64 ]; then
  (ulimit -Sn 64; exec "$footfalld" --listen 127.0.0.1:0 --no-rpcbind --port-file "$work/port2" 2> "$work/limit.log") &
  limited=$!
  for _ in $(seq 100); do [ -s "$work/port2" ] && break; sleep 0.05; done
  soft=$(awk '/Max open files/ { print $4 }' "/proc/$limited/limits")
  check "footfalld raises its descriptor limit to the hard one" [ "$soft" = "$hard" ]
  check "footfalld says so" grep -q "open descriptor limit raised from 64 to" "$work/limit.log"
  kill "$limited"; wait "$limited" 2>/dev/null
else
  check "a hard descriptor limit above 64 to test with" false
fi

finish
