"""Shared pieces for the benchmarks: a server subprocess, many SSE clients in one thread, stats."""

from __future__ import annotations

import json
import os
import random
import selectors
import socket
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import psutil
import requests

ROOT = Path(__file__).resolve().parent.parent


def ros_env(**extra: str) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if not k.startswith("ROVER_WEB_")}
    env.setdefault("ROS_DOMAIN_ID", str(random.randint(201, 230)))
    env["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    env["PYTHONPATH"] = str(ROOT)
    env["PYTHONUNBUFFERED"] = "1"
    env.update(extra)
    return env


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Server:
    """The app in its own process, so its CPU and RSS are its own: `flask --app rover_web run
    --no-reload`, or gunicorn with gunicorn.conf.py (kind="gunicorn"), on a free 127.0.0.1 port."""

    def __init__(self, env: dict[str, str], kind: str = "flask"):
        self.port = free_port()
        self.url = f"http://127.0.0.1:{self.port}"
        # A throwaway database: a bench must never touch the operator's waypoints or e-stop latch.
        self._tmp = tempfile.TemporaryDirectory(prefix="rover_web-bench-")
        env = {**env, "ROVER_WEB_DB_PATH": env.get("ROVER_WEB_DB_PATH") or os.path.join(self._tmp.name, "bench.sqlite3")}
        if kind == "gunicorn":
            cmd = [sys.executable, "-m", "gunicorn", "-c", str(ROOT / "gunicorn.conf.py"),
                   "--bind", f"127.0.0.1:{self.port}", "rover_web:create_app()"]
        else:
            cmd = [sys.executable, "-m", "flask", "--app", "rover_web", "run", "--no-reload",
                   "--host", "127.0.0.1", "--port", str(self.port)]
        self.proc = subprocess.Popen(cmd, cwd=ROOT, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        self.ps = psutil.Process(self.proc.pid)
        deadline = time.monotonic() + 30
        while True:
            try:
                if requests.get(self.url + "/api/status", timeout=1).ok:
                    break
            except requests.RequestException:
                pass
            if time.monotonic() > deadline or self.proc.poll() is not None:
                self.stop()
                raise RuntimeError(f"{kind} server did not start")
            time.sleep(0.1)

    def cpu_seconds(self) -> float:
        t = self.ps.cpu_times()
        return t.user + t.system

    def rss_mb(self) -> float:
        return self.ps.memory_info().rss / 1e6

    def stop(self) -> None:
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(10)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait(5)
        self._tmp.cleanup()


class SseFleet:
    """N SSE connections read by one thread with epoll; each frame is timestamped on arrival."""

    def __init__(self, url: str, path: str, n: int):
        host, port = url.removeprefix("http://").split(":")
        self.sel = selectors.DefaultSelector()
        self.buffers: dict[socket.socket, bytes] = {}
        for _ in range(n):
            s = socket.create_connection((host, int(port)))
            s.sendall(f"GET {path} HTTP/1.1\r\nHost: {host}:{port}\r\nAccept: text/event-stream\r\n\r\n".encode())
            s.setblocking(False)
            self.sel.register(s, selectors.EVENT_READ)
            self.buffers[s] = b""

    def poll(self, seconds: float, on_event) -> None:
        """Call on_event(arrival_monotonic, event_name, data_dict) for every frame for `seconds`."""
        end = time.monotonic() + seconds
        while (remaining := end - time.monotonic()) > 0:
            ready = self.sel.select(remaining)
            # Every socket in this batch was readable when select returned: stamp them all then,
            # so this one Python reader's own parsing time is not counted against the server.
            t = time.monotonic()
            for key, _ in ready:
                s = key.fileobj
                data = s.recv(262144)
                if not data:
                    self.sel.unregister(s)
                    continue
                buf = self.buffers[s] + data
                # Chunked transfer framing lines are skipped; SSE frames end with a blank line.
                while b"\n\n" in buf:
                    block, buf = buf.split(b"\n\n", 1)
                    name, payload = None, None
                    for line in block.split(b"\n"):
                        if line.startswith(b"event: "):
                            name = line[7:].decode()
                        elif line.startswith(b"data: "):
                            payload = line[6:]
                    if name and payload is not None:
                        on_event(t, name, json.loads(payload))
                self.buffers[s] = buf

    def close(self) -> None:
        for s in list(self.buffers):
            try:
                self.sel.unregister(s)
            except (KeyError, ValueError):
                pass
            s.close()


def percentile(values: list[float], p: float) -> float:
    ordered = sorted(values)
    if not ordered:
        return float("nan")
    k = (len(ordered) - 1) * p / 100.0
    lo, hi = int(k), min(int(k) + 1, len(ordered) - 1)
    return ordered[lo] + (ordered[hi] - ordered[lo]) * (k - lo)


def summary_ms(latencies_s: list[float]) -> str:
    ms = [x * 1000 for x in latencies_s]
    return f"median {statistics.median(ms):6.3f} ms  p99 {percentile(ms, 99):6.3f} ms  max {max(ms):6.3f} ms  n={len(ms)}"


def machine() -> str:
    import platform
    return f"{platform.node()} {os.cpu_count()} cores, Python {platform.python_version()}"
