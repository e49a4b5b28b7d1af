"""LiveMap benchmark: /amcl_pose publish -> SSE `pose` frame latency, and GET /api/maps/<map> latency.

Starts `flask --app rover_web run --no-reload` on 127.0.0.1 in its own process (so its CPU and RSS
are its own), publishes /amcl_pose at 30 Hz from a node in this process, and reads the `pose`
channel on 1 and then 10 SSE connections with one selector thread. Each pose's x encodes its
sequence number; latency = arrival of the frame carrying it - the moment it was published (both
CLOCK_MONOTONIC in this process). The server's channel is throttled to ROVER_WEB_LIVEMAP_POSE_MAX_HZ
(30), so a pose that arrives early in a 33 ms window may wait for it: that is part of the number.

    .venv/bin/python bench/livemap.py [--seconds 10] [--rate 30] [--clients 1 10]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import random
import selectors
import socket
import statistics
import sys
import threading
import time
from pathlib import Path
from urllib.parse import quote

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

import requests  # noqa: E402
from common import Server  # noqa: E402  (bench/ is on sys.path when run as a script)

MAP = "Science Hall Basement"


def percentile(values: list[float], q: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, max(0, math.ceil(q / 100 * len(ordered)) - 1))]


class SseFleet:
    """n SSE connections on one selector thread; every `pose` frame is timestamped on arrival."""

    def __init__(self, url: str, n: int):
        self.arrivals: list[tuple[float, float]] = []  # (monotonic arrival, x)
        self.sel = selectors.DefaultSelector()
        self.buffers: dict[socket.socket, bytes] = {}
        host, port = url.removeprefix("http://").split(":")
        for _ in range(n):
            sock = socket.create_connection((host, int(port)))
            sock.sendall(f"GET /api/events?channels=pose HTTP/1.1\r\nHost: {host}:{port}\r\n"
                         "Accept: text/event-stream\r\n\r\n".encode())
            sock.setblocking(False)
            self.sel.register(sock, selectors.EVENT_READ)
            self.buffers[sock] = b""
        self._stop = threading.Event()
        self._lock = threading.Lock()
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    def _run(self) -> None:
        while not self._stop.is_set():
            for key, _ in self.sel.select(0.1):
                sock = key.fileobj
                try:
                    data = sock.recv(65536)
                except BlockingIOError:
                    continue
                t = time.monotonic()
                if not data:
                    self.sel.unregister(sock)
                    continue
                buf = self.buffers[sock] + data
                *frames, rest = buf.split(b"\n\n")
                self.buffers[sock] = rest
                for frame in frames:
                    i = frame.find(b"data: {")
                    if b"event: pose" in frame and i >= 0:
                        end = frame.find(b"\r\n", i)
                        payload = frame[i + 6:end if end > 0 else None]
                        try:
                            x = json.loads(payload)["x"]
                        except (ValueError, KeyError):
                            continue
                        with self._lock:
                            self.arrivals.append((t, x))

    def take(self) -> list[tuple[float, float]]:
        with self._lock:
            taken, self.arrivals = self.arrivals, []
        return taken

    def close(self) -> None:
        self._stop.set()
        self.thread.join(2)
        for sock in self.buffers:
            sock.close()


class PosePublisher:
    """A node in this process publishing /amcl_pose at `rate_hz`; x = 1 + seq / 1000 identifies each one."""

    def __init__(self):
        import rclpy
        from rclpy.context import Context
        from rclpy.signals import SignalHandlerOptions

        from rover_web.ros import qos
        from rover_web.ros.typesupport import message_class

        self.context = Context()
        rclpy.init(context=self.context, signal_handler_options=SignalHandlerOptions.NO)
        self.node = rclpy.create_node("bench_amcl", context=self.context)
        self.cls = message_class("geometry_msgs/msg/PoseWithCovarianceStamped")
        self.pub = self.node.create_publisher(self.cls, "/amcl_pose", qos.profile("latched"))
        self.sent: dict[float, float] = {}
        self.seq = 0

    def publish(self) -> None:
        self.seq += 1
        x = round(1.0 + self.seq / 1000.0, 4)
        msg = self.cls()
        msg.header.frame_id = "map"
        msg.header.stamp = self.node.get_clock().now().to_msg()
        msg.pose.pose.position.x, msg.pose.pose.position.y = x, 10.5
        msg.pose.pose.orientation.w = 1.0
        self.sent[x] = time.monotonic()
        self.pub.publish(msg)

    def run(self, seconds: float, rate_hz: float) -> None:
        period = 1.0 / rate_hz
        start = time.monotonic()
        for i in range(int(seconds * rate_hz)):
            time.sleep(max(0.0, start + i * period - time.monotonic()))
            self.publish()

    def close(self) -> None:
        self.node.destroy_node()
        self.context.try_shutdown()


def pose_latency(server: Server, publisher: PosePublisher, clients: int, seconds: float, rate_hz: float) -> dict:
    fleet = SseFleet(server.url, clients)
    try:
        publisher.run(2.0, rate_hz)                 # warm-up: discovery, snapshots
        time.sleep(0.3)
        fleet.take()
        cpu0, wall0 = server.cpu_seconds(), time.monotonic()
        first_seq = publisher.seq + 1
        publisher.run(seconds, rate_hz)
        time.sleep(0.3)
        cpu = (server.cpu_seconds() - cpu0) / (time.monotonic() - wall0) * 100
        arrivals = fleet.take()
    finally:
        fleet.close()
    wanted = {round(1.0 + s / 1000.0, 4) for s in range(first_seq, publisher.seq + 1)}
    latencies = [(t - publisher.sent[x]) * 1000 for t, x in arrivals if x in wanted]
    published = len(wanted)
    return {"clients": clients, "published": published, "frames": len(latencies),
            "frames_per_client": len(latencies) / clients,
            "median_ms": statistics.median(latencies), "p99_ms": percentile(latencies, 99),
            "max_ms": max(latencies), "server_cpu_pct": cpu, "server_rss_mb": server.rss_mb()}


def map_state_latency(server: Server, n: int = 300) -> list[dict]:
    results = []
    with requests.Session() as session:
        for query in ("", "?cm_per_pixel=2"):
            url = f"{server.url}/api/maps/{quote(MAP)}{query}"
            for _ in range(20):
                session.get(url, timeout=5).raise_for_status()
            times = []
            for _ in range(n):
                t0 = time.perf_counter()
                response = session.get(url, timeout=5)
                times.append((time.perf_counter() - t0) * 1000)
                response.raise_for_status()
            results.append({"url": f"/api/maps/<map>{query}", "n": n, "median_ms": statistics.median(times),
                            "p99_ms": percentile(times, 99), "bytes": len(response.content)})
    return results


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seconds", type=float, default=10.0, help="measured seconds per client count")
    parser.add_argument("--rate", type=float, default=30.0, help="/amcl_pose publish rate (Hz)")
    parser.add_argument("--clients", type=int, nargs="+", default=[1, 10])
    parser.add_argument("--server-max-hz", type=float, default=None,
                        help="ROVER_WEB_LIVEMAP_POSE_MAX_HZ for the server (default: its own, 30)")
    args = parser.parse_args()

    os.environ.setdefault("ROS_DOMAIN_ID", str(random.randint(201, 230)))
    os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    env = {k: v for k, v in os.environ.items() if not k.startswith("ROVER_WEB_")}
    env.update(PYTHONPATH=str(ROOT), PYTHONUNBUFFERED="1")
    if args.server_max_hz:
        env["ROVER_WEB_LIVEMAP_POSE_MAX_HZ"] = str(args.server_max_hz)
    print(f"LiveMap bench: domain {os.environ['ROS_DOMAIN_ID']}, {args.rate:g} Hz /amcl_pose, "
          f"pose channel at most {args.server_max_hz or 30:g} Hz, {args.seconds:g} s per run, {os.cpu_count()} CPUs")
    server = Server(env)
    publisher = PosePublisher()
    try:
        print(f"server idle: RSS {server.rss_mb():.0f} MB")
        print("\npose publish -> SSE `pose` frame")
        print(f"{'clients':>7} {'published':>9} {'frames/client':>13} {'median ms':>9} {'p99 ms':>7} {'max ms':>7} "
              f"{'server CPU %':>12} {'RSS MB':>7}")
        for n in args.clients:
            r = pose_latency(server, publisher, n, args.seconds, args.rate)
            print(f"{r['clients']:>7} {r['published']:>9} {r['frames_per_client']:>13.1f} {r['median_ms']:>9.1f} "
                  f"{r['p99_ms']:>7.1f} {r['max_ms']:>7.1f} {r['server_cpu_pct']:>12.1f} {r['server_rss_mb']:>7.0f}")
        print("\nGET /api/maps/<map> (one keep-alive connection, sequential)")
        for r in map_state_latency(server):
            print(f"  {r['url']:<32} n={r['n']} median {r['median_ms']:.2f} ms  p99 {r['p99_ms']:.2f} ms  "
                  f"({r['bytes']} bytes)")
    finally:
        publisher.close()
        server.stop()


if __name__ == "__main__":
    main()
