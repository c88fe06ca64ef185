#!/usr/bin/env bash
# /livez latency, CPU time and peak memory of issue 8's heavy requests
# (docs/BENCHMARKS.md; goals: /livez p99 at most 10 ms while any single request
# within the limits runs, and no such request over about 2 CPU-s or 64 MB
# beyond the cache). For each case of the table below, a fresh build/pdesolidd
# (or $PDESOLIDD) with --quiet and $ARGS (default limits otherwise) on a free
# loopback port; bench/livez_heavy.py sends the case's request(s) and polls
# /livez on one keep-alive connection back to back while they run, and reads
# the daemon's CPU time (/proc/PID/stat) and peak RSS (VmHWM, reset through
# /proc/PID/clear_refs; root only) around them. Prints one row per case.
#   bench/bench_livez.sh                 (after `make`; not run by `make test`)
#   CASES='f32-fig4a-max glb-fig4a-max' bench/bench_livez.sh
#   ARGS='--max-work 1e15 --max-mem-mb 4096 --job-timeout 600' CASES=f32-4096 bench/bench_livez.sh
set -uo pipefail  # no -e: a failed case or round is reported, and the others still run
cd "$(dirname "$0")/.."
BIN=${PDESOLIDD:-build/pdesolidd} ARGS=${ARGS:-}
[ -x "$BIN" ] || { echo "bench_livez: $BIN is missing (make)"; exit 1; }
command -v python3 >/dev/null || { echo "bench_livez: python3 is missing"; exit 1; }
TMP=$(mktemp -d)
D=""
trap 'kill -9 $D 2>/dev/null; wait 2>/dev/null; rm -rf "$TMP"' EXIT  # -9: no grace for a heavy job

# The models of issue 8's findings 1 and 2, with T force terms per component,
# each its own (u, v) mode (a = 1 + k % 64, b = 1 + k / 64):
#   m1: {"coef":10,"u":{"cos":a},"v":{"cos":b},"w":{"sin":1}}, with fig4a-like
#       boundary loads (one more mode on x: 4095 terms make 4096 modes, the most);
#   m2: {"u":{"sin":a},"v":{"sin":b},"w":{"pow":100}} (finding 2's force terms).
model() {  # kind terms
  awk -v kind="$1" -v n="$2" 'BEGIN {
    printf "{\"pde\":{\"a\":[1,1,1],\"b\":[1,1,1],\"c\":[-9.5,-9.5,-10]},\"boundary\":{"
    printf "\"x\":[{\"u\":{\"pow\":1},\"v\":{\"sin\":2},\"w0\":0.5,\"w1\":0.5}],"
    printf "\"y\":[{\"u\":{\"pow\":1},\"v\":{\"cos\":2},\"w0\":0.5,\"w1\":0.5}],\"z\":[{\"w1\":3}]},\"force\":{"
    for (c = 0; c < 3; c++) {
      printf "%s\"%s\":[", (c ? "," : ""), substr("xyz", c + 1, 1)
      for (k = 0; k < n; k++)
        if (kind == "m1")
          printf "%s{\"coef\":10,\"u\":{\"cos\":%d},\"v\":{\"cos\":%d},\"w\":{\"sin\":1}}", (k ? "," : ""), 1 + k % 64, 1 + int(k / 64)
        else
          printf "%s{\"u\":{\"sin\":%d},\"v\":{\"sin\":%d},\"w\":{\"pow\":100}}", (k ? "," : ""), 1 + k % 64, 1 + int(k / 64)
      printf "]"
    }
    printf "}}"
  }'
}
points() {  # n: {"points":[...],"derivatives":true}, corners of the cube so that 100000 fit in 1 MiB
  awk -v n="$1" 'BEGIN { srand(1); printf "{\"points\":["
    for (i = 0; i < n; i++) printf "%s[%d,%d,%d]", (i ? "," : ""), rand() < .5, rand() < .5, rand() < .5
    printf "],\"derivatives\":true}" }'
}
echo '{"preset":"fig4a"}' > "$TMP/fig4a.json"
body() {  # name -> a file
  local f="$TMP/$1.json"
  if [ ! -f "$f" ]; then
    case $1 in
      m1_*) model m1 "${1#m1_}" > "$f" ;;
      m2_*) model m2 "${1#m2_}" > "$f" ;;
      pts_*) points "${1#pts_}" > "$f" ;;
    esac
  fi
  echo "$f"
}

