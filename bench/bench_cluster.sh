#!/usr/bin/env bash
# The cluster benchmark (docs/BENCHMARKS.md, "The cluster"; issue 12): wrk through nginx in front of
# 1 and then 3 replicas of build/pdesolidd sharing Redis, as `make cluster` runs them
# (deploy/cluster.sh, in build/bench-cluster/ on ports BENCH_PORT.., with nginx's per-address rate
# limit lifted, since wrk is one address). Four loads, each RUNS rounds of DUR, the replica counts
# taking turns each round; medians of requests/s, and of the rounds' non-2xx answers:
#   cached json       POST /solve {"preset":"fig4a"} again and again: the replica's kept response
#   nginx cache       GET /solids/ID of that solid: nginx's proxy_cache answers, no replica is asked
#   uncached json     POST /solve of fig4a with a new p0 each time: solve, properties, json, a Redis put
#   uncached f32      the same with ?format=f32&res=2: solve and Redis put, no properties
# Then build/bench/bench_store against this cluster's Redis: a store lookup on a cache miss (LMDB and
# Redis) as a ratio of a solve.
#   bench/bench_cluster.sh            (after `make`; `make bench` runs it)
#   RUNS=5 DUR=5s CONNS=16 BENCH_PORT=18490 bench/bench_cluster.sh
set -euo pipefail
cd "$(dirname "$0")/.."
RUNS=${RUNS:-3} DUR=${DUR:-4s} CONNS=${CONNS:-16} PORT=${BENCH_PORT:-18490}
command -v wrk >/dev/null || { echo "bench_cluster: wrk is missing (apt-get install wrk, or make deps)"; exit 1; }
[ -x build/pdesolidd ] || { echo "bench_cluster: build/pdesolidd is missing: make"; exit 1; }
DIR=build/bench-cluster
TMP=$(mktemp -d /tmp/bench-cluster-XXXXXX)
cluster() {   # start|stop replicas
    CLUSTER_DIR=$DIR CLUSTER_PORT=$PORT CLUSTER_REPLICAS=$2 CLUSTER_RATE=1000000 PDESOLIDD=build/pdesolidd \
        bash deploy/cluster.sh "$1" 2>/dev/null
}
trap 'cluster stop 3 || true; rm -rf "$TMP"' EXIT
U=http://127.0.0.1:$PORT

# The uncached loads: a new p0 each request, random per wrk thread and run, so no two bodies meet.
for fmt in json f32; do
    q=""; [ $fmt = f32 ] && q="?format=f32&res=2"
    cat >"$TMP/uncached_$fmt.lua" <<LUA
local n = 0
local seed = 0
function setup(thread) seed = seed + 1; thread:set("seed", seed) end
function init(args) math.randomseed(os.time() * 1000 + seed * 7919 + math.floor(os.clock() * 1e6)) end
request = function()
  n = n + 1
  local p0 = 20000 + math.random() * 40000 + n * 1e-6
  return wrk.format("POST", "/solve$q", {["Content-Type"] = "application/json"},
                    string.format('{"preset":"fig4a","params":{"p0":%.9f}}', p0))
end
LUA
done
cat >"$TMP/cached.lua" <<'LUA'
wrk.method = "POST"
wrk.body = '{"preset":"fig4a"}'
wrk.headers["Content-Type"] = "application/json"
LUA

