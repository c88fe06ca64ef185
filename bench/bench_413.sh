#!/usr/bin/env bash
# The urllib 413 check (issue 8, docs/BENCHMARKS.md): Python's urllib writes a
# whole request body before it reads, so a daemon that answers 413 and closes
# before draining the body leaves it a broken pipe instead of the answer.
# Starts build/pdesolidd (or $PDESOLIDD) on a free loopback port with
# --max-body 1MiB and POSTs 2 MiB to /solve TRIES times (20).
#   bench/bench_413.sh        (after `make`; not run by `make test`)
set -euo pipefail
cd "$(dirname "$0")/.."
TRIES=${TRIES:-20} BIN=${PDESOLIDD:-build/pdesolidd}
command -v python3 >/dev/null || { echo "bench_413: python3 is not installed; skipped"; exit 0; }
[ -x "$BIN" ] || { echo "bench_413: $BIN is missing (make)"; exit 1; }
LOG=$(mktemp)
"$BIN" --port 0 --max-body 1MiB --quiet 2>"$LOG" & D=$!
trap 'kill $D 2>/dev/null; wait $D 2>/dev/null; rm -f "$LOG"' EXIT
PORT=""
for _ in $(seq 100); do
  PORT=$(sed -n 's|.*listening on http://127.0.0.1:\([0-9]*\)/.*|\1|p' "$LOG")
  [ -n "$PORT" ] && break
  sleep 0.05
done
[ -n "$PORT" ] || { echo "bench_413: pdesolidd did not start:"; cat "$LOG"; exit 1; }
python3 - "$PORT" "$TRIES" <<'PY'
import json, sys, urllib.error, urllib.request
port, tries = int(sys.argv[1]), int(sys.argv[2])
body = b" " * (2 << 20)
read, other = 0, {}
for _ in range(tries):
    req = urllib.request.Request(f"http://127.0.0.1:{port}/solve", data=body, method="POST",
                                 headers={"Content-Type": "application/json"})
    try:
        with urllib.request.urlopen(req, timeout=10) as r:
            k = f"status {r.status}"
    except urllib.error.HTTPError as e:
        ok = e.code == 413
        if ok:
            try:
                json.loads(e.read())
            except (ValueError, OSError):
                ok = False
        k = "413" if ok else f"status {e.code}"
    except (urllib.error.URLError, OSError) as e:
        k = type(getattr(e, "reason", e)).__name__
    if k == "413":
        read += 1
    else:
        other[k] = other.get(k, 0) + 1
print(f"413 read {read} of {tries}" + (f" (otherwise: {', '.join(f'{k} x{n}' for k, n in other.items())})" if other else ""))
PY
