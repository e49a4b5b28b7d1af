"""Calls to other nodes through the app (issue 19): a Trigger service call, a parameter list and a
parameter set, each N times one at a time, against tests/support/peers/admin_peer.py in its own
process. Times are from before the request to its answer (which includes the operator-log commit
for calls and sets).

    .venv/bin/python bench/ros_admin.py [--count 200]
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import time

import requests
from common import ROOT, Server, percentile, ros_env

PEER = "/api/nodes/peer_ns/param_peer"


def timed(count: int, fn) -> list[float]:
    out = []
    for i in range(count):
        t0 = time.perf_counter()
        response = fn(i)
        out.append((time.perf_counter() - t0) * 1000)
        if response.status_code != 200:
            raise RuntimeError(f"{response.status_code} {response.text[:200]}")
    return out


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--count", type=int, default=200)
    args = parser.parse_args()
    env = ros_env()
    peer = subprocess.Popen([sys.executable, str(ROOT / "tests/support/peers/admin_peer.py"), "/peer_ns", "param_peer"],
                            stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, env=env, cwd=ROOT)
    assert json.loads(peer.stdout.readline())["event"] == "ready"
    server = Server(env)
    session = requests.Session()
    try:
        deadline = time.monotonic() + 20
        while session.get(server.url + PEER + "/parameters", timeout=10).status_code != 200:
            if time.monotonic() > deadline:
                raise RuntimeError("the app did not see the peer")
            time.sleep(0.2)
        cpu0 = server.cpu_seconds()
        results = {
            "service call (Trigger)": timed(args.count, lambda i: session.post(
                server.url + "/api/services/call", json={"service": "/peer_ns/trigger", "type": "std_srvs/srv/Trigger"},
                timeout=10)),
            "parameter list (14 parameters)": timed(args.count, lambda i: session.get(
                server.url + PEER + "/parameters", timeout=10)),
            "parameter set (integer)": timed(args.count, lambda i: session.put(
                server.url + PEER + "/parameters/count", json={"value": i}, timeout=10)),
        }
        cpu_ms = (server.cpu_seconds() - cpu0) * 1000 / (3 * args.count)
        print("| | median | p90 | p99 | max |\n| --- | --- | --- | --- | --- |")
        for name, times in results.items():
            print(f"| {name} | {statistics.median(times):.1f} ms | {percentile(times, 90):.1f} ms | "
                  f"{percentile(times, 99):.1f} ms | {max(times):.1f} ms |")
        print(f"\nserver CPU {cpu_ms:.1f} ms per request, RSS {server.rss_mb():.0f} MB")
    finally:
        server.stop()
        peer.stdin.write("quit\n")
        peer.stdin.flush()
        peer.wait(10)


if __name__ == "__main__":
    main()
