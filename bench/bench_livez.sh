#!/usr/bin/env bash
# /livez latency while one heavy request runs (issue 8's goal: p99 at most
# 10 ms). Starts build/pdesolidd (or $PDESOLIDD) on a free loopback port with
# $ARGS, sends one heavy POST /solve (fig4a's boundary and TERMS force terms
# per component, each its own (u, v) mode, at $QUERY; 512 terms at glb res 512
# took 23 s before issue 8), and
# polls /livez until it ends or DUR seconds pass: with wrk if installed,
# otherwise with a loop of curl -w. Prints p50 and p99 and the heavy
# request's status and time (a request refused by a budget ends at once).
#   bench/bench_livez.sh                      (after `make`; not run by `make test`)
#   TERMS=4096 QUERY='format=f32&res=1024,1024,2' ARGS='--max-work 1e15' bench/bench_livez.sh
set -euo pipefail
cd "$(dirname "$0")/.."
BIN=${PDESOLIDD:-build/pdesolidd} TERMS=${TERMS:-512} QUERY=${QUERY:-format=glb&res=512} DUR=${DUR:-10}
ARGS=${ARGS:-}
[ -x "$BIN" ] || { echo "bench_livez: $BIN is missing (make)"; exit 1; }
TMP=$(mktemp -d)
# shellcheck disable=SC2086
"$BIN" --port 0 --quiet $ARGS 2>"$TMP/log" & D=$!
H=""
trap 'kill -9 $D 2>/dev/null; kill $H 2>/dev/null; wait 2>/dev/null; rm -rf "$TMP"' EXIT  # -9: no grace for the heavy job
PORT=""
for _ in $(seq 100); do
  PORT=$(sed -n 's|.*listening on http://127.0.0.1:\([0-9]*\)/.*|\1|p' "$TMP/log")
  [ -n "$PORT" ] && break
  sleep 0.05
done
[ -n "$PORT" ] || { echo "bench_livez: pdesolidd did not start:"; cat "$TMP/log"; exit 1; }
URL="http://127.0.0.1:$PORT"
awk -v n="$TERMS" 'BEGIN {
  printf "{\"pde\":{\"a\":[1,1,1],\"b\":[1,1,1],\"c\":[-9.5,-9.5,-10]},\"boundary\":{"
  printf "\"x\":[{\"u\":{\"pow\":1},\"v\":{\"sin\":2},\"w0\":0.5,\"w1\":0.5}],"
  printf "\"y\":[{\"u\":{\"pow\":1},\"v\":{\"cos\":2},\"w0\":0.5,\"w1\":0.5}],\"z\":[{\"w1\":3}]},\"force\":{"
  for (c = 0; c < 3; c++) {
    printf "%s\"%s\":[", (c ? "," : ""), substr("xyz", c + 1, 1)
    for (k = 0; k < n; k++)
      printf "%s{\"coef\":10,\"u\":{\"cos\":%d},\"v\":{\"cos\":%d},\"w\":{\"sin\":1}}", (k ? "," : ""), 1 + k % 64, 1 + int(k / 64)
    printf "]"
  }
  printf "}}"
}' > "$TMP/heavy.json"
curl -s -o /dev/null -w '%{http_code} %{time_total}\n' -X POST "$URL/solve?$QUERY" --data-binary @"$TMP/heavy.json" \
  > "$TMP/heavy.out" & H=$!
sleep 0.2
if command -v wrk >/dev/null; then
  how="wrk -t1 -c1"
  wrk -t1 -c1 -d"${DUR}s" --latency "$URL/livez" > "$TMP/wrk.out"
  p50=$(awk '/^ +50%/ {print $2}' "$TMP/wrk.out"); p99=$(awk '/^ +99%/ {print $2}' "$TMP/wrk.out")
  n=$(awk '/requests in/ {print $1}' "$TMP/wrk.out")
else
  how="curl -w, one connection per request"
  end=$(( $(date +%s) + DUR ))
  while [ "$(date +%s)" -lt "$end" ]; do
    curl -s -o /dev/null -w '%{time_total}\n' --max-time 30 "$URL/livez" >> "$TMP/lat" || echo 30 >> "$TMP/lat"
    kill -0 $H 2>/dev/null || [ "$(wc -l < "$TMP/lat")" -lt 50 ] || break
  done
  sort -n "$TMP/lat" > "$TMP/lat.s"
  n=$(wc -l < "$TMP/lat.s")
  pick() { awk -v q="$1" -v n="$n" 'NR == (int(q * n + 0.999) < 1 ? 1 : int(q * n + 0.999)) {printf "%.2fms", $1 * 1000}' "$TMP/lat.s"; }
  p50=$(pick 0.50); p99=$(pick 0.99)
fi
running=$(kill -0 $H 2>/dev/null && echo "still running" || echo "done")
[ "$running" = done ] || kill $H 2>/dev/null || true
wait $H 2>/dev/null || true
read -r hs ht < "$TMP/heavy.out" || { hs="-"; ht="-"; }
echo "/livez while POST /solve?$QUERY of $TERMS force terms per component runs ($how, $n requests):"
echo "  p50 $p50, p99 $p99"
echo "  the heavy request: status $hs after ${ht}s (it was $running when the polling stopped)"
