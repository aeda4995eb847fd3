#!/usr/bin/env bash
# `footfall bench` end to end: the figures it reports, embedded and against a real footfalld,
# and the errors of bad input. Figures are checked for presence and sense, never for speed.
# Usage: bench_cli_test.sh FOOTFALL FOOTFALLD SOURCE_DIR
set -u
footfall=$1
footfalld=$2
source_dir=$3
source "$(dirname "$0")/../support/cli_checks.sh"
hills=$source_dir/data/terrain/hills.pts

# Checks a JSON report: the terrain's figures, and every query figure positive, with the
# baseline expected ("brute force" or "embedded") beside the figures that have one.
check_report() {  # check_report NAME FILE BATCH_BASELINE
  python3 - "$2" "$3" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
batch_base = sys.argv[2]
assert r["samples"] == 25921, r["samples"]
assert 0 < r["bytes_per_sample"] <= 64, r["bytes_per_sample"]
assert r["load_s"] > 0 and r["queries"] == 3000
names = [f["name"] for f in r["figures"]]
for op in ("snap", "next"):
    for order in ("random", "coherent"):
        assert f"{op} {order}, one per call" in names, names
        assert f"{op} {order}, batches of 1000" in names, names
for f in r["figures"]:
    assert f["ns_per_query"] > 0 and f["queries_per_s"] > 0, f
    if f["name"].endswith("one per call"):
        assert f["baseline"] == "brute force" and f["baseline_ns_per_query"] > 0, f
    elif batch_base:
        assert f["baseline"] == batch_base and f["ratio"] > 0, f
    else:
        assert "baseline" not in f, f
PY
}

# 1. Embedded: every figure, brute force beside single queries.
"$footfall" bench --terrain "$hills" --queries 3000 --batch 1000 --min-time 0.02 --json \
  > "$work/embedded.json" 2> "$work/err"
check "embedded bench exits 0" [ $? -eq 0 ]
check "embedded report" check_report embedded "$work/embedded.json" ""
"$footfall" bench --terrain "$hills" --queries 3000 --batch 1000 --min-time 0.02 > "$work/text"
check "text report names the backend" grep -q '^backend: embedded$' "$work/text"
check "text report has a line per figure" [ "$(grep -c 'ns/query' "$work/text")" -eq 8 ]
# Ratios keep three significant digits: against brute force on a terrain of a million samples,
# three decimals read x0.000.
"$footfall" terrain make flat --size 100 --spacing 0.1 -o "$work/million.pts" > /dev/null
"$footfall" bench --terrain "$work/million.pts" --queries 200 --batch 100 --min-time 0.01 \
  > "$work/million.txt"
ratios=$(grep -o '(x[^)]*)' "$work/million.txt" | tr -d '(x)')
check "text report gives ratios" [ -n "$ratios" ]
check "no ratio reads zero" awk '$1 + 0 <= 0 { bad = 1 } END { exit bad }' <<< "$ratios"

# 2. Over RPC against a real footfalld: the embedded engine is the batches' baseline.
start_server "$footfalld"
"$footfall" bench --terrain "$hills" --server "$server" --queries 3000 --batch 1000 \
  --min-time 0.02 --json > "$work/rpc.json" 2> "$work/err"
check "rpc bench exits 0" [ $? -eq 0 ]
check "rpc report" check_report rpc "$work/rpc.json" embedded
check "rpc backend named" grep -q "\"backend\": \"rpc $server\"" "$work/rpc.json"

