"""The driver of bench/bench_livez.sh: runs one case against a pdesolidd
started by the script, and prints one tab-separated line of results.

A 200 whose body is shorter than its Content-Length (a stream stopped by
--job-timeout) shows as 200-cut. A case is COPIES concurrent copies of one heavy request (method, path and
body file), optionally after a setup POST /solve whose X-Solid-Id replaces
{id} in the path. While they run, one keep-alive connection polls GET /livez
back to back; its latencies give p50, p99 and max. Around the heavy requests
the daemon's CPU time (utime + stime of /proc/PID/stat, less what the /livez
polling itself cost, calibrated beforehand) and its peak RSS (VmHWM, reset
through /proc/PID/clear_refs first) give the request's cost.

    python3 bench/livez_heavy.py PORT PID NAME METHOD PATH BODYFILE COPIES [SETUP_PATH SETUP_BODYFILE]
"""
import http.client
import os
import re
import sys
import threading
import time

port, pid = int(sys.argv[1]), int(sys.argv[2])
name, method, path, bodyfile, copies = sys.argv[3], sys.argv[4], sys.argv[5], sys.argv[6], int(sys.argv[7])
TCK = os.sysconf("SC_CLK_TCK")


def cpu():
    with open(f"/proc/{pid}/stat") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / TCK  # utime, stime


def status(key):
    with open(f"/proc/{pid}/status") as f:
        for line in f:
            if line.startswith(key):
                return int(line.split()[1]) / 1024  # MiB
    return 0.0


def request(conn, m, p, body=None):
    conn.request(m, p, body=body, headers={"Content-Type": "application/json"} if body is not None else {})
    r = conn.getresponse()
    n, first = 0, b""
    while True:
        chunk = r.read(1 << 20)
        if not chunk:
            break
        if n < 600:
            first += chunk[:600]
        n += len(chunk)
    return r, n, first


def connect():
    return http.client.HTTPConnection("127.0.0.1", port, timeout=120)


def livez_loop(seconds):
    """/livez latencies in ms over a keep-alive connection, for seconds or until stop is set."""
    conn, lat = connect(), []
    end = time.monotonic() + seconds
    while time.monotonic() < end and not stop.is_set():
        t = time.perf_counter()
        request(conn, "GET", "/livez")
        lat.append((time.perf_counter() - t) * 1e3)
    conn.close()
    return lat


def pct(lat, q):
    s = sorted(lat)
    return s[min(len(s) - 1, max(0, int(q * len(s) + 0.999) - 1))] if s else float("nan")


stop = threading.Event()
# Calibration: the CPU the daemon spends on /livez alone, per request, and the idle latency.
c0 = cpu()
idle = livez_loop(1.5)
per_livez = (cpu() - c0) / len(idle)

body = open(bodyfile, "rb").read() if bodyfile != "-" else None
if len(sys.argv) > 9:
    r, n, first = request(connect(), "POST", sys.argv[8], open(sys.argv[9], "rb").read())
    sid = r.getheader("X-Solid-Id") or ""
    if r.status != 200 or not sid:
        print(f"{name}\tsetup failed: {r.status} {first[:200]!r}")
        sys.exit(1)
    path = path.replace("{id}", sid)

results = [None] * copies


def heavy(i):
    t = time.monotonic()
    try:
        r, n, first = request(connect(), method, path, body)
        detail = ""
        if r.status != 200:
            m = re.search(rb'"detail":"([^"]*)"', first)
            detail = m.group(1).decode(errors="replace") if m else first[:120].decode(errors="replace")
        want = r.getheader("Content-Length")
        st = r.status if want is None or int(want) == n else f"{r.status}-cut"  # a stream ended early
        results[i] = (st, time.monotonic() - t, n, detail)
    except Exception as e:  # a stream cut by its deadline, for example
        results[i] = (type(e).__name__, time.monotonic() - t, 0, str(e)[:120])


try:
    with open(f"/proc/{pid}/clear_refs", "w") as f:  # VmHWM := VmRSS
        f.write("5")
except OSError:  # not root: the peak since the start (a fresh daemon; /livez barely moves it)
    pass
rss0, c0 = status("VmRSS"), cpu()
threads = [threading.Thread(target=heavy, args=(i,)) for i in range(copies)]
t0 = time.monotonic()
for t in threads:
    t.start()


def watcher():
    for t in threads:
        t.join()
    stop.set()


threading.Thread(target=watcher).start()
lat = livez_loop(600)
for t in threads:
    t.join()
wall = time.monotonic() - t0
c1, hwm, rss1 = cpu(), status("VmHWM"), status("VmRSS")
cpu_s = max(0.0, c1 - c0 - per_livez * len(lat))
st = sorted({str(x[0]) for x in results})
times = sorted(x[1] for x in results)
size = results[0][2]
detail = next((x[3] for x in results if x[3]), "")
print("\t".join([
    name, ",".join(st) + (f" x{copies}" if copies > 1 else ""), f"{times[-1]:.3f}", f"{size}",
    f"{len(lat)}", f"{pct(lat, 0.5):.2f}", f"{pct(lat, 0.99):.2f}", f"{max(lat) if lat else float('nan'):.2f}",
    f"{pct(idle, 0.99):.2f}", f"{cpu_s:.2f}", f"{hwm - rss0:.1f}", f"{rss1:.1f}", detail]))
