#!/usr/bin/env python3
"""STOP latency of `sketchnav ui` while many idle (slowloris) connections are held.

Starts `sketchnav ui --port 0` on 127.0.0.1, opens --idle connections that each send half a
request line and then one header byte every --trickle-s seconds (so the server's 5 s read
timeout never closes them), optionally starts a simulated run from the page's API, and then
times --trials POST /api/run/stop requests, each on a fresh connection. Loopback only; the
connection count, the trial count and the whole run's time are bounded.

  bench/ui/stop_latency.py --exe build/release/apps/sketchnav --idle 500 --trials 20 --json

Prints one JSON object (--json) or a line per figure; exits 1 when a STOP was not answered
200 within --bound-ms, or when fewer idle connections than asked were still held by the
server when the STOPs were sent (the measurement would then not be of the asked load).
"""
import argparse
import json
import resource
import select
import socket
import subprocess
import sys
import threading
import time

HOST = "127.0.0.1"


def http(port, method, path, body=None, timeout=5.0):
    """One request on a fresh connection; (status, body, seconds) or (None, error, seconds)."""
    data = b"" if body is None else json.dumps(body).encode()
    req = (f"{method} {path} HTTP/1.1\r\nHost: {HOST}:{port}\r\n"
           f"Content-Type: application/json\r\nContent-Length: {len(data)}\r\n"
           "Connection: close\r\n\r\n").encode() + data
    t0 = time.monotonic()
    try:
        with socket.create_connection((HOST, port), timeout=timeout) as s:
            s.sendall(req)
            out = b""
            while True:
                chunk = s.recv(65536)
                if not chunk:
                    break
                out += chunk
    except OSError as e:
        return None, str(e), time.monotonic() - t0
    dt = time.monotonic() - t0
    head, _, rest = out.partition(b"\r\n\r\n")
    try:
        status = int(head.split(b" ", 2)[1])
    except (IndexError, ValueError):
        return None, out[:200].decode(errors="replace"), dt
    return status, rest.decode(errors="replace"), dt


class Idle:
    """--idle connections holding half a request, one header byte now and then."""

    def __init__(self, port, n, trickle_s):
        self.socks = []
        self.trickle_s = trickle_s
        self.stop = threading.Event()
        for i in range(n):
            s = socket.create_connection((HOST, port), timeout=5.0)
            s.sendall(b"GET / HTTP/1.1\r\nX-a: ")
            self.socks.append(s)
            # httplib listens with a small backlog: connecting faster than it accepts only
            # makes the kernel drop SYNs (1 s retransmits); that slows this tool, not STOP.
            time.sleep(0.002)
        self.thread = threading.Thread(target=self._trickle, daemon=True)
        self.thread.start()

    def _trickle(self):
        while not self.stop.wait(self.trickle_s):
            for s in self.socks:
                try:
                    s.send(b"a")
                except OSError:
                    pass

    def held(self):
        """How many the server has not closed (no EOF, no reset, nothing answered), and what
        the first closed one received."""
        n, first = 0, None
        for s in self.socks:
            r, _, _ = select.select([s], [], [], 0)
            if not r:
                n += 1
            elif first is None:
                try:
                    first = s.recv(200, socket.MSG_PEEK).decode(errors="replace") or "EOF"
                except OSError as e:
                    first = str(e)
        return n, first

    def close(self):
        self.stop.set()
        self.thread.join()
        for s in self.socks:
            s.close()


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--exe", default="build/release/apps/sketchnav")
    ap.add_argument("--idle", type=int, default=500, help="idle connections (1..1000)")
    ap.add_argument("--trials", type=int, default=20, help="STOP requests timed (1..200)")
    ap.add_argument("--gap-s", type=float, default=0.25, help="pause between STOPs [s]")
    ap.add_argument("--trickle-s", type=float, default=2.0,
                    help="a byte on every idle connection this often [s] (< the server's 5 s)")
    ap.add_argument("--with-run", action="store_true",
                    help="start a simulated corridor run first (STOP then ends it)")
    ap.add_argument("--bound-ms", type=float, default=200.0)
    ap.add_argument("--json", action="store_true")
    a = ap.parse_args()
    if not 1 <= a.idle <= 1000 or not 1 <= a.trials <= 200:
        ap.error("--idle must be in 1..1000 and --trials in 1..200")
    soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    if soft < a.idle + 64:
        resource.setrlimit(resource.RLIMIT_NOFILE, (min(hard, a.idle + 64), hard))

    ui = subprocess.Popen([a.exe, "--json", "ui", "--port", "0"], stdout=subprocess.PIPE,
                          stderr=subprocess.DEVNULL, text=True)
    deadline = time.monotonic() + 180  # the whole measurement, whatever happens
    idle = None
    try:
        text = ""
        while True:  # the first JSON object on stdout (printed over several lines)
            line = ui.stdout.readline()
            if not line:
                sys.exit("stop_latency: `sketchnav ui` ended before saying its port")
            text += line
            try:
                port = json.loads(text)["port"]
                break
            except json.JSONDecodeError:
                continue
        if a.with_run:
            st, body, _ = http(port, "POST", "/api/run/start",
                               {"world": "corridor", "seed": 1, "max_time_s": 120})
            if st != 200:
                sys.exit(f"stop_latency: run start answered {st}: {body[:200]}")
            # Running and ticking: the run is driving when the STOPs come.
            while True:
                s = json.loads(http(port, "GET", "/api/run/state")[1])
                if s.get("status") == "running" and s.get("t", 0) > 0:
                    break
                if s.get("status") not in ("starting", "running") or \
                        time.monotonic() > deadline - 60:
                    sys.exit("stop_latency: the run did not start")
                time.sleep(0.2)
        idle = Idle(port, a.idle, a.trickle_s)
        time.sleep(0.5)  # let the server accept the last ones
        held_before, closed_before = idle.held()
        times, failures = [], []
        for i in range(a.trials):
            if time.monotonic() > deadline:
                failures.append("time bound reached")
                break
            st, body, dt = http(port, "POST", "/api/run/stop", {}, timeout=2.0)
            if st != 200:
                failures.append(f"trial {i}: {st} {body[:120]}")
            times.append(dt * 1000.0)
            time.sleep(a.gap_s)
        held_after, closed_after = idle.held()
        state = json.loads(http(port, "GET", "/api/run/state")[1])
    finally:
        if idle:
            idle.close()
        ui.terminate()
        try:
            ui.wait(10)
        except subprocess.TimeoutExpired:
            ui.kill()
    times.sort()
    res = {
        "idle_connections": a.idle,
        "held_before": held_before,
        "held_after": held_after,
        "first_closed_got": closed_after or closed_before,
        "with_run": a.with_run,
        "run_status_after": state.get("status"),
        "trials": len(times),
        "stop_ms_median": round(times[len(times) // 2], 2) if times else None,
        "stop_ms_max": round(times[-1], 2) if times else None,
        "stop_ms_min": round(times[0], 2) if times else None,
        "bound_ms": a.bound_ms,
        "failures": failures,
    }
    ok = (not failures and times and times[-1] <= a.bound_ms and held_before == a.idle
          and held_after == a.idle
          and (not a.with_run or state.get("status") in ("stopping", "stopped")))
    res["ok"] = bool(ok)
    if a.json:
        print(json.dumps(res))
    else:
        for k, v in res.items():
            print(f"{k}: {v}")
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
