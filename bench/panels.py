"""Command -> topic latency of the mission control panel: POST /api/panels/drone/stop to /control_phase.

Starts the GUI (`flask run`, its own process, a throwaway database) on 127.0.0.1 and a separate
rclpy subscriber in this process, unlocks the drone panel, then sends Stop (allowed in every
status, no confirmation) one at a time and times, from just before the POST:
  - topic: until the subscriber's callback receives the Int8 (the publish happens before the
    operator-log write, so it does not wait for SQLite's fsync);
  - http: until the POST's 200 answer (includes the committed operator-log entry).
Also prints the server's CPU time per command and its RSS.

    .venv/bin/python bench/panels.py [--samples 300]
"""

from __future__ import annotations

import argparse
import os
import random
import signal
import socket
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def percentile(values: list[float], q: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(round(q / 100 * (len(ordered) - 1))))]


def summary(name: str, values_s: list[float]) -> str:
    ms = [v * 1000 for v in values_s]
    return (f"{name:6s} median {statistics.median(ms):6.2f} ms   p90 {percentile(ms, 90):6.2f} ms   "
            f"p99 {percentile(ms, 99):6.2f} ms   max {max(ms):6.2f} ms   (n={len(ms)})")


class Listener:
    """An rclpy subscriber on /control_phase in its own context and spinning thread."""

    def __init__(self):
        import rclpy
        from rclpy.context import Context
        from rclpy.executors import SingleThreadedExecutor
        from rclpy.signals import SignalHandlerOptions
        from std_msgs.msg import Int8

        from rover_web.ros import qos

        self.context = Context()
        rclpy.init(context=self.context, signal_handler_options=SignalHandlerOptions.NO)
        self.node = rclpy.create_node("bench_listener", context=self.context)
        self.arrived = threading.Event()
        self.arrival = 0.0
        self.node.create_subscription(Int8, "/control_phase", self._on_msg, qos.profile("default"))
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)
        self.thread = threading.Thread(target=self._spin, daemon=True)
        self.thread.start()

    def _on_msg(self, _msg) -> None:
        self.arrival = time.monotonic()
        self.arrived.set()

    def _spin(self) -> None:
        from rclpy.executors import ExternalShutdownException
        try:
            self.executor.spin()
        except ExternalShutdownException:
            pass

    def close(self) -> None:
        self.executor.shutdown(timeout_sec=1.0)
        self.thread.join(2)
        self.node.destroy_node()
        self.context.try_shutdown()


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--samples", type=int, default=300)
    args = parser.parse_args()

    os.environ.setdefault("ROS_DOMAIN_ID", str(random.randint(100, 200)))
    os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    sys.path.insert(0, str(ROOT))
    import psutil
    import requests

    port = free_port()
    url = f"http://127.0.0.1:{port}"
    workdir = tempfile.TemporaryDirectory(prefix="bench-panels-")
    env = {k: v for k, v in os.environ.items() if not k.startswith("ROVER_WEB_")}
    env.update(ROVER_WEB_DB_PATH=str(Path(workdir.name) / "bench.sqlite3"), PYTHONPATH=str(ROOT))
    server = subprocess.Popen([sys.executable, "-m", "flask", "--app", "rover_web", "run", "--no-reload",
                               "--host", "127.0.0.1", "--port", str(port)], cwd=ROOT, env=env,
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    listener = None
    session = requests.Session()
    try:
        deadline = time.monotonic() + 30
        while True:
            try:
                if session.get(url + "/api/panels/drone", timeout=1).ok:
                    break
            except requests.RequestException:
                pass
            if time.monotonic() > deadline or server.poll() is not None:
                raise SystemExit("the server did not start")
            time.sleep(0.1)
        listener = Listener()
        stop_url = url + "/api/panels/drone/stop"
        session.post(url + "/api/panels/drone/unlock", json={}, timeout=5).raise_for_status()
        deadline = time.monotonic() + 20
        while not listener.arrived.is_set():  # discovery: publish until the subscriber has matched
            if time.monotonic() > deadline:
                raise SystemExit("the subscriber never received a command")
            session.post(stop_url, json={}, timeout=5).raise_for_status()
            listener.arrived.wait(0.2)
        for _ in range(20):  # warm up both ends
            listener.arrived.clear()
            session.post(stop_url, json={}, timeout=5)
            listener.arrived.wait(2)

        proc = psutil.Process(server.pid)
        cpu_before = sum(proc.cpu_times()[:2])
        topic, http, lost = [], [], 0
        for _ in range(args.samples):
            listener.arrived.clear()
            t0 = time.monotonic()
            response = session.post(stop_url, json={}, timeout=5)
            t_http = time.monotonic()
            response.raise_for_status()
            if not listener.arrived.wait(2):
                lost += 1
                continue
            topic.append(listener.arrival - t0)
            http.append(t_http - t0)
        cpu_per_command_ms = (sum(proc.cpu_times()[:2]) - cpu_before) / args.samples * 1000
        rss_mib = proc.memory_info().rss / 2**20

        print(f"mission control panel: POST /api/panels/drone/stop -> /control_phase ({args.samples} commands, "
              f"one at a time, loopback, {os.cpu_count()} CPUs)")
        print(summary("topic", topic))
        print(summary("http", http))
        print(f"lost   {lost}")
        print(f"server CPU {cpu_per_command_ms:.2f} ms per command, RSS {rss_mib:.0f} MiB")
        return 0 if not lost else 1
    finally:
        if listener is not None:
            listener.close()
        server.send_signal(signal.SIGTERM)
        try:
            server.wait(10)
        except subprocess.TimeoutExpired:
            server.kill()
        workdir.cleanup()


if __name__ == "__main__":
    sys.exit(main())