# name | copies | method path | body | setup path (its X-Solid-Id is {id}) | setup body
# The first four are the findings' requests; the others the heaviest ones the
# default limits still accept, found from the estimates the 422s name.
CASE_TABLE='
idle             1 GET  /livez                              -        -                       -
f32-4096         1 POST /solve?format=f32&res=4096,4096,2   m1_4095  -                       -
glb-4096         1 POST /solve?format=glb&res=512           m2_4096  -                       -
eval-100k        1 POST /solids/{id}/eval                   pts_100000 /solve?format=f32&res=2 m1_4095
json-4096        1 POST /solve?format=json                  m1_4095  -                       -
f32-m1-max       1 POST /solve?format=f32&res=300,300,2     m1_4095  -                       -
f32-m1-cube      1 POST /solve?format=f32&res=110           m1_4095  -                       -
eval-m1-max      1 POST /solids/{id}/eval                   pts_1500 /solve?format=f32&res=2 m1_4095
json-m1-max      1 POST /solve?format=json                  m1_900   -                       -
glb-m2-max       1 POST /solve?format=glb&res=230           m2_1900  -                       -
f32-fig4a-max    1 POST /solve?format=f32&res=4096,4096,2   fig4a    -                       -
glb-fig4a-max    1 POST /solve?format=glb&res=230           fig4a    -                       -
glb-fig4a-512    1 POST /solve?format=glb&res=512           fig4a    -                       -
f32-fig4a-128x8  8 POST /solve?format=f32&res=128           fig4a    -                       -
'
CASES=${CASES:-$(awk 'NF {print $1}' <<< "$CASE_TABLE" | tr '\n' ' ')}

start() {  # name: a daemon of its own, with its own log (the shell opens it after the fork)
  LOG="$TMP/log.$1"
  # shellcheck disable=SC2086
  "$BIN" --port 0 --quiet $ARGS 2>"$LOG" & D=$!
  PORT=""
  for _ in $(seq 100); do
    PORT=$(sed -n 's|.*listening on http://127.0.0.1:\([0-9]*\)/.*|\1|p' "$LOG" 2>/dev/null)
    [ -n "$PORT" ] && return 0
    sleep 0.05
  done
  echo "bench_livez: pdesolidd did not start:"; cat "$LOG"; exit 1
}

echo "load before: $(cut -d' ' -f1-3 /proc/loadavg); pdesolidd $ARGS"
printf '%s\t' case status seconds bytes livez_n p50_ms p99_ms max_ms idle_p99_ms cpu_s hwm_growth_mb rss_after_mb; echo detail
for c in $CASES; do
  read -r name copies method path bname sname sbody < <(awk -v c="$c" '$1 == c' <<< "$CASE_TABLE")
  [ -n "${name:-}" ] || { echo "bench_livez: no case $c"; exit 1; }
  bf=-; [ "$bname" = - ] || bf=$(body "$bname")
  setup=(); [ "$sname" = - ] || setup=("$sname" "$(body "$sbody")")
  start "$name"
  python3 bench/livez_heavy.py "$PORT" "$D" "$name" "$method" "$path" "$bf" "$copies" "${setup[@]}" || true
  kill -9 "$D" 2>/dev/null || echo "bench_livez: pdesolidd had exited: $(tail -3 "$LOG")"; wait "$D" 2>/dev/null || true
done
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
