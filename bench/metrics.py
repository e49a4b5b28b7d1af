"""GET /metrics (issue 42): what one scrape of a robot's rover_web costs, and a scraper for the other
benches (bench/teleop.py and bench/events.py --scrape-metrics 5: their figures with Prometheus
scraping every 5 s).

    .venv/bin/python bench/metrics.py [--scrapes 200] [--seconds 4]

The app is `flask run` in its own process with the simulated rover (rover_web.sim, its topics
tracked on /api/status). Server CPU per scrape: the app's CPU over a burst of back-to-back scrapes,
less its CPU at rest over a window as long (the simulator's topics, the status loop), divided by
the scrapes. Also the scrape's wall time (p50/p99, on this machine, HTTP included), its size and
how many series it holds. Target: <= 5 ms of server CPU per scrape. One JSON line last.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import threading
import time

import requests
from common import ROOT, Server, machine, percentile, ros_env, stop_process


class Scraper:
    """GET `url`/metrics every `period_s` on a thread, as Prometheus would, until stop()."""

    def __init__(self, url: str, period_s: float, headers: dict | None = None):
        self.url, self.period_s, self.headers = url, period_s, headers or {}
        self.scrapes = 0
        self.failures = 0
        self._done = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def _run(self) -> None:
        while not self._done.wait(self.period_s):
            try:
                ok = requests.get(self.url + "/metrics", headers=self.headers, timeout=5).ok
            except requests.RequestException:
                ok = False
            self.scrapes += ok
            self.failures += not ok

    def stop(self) -> str:
        self._done.set()
        self._thread.join(10)
        return f"Prometheus-like scrapes of /metrics every {self.period_s:g} s: {self.scrapes} ({self.failures} failed)"


def scrape_cost(server: Server, scrapes: int, seconds: float, headers: dict | None = None) -> dict:
    """Server CPU per scrape (the burst's less the rest's), wall p50/p99, size and series."""
    session = requests.Session()
    body = session.get(server.url + "/metrics", headers=headers, timeout=10).text  # warm
    cpu0, t0 = server.cpu_seconds(), time.monotonic()
    time.sleep(seconds)
    rest_rate = (server.cpu_seconds() - cpu0) / (time.monotonic() - t0)
    walls = []
    cpu0, t0 = server.cpu_seconds(), time.monotonic()
    for _ in range(scrapes):
        t = time.perf_counter()
        reply = session.get(server.url + "/metrics", headers=headers, timeout=10)
        walls.append(time.perf_counter() - t)
        reply.raise_for_status()
        body = reply.text
    elapsed = time.monotonic() - t0
    cpu = (server.cpu_seconds() - cpu0 - rest_rate * elapsed) / scrapes
    series = sum(1 for line in body.splitlines() if line and not line.startswith("#"))
    return {"scrapes": scrapes, "cpu_ms_per_scrape": round(cpu * 1000, 3),
            "rest_cpu_pct": round(rest_rate * 100, 1), "wall_p50_ms": round(percentile(walls, 50) * 1000, 3),
            "wall_p99_ms": round(percentile(walls, 99) * 1000, 3), "bytes": len(body.encode()), "series": series}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--scrapes", type=int, default=200)
    parser.add_argument("--seconds", type=float, default=4.0, help="the window at rest the burst is measured against")
    args = parser.parse_args()
    env = ros_env()
    sim = subprocess.Popen([sys.executable, "-m", "rover_web.sim", "--only", "rover"], cwd=ROOT, env=env,
                           stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    server = None
    try:
        if "simulator running" not in sim.stdout.readline():
            raise RuntimeError("the simulator did not start")
        server = Server(env)
        deadline = time.monotonic() + 15
        while requests.get(server.url + "/api/status", timeout=5).json()["robot_link"] != "ok":
            if time.monotonic() > deadline:
                raise RuntimeError("the simulator's topics never reached the app")
            time.sleep(0.2)
        print(f"# metrics bench on {machine()}: one robot's rover_web with the simulated rover; shared machine")
        result = scrape_cost(server, args.scrapes, args.seconds)
        print(f"one robot's /metrics: {result['cpu_ms_per_scrape']:.2f} ms server CPU per scrape (target <= 5), "
              f"wall p50 {result['wall_p50_ms']:.2f} ms p99 {result['wall_p99_ms']:.2f} ms, {result['bytes']} bytes, "
              f"{result['series']} series; the app at rest {result['rest_cpu_pct']:.1f}% of a core")
        print(json.dumps({"bench": "metrics", **result}))
    finally:
        if server is not None:
            server.stop()
        stop_process(sim)


if __name__ == "__main__":
    main()
