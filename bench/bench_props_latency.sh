#!/usr/bin/env bash
# The server's uncached latency for a new model's json (docs/BENCHMARKS.md, issue 9): POST /solve
# of N fig. 4a models that differ only in p0, so each is solved and its properties computed anew.
# Prints the median wall time (curl) and the median of Server-Timing's props part.
#   bench/bench_props_latency.sh           (after `make`; `make bench` runs it)
#   N=41 PRESET=fig4b bench/bench_props_latency.sh
set -euo pipefail
cd "$(dirname "$0")/.."
N=${N:-41} PRESET=${PRESET:-fig4a} PORT=${PORT:-18491}
build/pdesolidd --port "$PORT" --quiet 2>/dev/null & D=$!
trap 'kill $D 2>/dev/null; wait 2>/dev/null' EXIT
sleep 0.5
p0=$(curl -s "http://127.0.0.1:$PORT/presets/$PRESET" | python3 -c 'import json,sys; print(json.load(sys.stdin)["params"]["p0"])')
walls=() props=()
for i in $(seq 1 "$N"); do
    body="{\"preset\":\"$PRESET\",\"params\":{\"p0\":$(python3 -c "print($p0 * (1 + $i * 1e-6))")}}"
    out=$(curl -s -D - -o /dev/null -w 'wall=%{time_total}\n' -X POST "http://127.0.0.1:$PORT/solve" -d "$body")
    walls+=("$(sed -n 's/^wall=//p' <<<"$out")")
    props+=("$(sed -n 's/.*props;dur=\([0-9.]*\).*/\1/p' <<<"$out" | tr -d '\r')")
done
median() { printf '%s\n' "$@" | sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }
echo "$PRESET, $N new models: median wall $(median "${walls[@]}") s, median props $(median "${props[@]}") ms"
