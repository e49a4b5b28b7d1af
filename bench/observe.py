"""Observability cost: /rosout at 1,000 lines/s, a 100 Hz field plotted, both; and RSS after 100,000 lines.

Phases (each `--seconds` long, server CPU as % of one core, one SSE client on rosout and plot):
idle; 1,000 log lines/s; a 100 Hz Odometry field plotted; both. Then a flood of 100,000 lines
as fast as one rclpy process logs them, with the server's RSS before and after (the ring holds
ROVER_WEB_ROSOUT_KEEP lines, so memory must stay flat).

    .venv/bin/python bench/observe.py [--seconds 10]
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import threading
import time

import requests
from common import ROOT, Server, SseFleet, machine, ros_env, start_peer

ODOM = "/bench/odom"


def received(server: Server) -> int:
    return requests.get(server.url + "/api/rosout", params={"limit": 1}, timeout=5).json()["received"]


def measure(server: Server, fleet: SseFleet, seconds: float) -> dict:
    counts: dict[str, int] = {}
    lines = [0]

    def on_event(_woken, _arrived, name, data):
        counts[name] = counts.get(name, 0) + 1
        if name == "rosout":
            lines[0] += len(data["lines"])

    fleet.poll(0.3, lambda *_: None)  # what queued in the socket between phases is not this phase's
    r0, cpu0, t0 = received(server), server.cpu_seconds(), time.monotonic()
    fleet.poll(seconds, on_event)
    r1, cpu1, t1 = received(server), server.cpu_seconds(), time.monotonic()
    dt = t1 - t0
    return {"cpu_pct": 100 * (cpu1 - cpu0) / dt, "log_lines_per_s": (r1 - r0) / dt,
            "rosout_events_per_s": counts.get("rosout", 0) / dt, "rosout_lines_per_s_sse": lines[0] / dt,
            "plot_events_per_s": counts.get("plot", 0) / dt, "rss_mb": server.rss_mb()}


def show(name: str, m: dict) -> None:
    print(f"{name:<22} server CPU {m['cpu_pct']:5.1f}%  /rosout in {m['log_lines_per_s']:7.1f} lines/s  "
          f"SSE rosout {m['rosout_events_per_s']:4.1f} events/s ({m['rosout_lines_per_s_sse']:6.1f} lines/s)  "
          f"plot {m['plot_events_per_s']:4.1f} events/s  RSS {m['rss_mb']:.0f} MB", flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--seconds", type=float, default=10.0)
    parser.add_argument("--flood", type=int, default=100_000)
    args = parser.parse_args()
    env = ros_env()
    print(machine())
    server = Server(env)
    fleet = SseFleet(server.url, "/api/events?channels=rosout,plot", 1)
    procs: list[subprocess.Popen] = []
    try:
        time.sleep(2.0)
        show("idle", measure(server, fleet, args.seconds))

        n = int(1000 * (args.seconds + 4))
        logs = start_peer("rosout_publisher.py", env, "--rate", "1000", "--count", str(n))
        procs.append(logs)
        time.sleep(1.0)
        show("1,000 log lines/s", measure(server, fleet, args.seconds))
        logs.wait(60)

        count = int(100 * (2 * args.seconds + 30))
        odom = subprocess.Popen([sys.executable, str(ROOT / "bench" / "odom_publisher.py"), "--topic", ODOM,
                                 "--rate", "100", "--count", str(count)], cwd=ROOT, env=env,
                                stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
        procs.append(odom)
        deadline = time.monotonic() + 20
        while True:  # the topic must be in the graph before a series can be asked for
            reply = requests.get(server.url + "/api/plot", params={"topic": ODOM, "field": "pose.pose.position.x",
                                                                   "type": "nav_msgs/msg/Odometry"}, timeout=5)
            if reply.ok or time.monotonic() > deadline:
                break
            time.sleep(0.2)
        reply.raise_for_status()
        if "publishing" not in odom.stdout.readline():
            raise RuntimeError("odometry publisher did not start")
        keep = threading.Event()

        def keep_alive():  # as an open /plot page does
            while not keep.wait(5):
                requests.get(server.url + "/api/plot", params={"topic": ODOM, "field": "pose.pose.position.x",
                                                               "seconds": 1}, timeout=5)

        threading.Thread(target=keep_alive, daemon=True).start()
        time.sleep(1.0)
        show("100 Hz field plotted", measure(server, fleet, args.seconds))
        logs = start_peer("rosout_publisher.py", env, "--rate", "1000", "--count", str(n))
        procs.append(logs)
        time.sleep(1.0)
        show("both", measure(server, fleet, args.seconds))
        body = requests.get(server.url + "/api/plot", params={"topic": ODOM, "field": "pose.pose.position.x",
                                                              "seconds": 5}, timeout=5).json()
        print(f"  plot: {len(body['v'])} points in the last 5 s (100 Hz → 500 expected)")
        logs.wait(60)
        keep.set()

        rss0 = server.rss_mb()
        before = received(server)
        flood = start_peer("rosout_publisher.py", env, "--rate", "0", "--count", str(args.flood))
        procs.append(flood)
        took = flood.stdout.readline().strip()
        flood.wait(120)
        time.sleep(2.0)
        got = received(server) - before
        kept = requests.get(server.url + "/api/rosout", params={"limit": 1}, timeout=5).json()
        print(f"flood: {args.flood} lines logged ({took} s), {got} received by the server; ring holds "
              f"{kept['kept']} (keep {kept['keep']}); RSS {rss0:.0f} MB before, {server.rss_mb():.0f} MB after")
    finally:
        for proc in procs:
            if proc.poll() is None:
                proc.kill()
            proc.wait(5)
        fleet.close()
        server.stop()


if __name__ == "__main__":
    main()
