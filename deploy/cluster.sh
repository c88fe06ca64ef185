#!/usr/bin/env bash
# deploy/cluster.sh start|stop|status: a cluster on one machine, unprivileged (`make cluster`,
# `make cluster-stop`): Debian's redis-server (AOF on) as the shared store, three pdesolidd
# replicas on loopback ports, and Debian's nginx on 127.0.0.1:$CLUSTER_PORT (8088) with
# deploy/nginx.conf in front of them. Everything lives in build/cluster/: a directory and a log
# per process, and a pid file each (redis.pid, pdesolidd-1.pid .. pdesolidd-3.pid, nginx.pid).
# No system service is touched.
#
# Ports: nginx on CLUSTER_PORT, Redis on CLUSTER_PORT + 1, the replicas on CLUSTER_PORT + 2..
# (build/cluster/ports lists them). The shipped file's per-address rate (20 r/s) would throttle a
# benchmark from this one address, so the cluster's copy allows CLUSTER_RATE (1000) a second.
#
# Knobs, all optional (the environment, or make's command line: `make cluster CLUSTER_PORT=18300`):
#   CLUSTER_PORT      nginx's port [8088]
#   CLUSTER_DIR       where state, logs and pid files go [build/cluster]; a second cluster on the
#                     same checkout (tests/test_cluster.c) needs a directory and ports of its own
#   CLUSTER_REPLICAS  how many replicas [3] (bench/bench_cluster.sh runs 1 and 3)
#   PDESOLIDD         the daemon [build/pdesolidd]; the tests give build/san/pdesolidd
#   CLUSTER_RATE      nginx's requests a second per address [1000]
#   CLUSTER_ALLOW_HOST  the names clients reach nginx by, comma-separated, each replica's
#                     --allow-host [none: 127.0.0.1:PORT and localhost:PORT only]; nginx passes
#                     the client's Host on, and a replica answers another name 403 (DNS rebinding)
#
# start starts what is not running and leaves the rest alone, so after a replica or Redis dies,
# `make cluster` again brings it back. stop stops every process that has a pid file here.
set -euo pipefail
cd "$(dirname "$0")/.."

