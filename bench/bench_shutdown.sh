#!/usr/bin/env bash
# Bounded shutdown (issue 8, docs/BENCHMARKS.md; goal: the daemon exits 0
# within --grace + 1 s). Starts build/pdesolidd (or $PDESOLIDD) on a free
# loopback port with --grace $GRACE (2) --threads 1 and budgets lifted so
# that each job is heavy, sends JOBS (12) distinct heavy requests at once
# (json of finding 1's 4096-mode model, each with its own coefficient, so that
# none shares another's solution; tens of CPU-seconds each), waits WAIT
# seconds (1), sends SIGTERM and times the exit. Repeats ROUNDS (3) times;
# prints each round's time to exit, exit status and the clients' statuses.
#   bench/bench_shutdown.sh        (after `make`; not run by `make test`)
set -uo pipefail  # no -e: a failed case or round is reported, and the others still run
cd "$(dirname "$0")/.."
BIN=${PDESOLIDD:-build/pdesolidd} GRACE=${GRACE:-2} JOBS=${JOBS:-12} WAIT=${WAIT:-1} ROUNDS=${ROUNDS:-3}
[ -x "$BIN" ] || { echo "bench_shutdown: $BIN is missing (make)"; exit 1; }
TMP=$(mktemp -d)
D=""
trap '[ -z "$D" ] || kill -9 $D 2>/dev/null; wait 2>/dev/null; rm -rf "$TMP"' EXIT
for j in $(seq "$JOBS"); do
  awk -v n=4095 -v coef="$((10 + j))" 'BEGIN {
    printf "{\"pde\":{\"a\":[1,1,1],\"b\":[1,1,1],\"c\":[-9.5,-9.5,-10]},\"boundary\":{"
    printf "\"x\":[{\"u\":{\"pow\":1},\"v\":{\"sin\":2},\"w0\":0.5,\"w1\":0.5}],"
    printf "\"y\":[{\"u\":{\"pow\":1},\"v\":{\"cos\":2},\"w0\":0.5,\"w1\":0.5}],\"z\":[{\"w1\":3}]},\"force\":{"
    for (c = 0; c < 3; c++) {
      printf "%s\"%s\":[", (c ? "," : ""), substr("xyz", c + 1, 1)
      for (k = 0; k < n; k++)
        printf "%s{\"coef\":%d,\"u\":{\"cos\":%d},\"v\":{\"cos\":%d},\"w\":{\"sin\":1}}", (k ? "," : ""), coef, 1 + k % 64, 1 + int(k / 64)
      printf "]"
    }
    printf "}}" }' > "$TMP/m$j.json"
done
echo "load before: $(cut -d' ' -f1-3 /proc/loadavg)"
for round in $(seq "$ROUNDS"); do
  LOG="$TMP/log.$round"
  "$BIN" --port 0 --quiet --grace "$GRACE" --threads 1 --max-work 1e18 --max-mem-mb 65536 --job-timeout 86400 \
    --max-body 16MiB 2>"$LOG" & D=$!
  PORT=""
  for _ in $(seq 100); do
    PORT=$(sed -n 's|.*listening on http://127.0.0.1:\([0-9]*\)/.*|\1|p' "$LOG" 2>/dev/null)
    [ -n "$PORT" ] && break
    sleep 0.05
  done
  [ -n "$PORT" ] || { echo "bench_shutdown: pdesolidd did not start:"; cat "$LOG"; exit 1; }
  C=()
  for j in $(seq "$JOBS"); do
    curl -s -o /dev/null -w '%{http_code} curl-exit-%{exitcode} upload=%{size_upload} t=%{time_total}\n' --max-time 120 -X POST "http://127.0.0.1:$PORT/solve?format=json" \
      --data-binary @"$TMP/m$j.json" > "$TMP/c$round.$j" & C+=($!)
  done
  sleep "$WAIT"
  t0=$(date +%s.%N)
  kill -TERM "$D"
  rc=0; wait "$D" || rc=$?
  t1=$(date +%s.%N)
  wait "${C[@]}" 2>/dev/null || true
  D=""
  [ -z "${VERBOSE:-}" ] || cat "$TMP"/c"$round".*
  statuses=$(cut -d" " -f1,2 "$TMP"/c"$round".* | sort | uniq -c | awk '{printf "%s%s %s x%s", (NR > 1 ? ", " : ""), $2, $3, $1}')
  awk -v a="$t0" -v b="$t1" -v g="$GRACE" -v rc="$rc" -v s="$statuses" -v n="$JOBS" 'BEGIN {
    printf "round: exit %.2f s after SIGTERM (grace %d s, bound %d s), exit status %d; the %d clients: %s\n", b - a, g, g + 1, rc, n, s }'
done
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
