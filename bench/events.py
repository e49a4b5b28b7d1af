"""ROS publish (another process, 100 Hz) -> SSE frame at 1, 10 and 50 clients: latency, server CPU, RSS.

    .venv/bin/python bench/events.py [--seconds 10]
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import time

from common import ROOT, Server, SseFleet, machine, ros_env, summary_ms


def run(clients: int, seconds: float, env: dict) -> dict:
    server = Server(env)
    fleet = SseFleet(server.url, "/api/events?channels=odom", clients)
    try:
        fleet.poll(0.5, lambda *a: None)  # snapshots
        count = int(seconds * 100)
        pub = subprocess.Popen([sys.executable, str(ROOT / "bench" / "odom_publisher.py"), "--rate", "100",
                                "--count", str(count)], env=env, stdout=subprocess.PIPE, text=True)
        assert pub.stdout.readline().strip() == "publishing"
        latencies: list[float] = []

        def on_event(t, name, data):
            if name == "odom" and data.get("stamp"):
                latencies.append(t - data["stamp"])

        cpu0, t0 = server.cpu_seconds(), time.monotonic()
        fleet.poll(seconds + 1.0, on_event)
        cpu1, t1 = server.cpu_seconds(), time.monotonic()
        pub.wait(10)
        return {"clients": clients, "latencies": latencies, "expected": count * clients,
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
        lat = r["latencies"]
        print(f"clients {n:3d}: {summary_ms(lat)}  received {len(lat)}/{r['expected']}  "
              f"server CPU {r['cpu_pct']:5.1f}% of one core  RSS {r['rss_mb']:.0f} MB", flush=True)


if __name__ == "__main__":
    main()