DIR=${CLUSTER_DIR:-build/cluster}
case $DIR in /*) ;; *) DIR=$(pwd)/$DIR ;; esac
PORT=${CLUSTER_PORT:-8088}
RATE=${CLUSTER_RATE:-1000}
REPLICAS=${CLUSTER_REPLICAS:-3}
REDIS_PORT=$((PORT + 1))
NGINX=${NGINX:-/usr/sbin/nginx}
REDIS=${REDIS_SERVER:-/usr/bin/redis-server}
PDESOLIDD=${PDESOLIDD:-build/pdesolidd}
ALLOW_HOST=${CLUSTER_ALLOW_HOST:-}

say() { echo "cluster: $*" >&2; }
die() { say "$*"; exit 1; }

# The status line of GET path from 127.0.0.1:port, or nothing (bash's /dev/tcp: no curl needed).
http_status() {
    local port=$1 path=$2 line=""
    if { exec 3<>"/dev/tcp/127.0.0.1/$port"; } 2>/dev/null; then
        printf 'GET %s HTTP/1.0\r\nHost: 127.0.0.1\r\n\r\n' "$path" >&3
        IFS= read -r -t 2 line <&3 || true
        exec 3<&- 3>&-
    fi
    echo "${line#* }" | cut -c1-3
}

# Waits up to $3 seconds for GET $2 on port $1 to answer 200.
wait_ready() {
    local port=$1 path=$2 tries=$(($3 * 10))
    for ((i = 0; i < tries; i++)); do
        [ "$(http_status "$port" "$path")" = 200 ] && return 0
        sleep 0.1
    done
    return 1
}

# Whether process pid runs and is the program named (pid files outlive reboots, and pids are
# reused). kill -0 alone is not enough: a SIGKILLed process stays a zombie until its parent reaps
# it, and its parent is init once this script has exited, which may take seconds (or, in a
# container whose init does not reap, for ever); kill -0 succeeds on a zombie. Trusting it, `start`
# took a killed replica for a running one and did not restart it (the "dead right after
# listening" restarts: its log still ended in the old process's "listening").
running() {
    local pid=$1 name=$2 stat cmd
    [ -n "$pid" ] && kill -0 "$pid" 2>/dev/null || return 1
    stat=$(cat "/proc/$pid/stat" 2>/dev/null) || return 1
    stat=${stat##*) }                      # the state follows the command's name in parentheses
    [ "${stat%% *}" != Z ] && [ "${stat%% *}" != X ] || return 1
    cmd=$(tr '\0' ' ' <"/proc/$pid/cmdline" 2>/dev/null) || return 1
    [[ $cmd == *"$name"* ]]
}

# The program a pid file names: pdesolidd-2.pid -> pdesolidd, redis.pid -> redis-server.
program() {
    case $(basename "$1") in
    redis.pid) echo redis-server ;;
    nginx.pid) echo nginx ;;
    *) echo pdesolidd ;;
    esac
}

alive() { [ -f "$1" ] && running "$(cat "$1" 2>/dev/null)" "$(program "$1")"; }

start_redis() {
    alive "$DIR/redis.pid" && return 0
    [ -x "$REDIS" ] || die "$REDIS is missing: apt-get install redis-server (or make deps)"
    mkdir -p "$DIR/redis"
    # AOF with an fsync a second: a put survives a crash of the machine but for the last second.
    "$REDIS" --bind 127.0.0.1 --port "$REDIS_PORT" --dir "$DIR/redis" --appendonly yes \
        --appendfsync everysec --save '' --daemonize yes --pidfile "$DIR/redis.pid" \
        --logfile "$DIR/redis.log" --protected-mode yes </dev/null
    for ((i = 0; i < 50; i++)); do
        { exec 3<>"/dev/tcp/127.0.0.1/$REDIS_PORT"; } 2>/dev/null && { exec 3<&- 3>&-; return 0; }
        sleep 0.1
    done
    die "redis-server did not start: $DIR/redis.log"
}

start_replica() {
    local k=$1 port=$((PORT + 1 + $1))
    alive "$DIR/pdesolidd-$k.pid" && return 0
    [ -x "$PDESOLIDD" ] || die "$PDESOLIDD is missing: make"
    # In a session of its own, with nothing of this script's (stdin, the terminal, its process
    # group's signals): it outlives the script. Not a process group leader here, so setsid execs
    # the daemon itself and $! is its pid.
    setsid "$PDESOLIDD" --port "$port" --allow-host="$ALLOW_HOST" --store "redis://127.0.0.1:$REDIS_PORT" --log-format json \
        </dev/null >>"$DIR/pdesolidd-$k.log" 2>&1 &
    echo $! >"$DIR/pdesolidd-$k.pid"
}

# deploy/nginx.conf with this cluster's ports, paths and rate, in a main file of its own.
write_nginx() {
    local site="$DIR/nginx/pdesolid.conf" servers=""
    for ((k = 1; k <= REPLICAS; k++)); do
        servers+="server 127.0.0.1:$((PORT + 1 + k));"$'\n    '
    done
    mkdir -p "$DIR/nginx/cache" "$DIR/nginx/temp"
    awk -v servers="$servers" -v port="$PORT" -v cache="$DIR/nginx/cache" -v rate="$RATE" '
        $0 ~ /^ *server 127\.0\.0\.1:8080;$/ { sub(/server 127\.0\.0\.1:8080;\n?/, servers); print; next }
        $0 ~ /^ *listen 80;$/                { sub(/listen 80;/, "listen 127.0.0.1:" port ";"); print; next }
        $0 ~ /^ *listen \[::\]:80;$/         { next }
        { gsub(/proxy_cache_path \/var\/cache\/nginx\/pdesolid /, "proxy_cache_path " cache " ");
          gsub(/rate=20r\/s/, "rate=" rate "r/s"); gsub(/burst=40 /, "burst=" (2 * rate) " ");
          gsub(/limit_conn pdesolid_conn 32;/, "limit_conn pdesolid_conn 1024;"); print }
    ' deploy/nginx.conf >"$site"
    cat >"$DIR/nginx/nginx.conf" <<EOF
# build/cluster/nginx/nginx.conf, written by deploy/cluster.sh: the main file that Debian's
# /etc/nginx/nginx.conf stands for, with every path under build/cluster/nginx.
worker_processes 2;
error_log $DIR/nginx/error.log;
pid $DIR/nginx.pid;
events { worker_connections 1024; }
http {
    include /etc/nginx/mime.types;
    default_type application/octet-stream;
    access_log $DIR/nginx/access.log;
    client_body_temp_path $DIR/nginx/temp/body;
    proxy_temp_path $DIR/nginx/temp/proxy;
    fastcgi_temp_path $DIR/nginx/temp/fastcgi;
    uwsgi_temp_path $DIR/nginx/temp/uwsgi;
    scgi_temp_path $DIR/nginx/temp/scgi;
    sendfile on;
    include $site;
}
EOF
}

start_nginx() {
    alive "$DIR/nginx.pid" && return 0
    [ -x "$NGINX" ] || die "$NGINX is missing: apt-get install nginx (or make deps)"
    write_nginx
    # As root, nginx's workers run as nobody: let them through to their files.
    if [ "$(id -u)" = 0 ]; then
        chmod 0711 "$DIR" "$DIR/nginx"
        chown -R nobody "$DIR/nginx/cache" "$DIR/nginx/temp" 2>/dev/null || true
    fi
    "$NGINX" -p "$DIR/nginx" -c "$DIR/nginx/nginx.conf" -e "$DIR/nginx/error.log" \
        </dev/null 2>>"$DIR/nginx/error.log" || die "nginx did not start: $DIR/nginx/error.log"
}

stop_pid() {   # pid file, signal, seconds to wait before SIGKILL
    local f=$1 sig=$2 wait=$3
    [ -f "$f" ] || return 0
    local pid name
    pid=$(cat "$f" 2>/dev/null) name=$(program "$f")
    if running "$pid" "$name"; then
        kill "-$sig" "$pid" 2>/dev/null || true
        for ((i = 0; i < wait * 10; i++)); do
            running "$pid" "$name" || break
            sleep 0.1
        done
        ! running "$pid" "$name" || kill -KILL "$pid" 2>/dev/null || true
    fi
    rm -f "$f"
}

case "${1:-}" in
start)
    mkdir -p "$DIR"
    start_redis
    for ((k = 1; k <= REPLICAS; k++)); do start_replica "$k"; done
    for ((k = 1; k <= REPLICAS; k++)); do
        wait_ready $((PORT + 1 + k)) /readyz 20 || die "pdesolidd-$k is not ready: $DIR/pdesolidd-$k.log"
    done
    start_nginx
    wait_ready "$PORT" /readyz 10 || die "nginx does not reach the replicas: $DIR/nginx/error.log"
    {
        echo "nginx $PORT"
        echo "redis $REDIS_PORT"
        for ((k = 1; k <= REPLICAS; k++)); do echo "pdesolidd-$k $((PORT + 1 + k))"; done
    } >"$DIR/ports"
    say "http://127.0.0.1:$PORT/ (nginx) -> replicas on $((PORT + 2))..$((PORT + 1 + REPLICAS)), Redis on $REDIS_PORT; logs and pid files in $DIR/; make cluster-stop stops it"
    ;;
stop)
    stop_pid "$DIR/nginx.pid" QUIT 10
    # Every replica with a pid file, however many this start was asked for, all at once.
    for f in "$DIR"/pdesolidd-*.pid; do stop_pid "$f" TERM 35 & done
    wait
    stop_pid "$DIR/redis.pid" TERM 10    # Redis flushes its AOF on SIGTERM
    say "stopped"
    ;;
status)
    for f in "$DIR"/nginx.pid "$DIR"/redis.pid "$DIR"/pdesolidd-*.pid; do
        [ -f "$f" ] || continue
        if alive "$f"; then echo "$(basename "$f" .pid): running ($(cat "$f"))"; else echo "$(basename "$f" .pid): dead"; fi
    done
    ;;
*)
    echo "usage: deploy/cluster.sh start|stop|status (make cluster, make cluster-stop)" >&2
    exit 2
    ;;
esac
