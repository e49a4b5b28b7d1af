"""Shared pieces for the benchmarks: a server subprocess, many SSE clients in one thread, stats."""

from __future__ import annotations

import json
import os
import random
import selectors
import socket
import statistics
import struct
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
        env = {**env,
               "ROVER_WEB_DB_PATH": env.get("ROVER_WEB_DB_PATH") or os.path.join(self._tmp.name, "bench.sqlite3")}
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
            stop_process(self.proc)
        self._tmp.cleanup()


def stop_process(proc: subprocess.Popen, timeout: float = 10) -> None:
    """SIGTERM, then SIGKILL if it has not ended within `timeout` s: a bench leaves no process behind."""
    proc.terminate()
    try:
        proc.wait(timeout)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait(5)


def wait_for(predicate, timeout: float, what: str):
    deadline = time.monotonic() + timeout
    while not (value := predicate()):
        if time.monotonic() > deadline:
            raise RuntimeError(f"{what} did not happen within {timeout} s")
        time.sleep(0.1)
    return value


def wait_for_topic(server: Server, topic: str, what: str, timeout: float = 30) -> None:
    """Until the app's topic list (GET /api/topics) has `topic`: its node has discovered the publisher."""
    wait_for(lambda: any(t["name"] == topic for t in requests.get(server.url + "/api/topics", timeout=5)
                         .json()["topics"]), timeout, what)


def count_rtp_payload(receiver, count) -> None:
    """count(n) with the payload size of each RTP packet an aiortc RTCRtpReceiver gets, before it
    handles the packet: what the video costs on the wire. aiortc has no public hook, so this wraps
    its private _handle_rtp_packet, here only."""
    handle = receiver._handle_rtp_packet

    async def counted(packet, arrival_time_ms):
        count(len(packet.payload))
        await handle(packet, arrival_time_ms)
    receiver._handle_rtp_packet = counted


async def decoded_frames(track):
    """Each frame an aiortc video track decodes, until the track ends."""
    from aiortc.mediastreams import MediaStreamError  # only the WebRTC benches have aiortc loaded

    while True:
        try:
            yield await track.recv()
        except MediaStreamError:
            return


# Linux's SO_TIMESTAMPNS (Python 3.11's socket module lacks the name): every recvmsg() then says
# when the kernel queued those bytes on the socket (CLOCK_REALTIME), however late the reader wakes.
SO_TIMESTAMPNS = getattr(socket, "SO_TIMESTAMPNS", 35)
_REALTIME_MINUS_MONOTONIC = time.time() - time.monotonic()
WALL_MINUS_MONOTONIC = _REALTIME_MINUS_MONOTONIC  # arrival + this = wall clock, for wall-clock stamps


def stamp_arrivals(sock: socket.socket) -> None:
    sock.setsockopt(socket.SOL_SOCKET, SO_TIMESTAMPNS, 1)


def recv_stamped(sock: socket.socket, t_woken: float) -> tuple[bytes, float]:
    """recv() plus when the data reached the socket, as CLOCK_MONOTONIC (t_woken if unknown)."""
    data, ancillary, _, _ = sock.recvmsg(262144, 64)
    for level, kind, value in ancillary:
        if level == socket.SOL_SOCKET and kind == SO_TIMESTAMPNS:
            sec, nsec = struct.unpack("qq", value[:16])
            return data, sec + nsec * 1e-9 - _REALTIME_MINUS_MONOTONIC
    return data, t_woken


class SseFleet:
    """N SSE connections read by one thread with epoll. Each frame gets two times: when its last
    byte reached the socket (kernel timestamp) and when this process woke with the socket readable.
    While polling, the fleet only receives; frames are parsed when the poll ends, so this one
    Python process standing in for N browsers takes as little CPU from the server as it can."""

    def __init__(self, url: str, path: str | list[str], n: int = 1):
        """n connections to `path`, or n to each path of a list (bench/fleet.py: one per robot)."""
        host, port = url.removeprefix("http://").split(":")
        self.sel = selectors.DefaultSelector()
        self.buffers: dict[socket.socket, bytes] = {}
        self.paths: dict[socket.socket, str] = {}
        self.bytes_received = 0
        for one in [path] if isinstance(path, str) else path:
            for _ in range(n):
                s = socket.create_connection((host, int(port)))
                stamp_arrivals(s)
                s.sendall(f"GET {one} HTTP/1.1\r\nHost: {host}:{port}\r\nAccept: text/event-stream\r\n\r\n".encode())
                s.setblocking(False)
                self.sel.register(s, selectors.EVENT_READ)
                self.buffers[s] = b""
                self.paths[s] = one

    @property
    def open_count(self) -> int:
        """Connections the server has not closed."""
        return len(self.sel.get_map())

    def poll(self, seconds: float, on_event, source: bool = False) -> None:
        """For `seconds`, receive; then call on_event(woken, arrived, event_name, data_dict) per frame,
        with a fifth argument, the connection's (path, socket number), if `source`."""
        end = time.monotonic() + seconds
        chunks: list[tuple[socket.socket, float, float, bytes]] = []
        while (remaining := end - time.monotonic()) > 0:
            ready = self.sel.select(remaining)
            t = time.monotonic()  # one stamp per wake-up, before anything else
            for key, _ in ready:
                s = key.fileobj
                try:
                    data, t_arrived = recv_stamped(s, t)
                except BlockingIOError:
                    continue
                if not data:
                    self.sel.unregister(s)
                    continue
                chunks.append((s, t, t_arrived, data))
                self.bytes_received += len(data)
        for s, t_woken, t_arrived, data in chunks:
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
                    if source:
                        on_event(t_woken, t_arrived, name, json.loads(payload), (self.paths[s], s.fileno()))
                    else:
                        on_event(t_woken, t_arrived, name, json.loads(payload))
            self.buffers[s] = buf

    def close(self) -> None:
        for s in list(self.buffers):
            try:
                self.sel.unregister(s)
            except (KeyError, ValueError):
                pass
            s.close()


def start_peer(script: str, env: dict, *args: str) -> subprocess.Popen:
    """A bench/ script in its own process, returned once it prints "publishing" (its peers found)."""
    proc = subprocess.Popen([sys.executable, str(ROOT / "bench" / script), *args], cwd=ROOT, env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    line = proc.stdout.readline()
    if "publishing" not in line:
        proc.kill()
        proc.wait(5)
        raise RuntimeError(f"{script} did not start: {line!r}")
    return proc


def percentile(values: list[float], p: float) -> float:
    ordered = sorted(values)
    if not ordered:
        return float("nan")
    k = (len(ordered) - 1) * p / 100.0
    lo, hi = int(k), min(int(k) + 1, len(ordered) - 1)
    return ordered[lo] + (ordered[hi] - ordered[lo]) * (k - lo)


def summary_ms(latencies_s: list[float]) -> str:
    ms = [x * 1000 for x in latencies_s]
    return (f"median {statistics.median(ms):6.3f} ms  p99 {percentile(ms, 99):6.3f} ms  "
            f"max {max(ms):6.3f} ms  n={len(ms)}")


def machine() -> str:
    import platform
    return f"{platform.node()} {os.cpu_count()} cores, Python {platform.python_version()}"
