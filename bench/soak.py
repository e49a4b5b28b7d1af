"""Soak: the simulator and a day's worth of use in miniature, sampled every minute; prints the slopes.

    .venv/bin/python bench/soak.py --minutes 60 [--sample-s 60]

Running against `flask --app rover_web run` and `python -m rover_web.sim` (both in their own
processes, on a private ROS domain):
- three dashboards' worth of SSE: three streams on the dashboard's own channel list;
- one MJPEG viewer of the simulated camera at 320 px wide;
- a joystick (the teleop WebSocket) driving at 20 Hz for 10 s of every minute, then closed;
- a waypoint added every 3 s near the simulated boat (the mission cleared every 100 adds).

Every `--sample-s` it samples the server's RSS, threads, open file descriptors and CPU, and the SSE
latency of the simulator's /odom (its stamp to the frame's arrival in the socket). At the end it
prints each sample and, by least squares over the run after the first sample (start-up), the
slope per hour of RSS, threads and descriptors and of the latency p99. Targets (issue 21): RSS
growth under 5 MB an hour, threads and descriptors flat, latency p99 steady.
"""

from __future__ import annotations

import argparse
import json
import re
import statistics
import subprocess
import sys
import threading
import time

import requests
import websocket
from common import ROOT, Server, SseFleet, machine, percentile, ros_env

# The simulator's GPS origin (rover_web.sim.rover): waypoints stay near the boat.
LAT0, LON0 = 27.3742443, -82.4500873
WALL_MINUS_MONOTONIC = time.time() - time.monotonic()


