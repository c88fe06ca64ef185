#!/usr/bin/env bash
# The server benchmark (docs/BENCHMARKS.md, issue 8's throughput goals): wrk on
# loopback against pdesolidd and, in the same run, against bench/mhd_minimal,
# a minimal libmicrohttpd server answering the same bytes with the same number
# of polling threads (HTTP_THREADS, 2: pdesolidd --http-threads, mhd_minimal's
# THREADS). A third server is pdesolidd with its access log on, to /dev/null.
# Each round runs the three in turn; prints medians of RUNS rounds and the
# median of the per-round ratios (goals: pdesolidd / minimal >= 0.9; logged /
# quiet >= 0.95), and each server's CPU time per request (/proc/PID/stat).
#   bench/bench_server.sh        (after `make`; `make bench` runs it)
#   RUNS=9 DUR=5s CONNS=32 WRK_THREADS=2 HTTP_THREADS=2 GLB=0 bench/bench_server.sh
set -euo pipefail
cd "$(dirname "$0")/.."
RUNS=${RUNS:-5} DUR=${DUR:-5s} CONNS=${CONNS:-32} WRK_THREADS=${WRK_THREADS:-2} HTTP_THREADS=${HTTP_THREADS:-2}
GLB=${GLB:-1}
command -v wrk >/dev/null || { echo "bench_server: wrk is missing (apt-get install wrk)"; exit 1; }
P1=18481 P2=18482 P3=18483
build/pdesolidd --port $P1 --quiet --http-threads "$HTTP_THREADS" 2>/dev/null & D=$!
build/pdesolidd --port $P3 --http-threads "$HTTP_THREADS" 2>/dev/null & L=$!
M=""
trap 'kill $D $L $M 2>/dev/null; wait 2>/dev/null' EXIT
sleep 0.5
rss() { awk '/^VmRSS/ {print $2/1024 " MB"}' /proc/$1/status; }
hwm() { awk '/^VmHWM/ {print $2/1024 " MB"}' /proc/$1/status; }
echo "pdesolidd RSS idle: $(rss $D)"
curl -s -X POST "http://127.0.0.1:$P1/solve" -d '{"preset":"fig4a"}' -o /tmp/bench_fig4a.json
curl -s -X POST "http://127.0.0.1:$P3/solve" -d '{"preset":"fig4a"}' -o /dev/null
build/bench/mhd_minimal $P2 /tmp/bench_fig4a.json "$HTTP_THREADS" & M=$!
sleep 0.3
cpu() { awk '{print $14 + $15}' /proc/$1/stat; }  # utime + stime of a process, in clock ticks
TCK=$(getconf CLK_TCK)
run() {  # url pid -> "requests/s p99 server-CPU-us-per-request"
  local c0 c1; c0=$(cpu "$2")
  wrk -t"$WRK_THREADS" -c"$CONNS" -d"$DUR" --latency -s bench/post_fig4a.lua "$1" > /tmp/bench_wrk.out
  c1=$(cpu "$2")
  awk -v dc=$((c1 - c0)) -v tck="$TCK" '/Requests\/sec/ {rps=$2} /^ +99%/ {p99=$2} / requests in / {n=$1}
    END {printf "%s %s %.2f\n", rps, p99, dc / tck * 1e6 / n}' /tmp/bench_wrk.out
}
median() { sort -g | awk '{a[NR]=$1} END {print (NR%2 ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2)}'; }
echo "load before: $(cut -d' ' -f1-3 /proc/loadavg)"
U1=http://127.0.0.1:$P1/solve U2=http://127.0.0.1:$P2/solve U3=http://127.0.0.1:$P3/solve
: > /tmp/bench_srv.txt
for i in $(seq "$RUNS"); do  # the order turns each round, so that no server always runs first
  case $((i % 3)) in
    1) a=$(run "$U1" $D); b=$(run "$U2" $M); c=$(run "$U3" $L) ;;
    2) b=$(run "$U2" $M); c=$(run "$U3" $L); a=$(run "$U1" $D) ;;
    0) c=$(run "$U3" $L); a=$(run "$U1" $D); b=$(run "$U2" $M) ;;
  esac
  echo "$a $b $c" | tee -a /tmp/bench_srv.txt >&2
done
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
echo "pdesolidd RSS after json load: $(rss $D)"
pd=$(awk '{print $1}' /tmp/bench_srv.txt | median); mn=$(awk '{print $4}' /tmp/bench_srv.txt | median)
lg=$(awk '{print $7}' /tmp/bench_srv.txt | median)
ratio=$(awk '{print $1/$4}' /tmp/bench_srv.txt | median); lratio=$(awk '{print $7/$1}' /tmp/bench_srv.txt | median)
cratio=$(awk '{print $6/$3}' /tmp/bench_srv.txt | median); clratio=$(awk '{print $3/$9}' /tmp/bench_srv.txt | median)
echo "cached POST /solve {\"preset\":\"fig4a\"} (json, $(wc -c </tmp/bench_fig4a.json) bytes), wrk -t$WRK_THREADS -c$CONNS -d$DUR, $HTTP_THREADS polling threads each, $RUNS rounds:"
echo "  pdesolidd --quiet:       $pd requests/s (median), p99 per round: $(awk '{printf "%s ", $2}' /tmp/bench_srv.txt)"
echo "  mhd_minimal:             $mn requests/s (median), p99 per round: $(awk '{printf "%s ", $5}' /tmp/bench_srv.txt)"
echo "  pdesolidd, log on:       $lg requests/s (median), p99 per round: $(awk '{printf "%s ", $8}' /tmp/bench_srv.txt)"
echo "  ratio pdesolidd / minimal (median of per-round ratios): $ratio   per round: $(awk '{printf "%.3f ", $1/$4}' /tmp/bench_srv.txt)"
echo "  ratio log on / --quiet (median of per-round ratios):    $lratio   per round: $(awk '{printf "%.3f ", $7/$1}' /tmp/bench_srv.txt)"
echo "  server CPU per request, us (median): pdesolidd --quiet $(awk '{print $3}' /tmp/bench_srv.txt | median), mhd_minimal $(awk '{print $6}' /tmp/bench_srv.txt | median), log on $(awk '{print $9}' /tmp/bench_srv.txt | median)"
echo "  CPU ratios (median of per-round ratios): minimal / pdesolidd $cratio, --quiet / log on $clratio"
[ "$GLB" = 1 ] || exit 0
: > /tmp/bench_glb.txt
for i in $(seq $RUNS); do run "http://127.0.0.1:$P1/solve?format=glb&res=64" $D >> /tmp/bench_glb.txt; done
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
