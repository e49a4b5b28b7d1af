"""ROS publish (another process, 100 Hz) -> SSE frame at 1, 10 and 50 clients: latency, server CPU, RSS.

    .venv/bin/python bench/events.py [--seconds 10]

Latency runs from the publisher's stamp to "arrived" (the frame in the client's socket, by the
kernel's receive timestamp) and to "woken" (this one process, which holds every client, woken with
the socket readable); see common.SseFleet.
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import time

from common import ROOT, Server, SseFleet, machine, percentile, ros_env, summary_ms


def run(clients: int, seconds: float, env: dict) -> dict:
    server = Server(env)
    fleet = SseFleet(server.url, "/api/events?channels=odom", clients)
    try:
        fleet.poll(0.5, lambda *a: None)  # snapshots
        count = int(seconds * 100)
        pub = subprocess.Popen([sys.executable, str(ROOT / "bench" / "odom_publisher.py"), "--rate", "100",
                                "--count", str(count)], env=env, stdout=subprocess.PIPE, text=True)
        assert pub.stdout.readline().strip() == "publishing"
        arrived: list[float] = []
        woken: list[float] = []

        def on_event(t_woken, t_arrived, name, data):
            if name == "odom" and data.get("stamp"):
                arrived.append(t_arrived - data["stamp"])
                woken.append(t_woken - data["stamp"])

        cpu0, t0 = server.cpu_seconds(), time.monotonic()
        fleet.poll(seconds + 1.0, on_event)
        cpu1, t1 = server.cpu_seconds(), time.monotonic()
        pub.wait(10)
        return {"clients": clients, "arrived": arrived, "woken": woken, "expected": count * clients,
                "cpu_pct": 100 * (cpu1 - cpu0) / (t1 - t0), "rss_mb": server.rss_mb()}
    finally:
        fleet.close()
        server.stop()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--seconds", type=float, default=10.0)
    parser.add_argument("--clients", type=int, nargs="*", default=[1, 10, 50])
    args = parser.parse_args()
    env = ros_env(ROVER_WEB_ODOM_MAX_HZ="1000", ROVER_WEB_SSE_MAX_CLIENTS="200", ROVER_WEB_STATUS_PERIOD_S="1.0")
    print(f"# events bench on {machine()}: /odom at 100 Hz from another process -> SSE `odom` frame")
    for n in args.clients:
        r = run(n, args.seconds, env)
        lat = r["arrived"]
        woken = sorted(r["woken"])
        print(f"clients {n:3d}: arrived {summary_ms(lat)}  woken p50 {statistics.median(woken) * 1000:.3f} "
              f"p99 {percentile(woken, 99) * 1000:.3f} ms  received {len(lat)}/{r['expected']}  "
              f"server CPU {r['cpu_pct']:5.1f}% of one core  RSS {r['rss_mb']:.0f} MB", flush=True)


if __name__ == "__main__":
    main()