class Simulator:
    def __init__(self, env: dict):
        self.proc = subprocess.Popen([sys.executable, "-m", "rover_web.sim"], cwd=ROOT, env=env,
                                     stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        self.proc.stdout.readline()  # its first line says it is up
        threading.Thread(target=self.proc.stdout.read, daemon=True).start()  # keep its pipe drained

    def stop(self) -> None:
        self.proc.terminate()
        try:
            self.proc.wait(10)
        except subprocess.TimeoutExpired:
            self.proc.kill()


class Workload:
    """The MJPEG viewer, the joystick and the waypoint writer, each on its own thread."""

    def __init__(self, url: str):
        self.url = url
        self.stop = threading.Event()
        self.errors: list[str] = []
        self.counts = {"mjpeg_bytes": 0, "drives": 0, "waypoints": 0, "http_5xx": 0}
        self.threads = [threading.Thread(target=f, daemon=True)
                        for f in (self._mjpeg, self._joystick, self._waypoints)]
        for t in self.threads:
            t.start()

    def _note(self, what: str) -> None:
        if len(self.errors) < 50:
            self.errors.append(f"{time.strftime('%H:%M:%S')} {what}")

    def _mjpeg(self) -> None:
        while not self.stop.is_set():
            try:
                with requests.get(self.url + "/stream", params={"topic": "/camera/image_raw", "width": 320},
                                  stream=True, timeout=10) as response:
                    for chunk in response.iter_content(65536):
                        self.counts["mjpeg_bytes"] += len(chunk)
                        if self.stop.is_set():
                            return
            except requests.RequestException as exc:
                self._note(f"mjpeg: {exc}")
                self.stop.wait(1)

    def _joystick(self) -> None:
        ws_url = self.url.replace("http://", "ws://") + "/ws/teleop?name=soak"
        while not self.stop.is_set():
            minute_start = time.monotonic()
            try:
                ws = websocket.create_connection(ws_url, timeout=10)
                epoch = 0
                end = time.monotonic() + 10
                while time.monotonic() < end and not self.stop.is_set():
                    ws.send(json.dumps({"linear": 0.3, "angular": 0.2, "epoch": epoch}))
                    ws.settimeout(0.0)
                    try:
                        while True:  # read what came, keep the newest epoch
                            message = json.loads(ws.recv())
                            epoch = message.get("epoch", epoch)
                    except (websocket.WebSocketException, BlockingIOError, OSError, ValueError):
                        pass
                    self.counts["drives"] += 1
                    time.sleep(0.05)
                ws.close()
            except (websocket.WebSocketException, OSError) as exc:
                self._note(f"joystick: {exc}")
            self.stop.wait(max(0.0, 60 - (time.monotonic() - minute_start)))

    def _waypoints(self) -> None:
        n = 0
        while not self.stop.wait(3):
            try:
                if n and n % 100 == 0:
                    requests.delete(self.url + "/api/waypoints", timeout=10)
                offset = (n % 50) * 1e-5
                response = requests.post(self.url + "/api/waypoints",
                                         json={"lat": LAT0 + offset, "lng": LON0 + offset}, timeout=10)
                if response.status_code >= 500:
                    self.counts["http_5xx"] += 1
                    self._note(f"waypoint: {response.status_code} {response.text[:120]}")
                elif response.ok:
                    self.counts["waypoints"] += 1
                n += 1
            except requests.RequestException as exc:
                self._note(f"waypoint: {exc}")

    def close(self) -> None:
        self.stop.set()
        for t in self.threads:
            t.join(15)


def slope_per_hour(xs_s: list[float], ys: list[float]) -> float:
    if len(xs_s) < 2:
        return float("nan")
    mx, my = statistics.fmean(xs_s), statistics.fmean(ys)
    sxx = sum((x - mx) ** 2 for x in xs_s)
    return 3600 * sum((x - mx) * (y - my) for x, y in zip(xs_s, ys, strict=True)) / sxx if sxx else 0.0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--minutes", type=float, default=60.0)
    parser.add_argument("--sample-s", type=float, default=60.0)
    args = parser.parse_args()
    env = ros_env()
    print(f"# soak bench on {machine()}: {args.minutes:g} min, a sample every {args.sample_s:g} s", flush=True)
    sim = Simulator(env)
    server = Server(env)
    channels = re.search(r'data-channels="([^"]*)"', requests.get(server.url + "/", timeout=10).text).group(1)
    fleet = SseFleet(server.url, f"/api/events?channels={channels}", 3)
    work = Workload(server.url)
    samples = []
    started = time.monotonic()
    try:
        while time.monotonic() - started < args.minutes * 60:
            latencies: list[float] = []

            def on_event(t_woken, t_arrived, name, data, latencies=latencies):
                if name == "odom" and data.get("stamp"):
                    latencies.append(t_arrived + WALL_MINUS_MONOTONIC - data["stamp"])

            cpu0, t0 = server.cpu_seconds(), time.monotonic()
            fleet.poll(args.sample_s, on_event)
            cpu1, t1 = server.cpu_seconds(), time.monotonic()
            sample = {"t_s": t1 - started, "rss_mb": server.rss_mb(), "threads": server.ps.num_threads(),
                      "fds": server.ps.num_fds(), "cpu_pct": 100 * (cpu1 - cpu0) / (t1 - t0),
                      "odom_events": len(latencies),
                      "p50_ms": 1000 * statistics.median(latencies) if latencies else float("nan"),
                      "p99_ms": 1000 * percentile(latencies, 99) if latencies else float("nan")}
            samples.append(sample)
            print(f"{sample['t_s'] / 60:6.1f} min  RSS {sample['rss_mb']:6.1f} MB  threads {sample['threads']:3d}  "
                  f"fds {sample['fds']:4d}  CPU {sample['cpu_pct']:5.1f}%  odom SSE {sample['odom_events']:5d} "
                  f"p50 {sample['p50_ms']:6.2f} p99 {sample['p99_ms']:6.2f} ms  "
                  f"drives {work.counts['drives']} waypoints {work.counts['waypoints']} "
                  f"mjpeg {work.counts['mjpeg_bytes'] / 1e6:.0f} MB  5xx {work.counts['http_5xx']}", flush=True)
    finally:
        work.close()
        fleet.close()
        server.stop()
        sim.stop()
    steady = samples[1:] if len(samples) > 2 else samples
    xs = [s["t_s"] for s in steady]
    print("# slopes per hour, from the second sample on (the first includes start-up):")
    for key, unit in (("rss_mb", "MB"), ("threads", "threads"), ("fds", "descriptors"), ("p99_ms", "ms p99")):
        ys = [s[key] for s in steady]
        print(f"  {key:8s} {slope_per_hour(xs, ys):+8.2f} {unit}/h   (first {ys[0]:.1f}, last {ys[-1]:.1f}, "
              f"min {min(ys):.1f}, max {max(ys):.1f})")
    print(f"# 5xx: {work.counts['http_5xx']}; client errors noted: {len(work.errors)}")
    for line in work.errors[:20]:
        print("  " + line)


if __name__ == "__main__":
    main()