# CPU time of every process of the cluster (replicas, Redis, nginx's master and workers), in clock
# ticks: CPU per request depends much less on the neighbours than requests/s do.
cluster_cpu() {
    local pids
    pids=$(cat "$DIR"/*.pid; pgrep -P "$(cat "$DIR/nginx.pid")")
    for p in $pids; do cat "/proc/$p/stat"; done | awk '{sub(/.*\) /, ""); s += $12 + $13} END {print s}'
}
TCK=$(getconf CLK_TCK)
run() {   # lua-or-empty path -> "requests/s non2xx cpu-us-per-request"
    local args=(-t2 -c"$CONNS" -d"$DUR") c0 c1
    [ -n "$1" ] && args+=(-s "$1")
    c0=$(cluster_cpu)
    wrk "${args[@]}" "$U$2" >"$TMP/wrk.out"
    sleep 0.5   # what was in flight when wrk stopped
    c1=$(cluster_cpu)
    awk -v dc=$((c1 - c0)) -v tck="$TCK" '/Requests\/sec/ {rps=$2} /Non-2xx/ {bad=$NF} / requests in / {n=$1}
        END {printf "%s %d %.1f\n", rps, bad, dc / tck * 1e6 / n}' "$TMP/wrk.out"
}
median() { sort -g | awk '{a[NR]=$1} END {print (NR%2 ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2)}'; }

echo "load before: $(cut -d' ' -f1-3 /proc/loadavg)"
: >"$TMP/results"
for i in $(seq "$RUNS"); do
    order="1 3"; [ $((i % 2)) = 0 ] && order="3 1"
    for r in $order; do
        cluster stop 3; rm -rf "$DIR"
        cluster start "$r"
        id=$(curl -s -D - -o /dev/null -X POST "$U/solve" -d '{"preset":"fig4a"}' | awk -F': ' 'tolower($1) == "x-solid-id" {print $2}' | tr -d '\r')
        curl -s -o /dev/null "$U/solids/$id"   # into nginx's cache
        echo "$r cached_json $(run "$TMP/cached.lua" /solve)" >>"$TMP/results"
        echo "$r nginx_cache $(run "" "/solids/$id")" >>"$TMP/results"
        echo "$r uncached_f32 $(run "$TMP/uncached_f32.lua" /solve)" >>"$TMP/results"
        # Last: its requests in flight when wrk stops (0.2 s of CPU each) would spill into the next load.
        echo "$r uncached_json $(run "$TMP/uncached_json.lua" /solve)" >>"$TMP/results"
        tail -4 "$TMP/results" >&2
    done
done
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
echo "through nginx, wrk -t2 -c$CONNS -d$DUR, $RUNS rounds, medians: requests/s, and the cluster's CPU"
echo "(replicas, Redis, nginx) in microseconds per request; non-2xx answers in all rounds:"
printf '  %-14s %10s %10s %7s %12s %12s\n' load "1 replica" "3 replicas" "3 / 1" "CPU us, 1" "CPU us, 3"
col() { awk -v r="$1" -v l="$2" -v c="$3" '$1 == r && $2 == l {print $c}' "$TMP/results" | median; }
for load in cached_json nginx_cache uncached_f32 uncached_json; do
    one=$(col 1 $load 3) three=$(col 3 $load 3)
    bad=$(awk -v l=$load '$2 == l {s += $4} END {print s + 0}' "$TMP/results")
    printf '  %-14s %10.1f %10.1f %7.2f %12.1f %12.1f   non-2xx: %s\n' $load "$one" "$three" \
        "$(awk -v a="$three" -v b="$one" 'BEGIN {print a / b}')" "$(col 1 $load 5)" "$(col 3 $load 5)" "$bad"
done

# The store on a cache miss, against this cluster's Redis (3 replicas' cluster, left running for it).
cluster start 3
[ -x build/bench/bench_store ] || make -s build/bench/bench_store >/dev/null
REDIS_PORT=$((PORT + 1)) build/bench/bench_store

# What a new id's put costs: one daemon, no nginx, uncached f32 solves (wrk straight to it) with each
# store: none, this cluster's Redis, and LMDB in $TMP (a put is a synchronous, fsynced commit).
D=""
trap 'kill $D 2>/dev/null || true; cluster stop 3 || true; rm -rf "$TMP"' EXIT
echo "one daemon, uncached f32 (POST /solve?format=f32&res=2, a new p0 each), wrk -t2 -c$CONNS -d$DUR, $RUNS rounds, medians:"
for store in none "redis://127.0.0.1:$((PORT + 1))/8" "$TMP/lmdb"; do
    build/pdesolidd --port $((PORT + 10)) --quiet --store "$store" 2>/dev/null & D=$!
    sleep 0.5
    : >"$TMP/one"
    for i in $(seq "$RUNS"); do
        c0=$(awk '{print $14 + $15}' /proc/$D/stat)
        wrk -t2 -c"$CONNS" -d"$DUR" -s "$TMP/uncached_f32.lua" "http://127.0.0.1:$((PORT + 10))/solve" >"$TMP/wrk.out"
        c1=$(awk '{print $14 + $15}' /proc/$D/stat)
        awk -v dc=$((c1 - c0)) -v tck="$TCK" '/Requests\/sec/ {rps=$2} / requests in / {n=$1}
            END {printf "%s %.1f\n", rps, dc / tck * 1e6 / n}' "$TMP/wrk.out" >>"$TMP/one"
    done
    kill $D; wait $D 2>/dev/null || true
    printf '  --store %-28s %10.1f requests/s %8.1f us daemon CPU/request\n' "$store" \
        "$(awk '{print $1}' "$TMP/one" | median)" "$(awk '{print $2}' "$TMP/one" | median)"
done
