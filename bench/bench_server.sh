#!/usr/bin/env bash
# The server benchmark (docs/BENCHMARKS.md): wrk on loopback against pdesolidd
# and, in the same run, against a minimal libmicrohttpd server answering the
# same bytes. Prints medians of RUNS rounds, alternating the two servers.
#   bench/bench_server.sh        (after `make`; `make bench` runs it)
set -euo pipefail
cd "$(dirname "$0")/.."
RUNS=${RUNS:-5} DUR=${DUR:-5s} CONNS=${CONNS:-16}
command -v wrk >/dev/null || { echo "bench_server: wrk is missing (apt-get install wrk)"; exit 1; }
P1=18481 P2=18482
build/pdesolidd --port $P1 --quiet 2>/dev/null & D=$!
trap 'kill $D $M 2>/dev/null; wait 2>/dev/null' EXIT
M=""
sleep 0.5
rss() { awk '/^VmRSS/ {print $2/1024 " MB"}' /proc/$1/status; }
hwm() { awk '/^VmHWM/ {print $2/1024 " MB"}' /proc/$1/status; }
echo "pdesolidd RSS idle: $(rss $D)"
curl -s -X POST "http://127.0.0.1:$P1/solve" -d '{"preset":"fig4a"}' -o /tmp/bench_fig4a.json
build/bench/mhd_minimal $P2 /tmp/bench_fig4a.json & M=$!
sleep 0.3
run() {  # url -> "requests/s p99"
  wrk -t1 -c$CONNS -d$DUR --latency -s bench/post_fig4a.lua "$1" | awk '
    /Requests\/sec/ {rps=$2} /^ +99%/ {p99=$2} END {print rps, p99}'
}
median() { sort -n | awk '{a[NR]=$1} END {print (NR%2 ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2)}'; }
: > /tmp/bench_srv.txt
for i in $(seq $RUNS); do
  a=$(run "http://127.0.0.1:$P1/solve"); b=$(run "http://127.0.0.1:$P2/solve")
  echo "$a $b" >> /tmp/bench_srv.txt
done
echo "pdesolidd RSS after json load: $(rss $D)"
# The same with the access log on (one line to stderr per request).
build/pdesolidd --port 18483 2>/dev/null & L=$!
sleep 0.4
curl -s -X POST "http://127.0.0.1:18483/solve" -d '{"preset":"fig4a"}' -o /dev/null
logged=$(for i in $(seq $RUNS); do run "http://127.0.0.1:18483/solve"; done | awk '{print $1}' | median)
kill $L; wait $L 2>/dev/null || true
pd=$(awk '{print $1}' /tmp/bench_srv.txt | median); mn=$(awk '{print $3}' /tmp/bench_srv.txt | median)
ratio=$(awk '{print $1/$3}' /tmp/bench_srv.txt | median)
echo "cached POST /solve {\"preset\":\"fig4a\"} (json, $(wc -c </tmp/bench_fig4a.json) bytes), wrk -t1 -c$CONNS -d$DUR, $RUNS rounds:"
echo "  pdesolidd:   $pd requests/s (median), p99 latency per round: $(awk '{printf "%s ", $2}' /tmp/bench_srv.txt)"
echo "  mhd_minimal: $mn requests/s (median), p99 latency per round: $(awk '{printf "%s ", $4}' /tmp/bench_srv.txt)"
echo "  ratio pdesolidd / minimal (median of per-round ratios): $ratio"
echo "  pdesolidd with its access log on: $logged requests/s (median)"
: > /tmp/bench_glb.txt
for i in $(seq $RUNS); do run "http://127.0.0.1:$P1/solve?format=glb&res=64" >> /tmp/bench_glb.txt; done
echo "glb of fig4a at res 64, repeated (a kept response): $(awk '{print $1}' /tmp/bench_glb.txt | median) requests/s (median), p99 $(awk '{printf "%s ", $2}' /tmp/bench_glb.txt)"
# Distinct glb requests: each body differs (trailing spaces), so none is a kept response;
# the solution is cached and every mesh is built anew.
cat > /tmp/bench_glb_distinct.lua <<'LUA'
counter = 0
request = function()
  counter = counter + 1
  return wrk.format("POST", "/solve?format=glb&res=64", {["Content-Type"] = "application/json"},
                    '{"preset":"fig4a"}' .. string.rep(" ", counter))
end
LUA
: > /tmp/bench_glb2.txt
for i in $(seq $RUNS); do
  wrk -t1 -c4 -d$DUR --latency -s /tmp/bench_glb_distinct.lua "http://127.0.0.1:$P1" | awk '/Requests\/sec/ {rps=$2} /^ +99%/ {p99=$2} END {print rps, p99}' >> /tmp/bench_glb2.txt
done
echo "glb of fig4a at res 64, each built anew: $(awk '{print $1}' /tmp/bench_glb2.txt | median) requests/s (median), p99 $(awk '{printf "%s ", $2}' /tmp/bench_glb2.txt)"
echo "pdesolidd RSS under load: $(rss $D), peak $(hwm $D)"
curl -s -X POST "http://127.0.0.1:$P1/solve?format=f32&res=256" -d '{"preset":"fig4a"}' -o /dev/null -w "f32 256^3: %{size_download} bytes in %{time_total} s\n"
echo "pdesolidd peak RSS after streaming the 256^3 f32 grid: $(hwm $D) (cache bound 256 MB)"