# 3. Bad input: a clear message and a non-zero exit.
printf '0 0 0 0 1 0\n1 2 3\n' > "$work/bad.pts"
err=$("$footfall" bench --terrain "$work/bad.pts" 2>&1 >/dev/null)
check "bad terrain: exit 1" [ $? -eq 1 ]
check "bad terrain: file and line" grep -qF "$work/bad.pts:2: expected 6 numbers" <<< "$err"
printf '# no samples\n' > "$work/empty.pts"
err=$("$footfall" bench --terrain "$work/empty.pts" 2>&1 >/dev/null)
check "empty terrain: exit 1" [ $? -eq 1 ]
check "empty terrain: message" grep -qF "$work/empty.pts: no samples (expected at least one line x y z nx ny nz)" <<< "$err"
err=$("$footfall" bench --terrain "$hills" --jitter nan 2>&1 >/dev/null)
check "nan jitter refused" [ $? -ne 0 ]
check "nan jitter: message" grep -qF -- "--jitter: 'nan' is not a finite number from 0 to 1e+12" <<< "$err"
# A step of 0 (every next query invalid) and one so long no query is valid are refused; a
# jitter of 0 is taken as given (it was replaced by the default).
err=$("$footfall" bench --terrain "$hills" --step 0 2>&1 >/dev/null)
check "zero step refused" [ $? -ne 0 ]
check "zero step: message" grep -qF -- "--step: '0' is not a finite number > 0 and <= 1e+12" <<< "$err"
err=$("$footfall" bench --terrain "$hills" --step 1e300 2>&1 >/dev/null)
check "huge step refused" [ $? -ne 0 ]
out=$("$footfall" bench --terrain "$hills" --jitter 0 --queries 64 --min-time 0.001 2>/dev/null)
check "jitter 0 taken as given" grep -q "jitter 0)" <<< "$out"
check "batches no larger than the queries" grep -q "batches of 64" <<< "$out"
err=$("$footfall" bench --terrain "$hills" --queries 0 2>&1 >/dev/null)
check "zero queries refused" [ $? -ne 0 ]
# Whole-number flags (bench's and terrain make's) name their bounds as --steps does; CLI11 said
# "Value 1.5 not in range" or "Could not convert", and --query-seed read -1 as 2^64 - 1.
whole() {  # whole NAME EXPECTED_MESSAGE ARGS...: refused with this message
  local name=$1 want=$2; shift 2
  local err
  err=$("$footfall" "$@" 2>&1 >/dev/null)
  check "$name: refused" [ $? -ne 0 ]
  check "$name: message '$want'" grep -qF -- "$want" <<< "$err"
}
whole "bench --threads 1.5" "--threads: '1.5' is not a whole number from 1 to 256" bench --terrain "$hills" --threads 1.5
whole "bench --queries 1.5" "--queries: '1.5' is not a whole number from 1 to 16777216" bench --terrain "$hills" --queries 1.5
whole "bench --queries 0" "--queries: '0' is not a whole number from 1 to 16777216" bench --terrain "$hills" --queries 0
whole "bench --batch 2.5" "--batch: '2.5' is not a whole number from 1 to 1048576" bench --terrain "$hills" --batch 2.5
whole "bench --query-seed -1" "--query-seed: '-1' is not a whole number from 0 to 18446744073709551615" bench --terrain "$hills" --query-seed -1
whole "make --steps 1.5" "--steps: '1.5' is not a whole number from 1 to 2147483647" terrain make stairs --steps 1.5 -o "$work/x.pts"
whole "make --size 2.5" "--size: '2.5' is not a whole number from 1 to 2147483647" terrain make blocks --size 2.5 -o "$work/x.pts"
whole "make --max-height -1" "--max-height: '-1' is not a whole number from 0 to 2147483647" terrain make blocks --max-height -1 -o "$work/x.pts"
# terrain make: a flag of another kind's shape is refused, not ignored.
whole "make flat --steps" "--steps is for stairs, not flat" terrain make flat --steps 5 -o "$work/x.pts"
whole "make stairs --seed" "--seed is for blocks rocks hills, not stairs" terrain make stairs --seed 2 -o "$work/x.pts"
check "bad whole numbers: nothing written" [ ! -e "$work/x.pts" ]
stop_server
err=$("$footfall" bench --terrain "$hills" --server "$server" --timeout 2 2>&1 >/dev/null)
check "no server: exit 1" [ $? -eq 1 ]
check "no server: says so" grep -qi "footfall bench: .*$server" <<< "$err"

# More query points than the memory the process may use holds are refused before the terrain
# is loaded (--queries 16777216 under a 2 GB limit ran out of memory after 25 s).
err=$( (ulimit -v 2000000; timeout 20 "$footfall" bench --terrain "$hills" --queries 16777216) 2>&1 >/dev/null)
check "--queries beyond memory: exit 1" [ $? -eq 1 ]
check "--queries beyond memory: message" grep -qxF "footfall bench: --queries 16777216 needs about 2.68 GB for its queries, more than the 2.05 GB of memory this process may use (give fewer)" <<< "$err"

# Queries the engine refuses are counted and said: on samples 1e15 apart the default step
# (two cells) puts most ideal points beyond the query range (they were timed as answers).
printf '5e14 5e14 5e14 0 1 0\n-5e14 -5e14 -5e14 0 1 0\n' > "$work/far.pts"
err=$("$footfall" bench --terrain "$work/far.pts" --queries 1000 --min-time 0.01 2>&1 >/dev/null)
check "refused queries: said" grep -qE "^footfall bench: note: of the 1000 queries, 0 snap and [1-9][0-9]* next queries are refused as invalid" <<< "$err"
out=$("$footfall" bench --terrain "$work/far.pts" --queries 1000 --min-time 0.01 --json 2>/dev/null)
check "refused queries: in the JSON" python3 -c "import json, sys; j = json.loads(sys.argv[1]); assert j['refused_snap_queries'] == 0 and j['refused_next_queries'] > 0" "$out"
err=$("$footfall" bench --terrain "$hills" --queries 1000 --min-time 0.01 2>&1 >/dev/null)
check "no refused queries: no note" bash -c '! grep -q "refused" <<< "$1"' _ "$err"
finish
