#!/usr/bin/env python3
"""resume_time.py - time from odometryd's process start to its first tick (issue 17).

Starts `odometryd --config CONFIG` N times, each with NOTIFY_SOCKET pointing at a datagram
socket of ours: odometryd sends READY=1 after the loop's first tick (firmware/src/watchdog.cpp),
so spawn -> READY=1 is process start to the first tick. Each run is then stopped with SIGTERM (a
clean stop writes the state record, which the next run is offered) and, with --kill, SIGKILL.
Prints each time, the median and the maximum, and the daemon's resume line of the last run.

Usage: resume_time.py ODOMETRYD CONFIG [-n N] [--kill] [--settle S]
"""
import argparse
import os
import signal
import socket
import statistics
import subprocess
import sys
import tempfile
import time


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("odometryd")
    ap.add_argument("config")
    ap.add_argument("-n", type=int, default=20, help="runs (default 20)")
    ap.add_argument("--kill", action="store_true", help="stop each run with SIGKILL")
    ap.add_argument("--settle", type=float, default=0.3, help="[s] run time after READY=1")
    a = ap.parse_args()
    d = tempfile.mkdtemp(prefix="resume_time.")
    path = os.path.join(d, "notify")
    s = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
    s.bind(path)
    s.settimeout(30.0)
    times, last_log = [], ""
    for i in range(a.n):
        env = dict(os.environ, NOTIFY_SOCKET=path)
        log = open(os.path.join(d, f"log{i}"), "w+")
        t0 = time.monotonic()
        p = subprocess.Popen([a.odometryd, "--config", a.config], env=env, stdout=log,
                             stderr=subprocess.STDOUT)
        while True:
            try:
                msg = s.recv(4096).decode(errors="replace")
            except socket.timeout:
                p.kill()
                print(f"run {i}: no READY=1 within 30 s", file=sys.stderr)
                return 1
            if "READY=1" in msg.split("\n"):
                break
        times.append(time.monotonic() - t0)
        time.sleep(a.settle)
        p.send_signal(signal.SIGKILL if a.kill else signal.SIGTERM)
        p.wait()
        log.seek(0)
        last_log = [l for l in log.read().splitlines() if "resume:" in l]
        print(f"run {i}: {times[-1] * 1e3:.1f} ms  {last_log[0] if last_log else ''}")
    print(f"start -> first tick (READY=1): median {statistics.median(times) * 1e3:.1f} ms, "
          f"max {max(times) * 1e3:.1f} ms over {len(times)} runs; load average "
          f"{os.getloadavg()[0]:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
