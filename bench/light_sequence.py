"""Scan the Code: ROS publish → SSE frame latency with 1, 10 and 50 browsers attached.

    .venv/bin/python bench/light_sequence.py [--clients 1,10,50] [--messages 200] [--server flask|gunicorn]

Three processes on 127.0.0.1, as in the field: the server (`flask run --no-reload`, or gunicorn
with one worker and enough threads), a plain rclpy publisher standing in for the camera detector
(std_msgs/String on /light_sequence), and this process holding N raw SSE clients on
`/api/events?channels=status,light_sequence` (what the dashboard asks for).

Each message changes the light (red, green, blue, black, ...), so each produces one
`light_sequence` frame. The publisher stamps CLOCK_MONOTONIC just before publish(). Each client
socket has SO_TIMESTAMPNS on, so every recvmsg() says when the kernel put the bytes in that
socket: "arrived" is that moment for the chunk that completed the frame, which is when a browser
could first read it, whatever its own process is doing. "woken" is when this process's epoll
returned with the socket readable (one stamp per wake-up, before anything else): with 10 or 50
clients in one Python process that also counts this process catching up with the other sockets.
While a message is in flight the clients only receive (recvmsg, append, count `event:` lines);
parsing waits until every client has its frame, so this process takes as little CPU from the
server as it can on a 2-core machine. Messages go one at a time (the next after every client has
its frame, at most every --interval seconds): this measures latency, not queueing. Prints median,
p99 and max per client count, the last client's arrival per message, the wake-up latency, and the
server's CPU and RSS.
"""

from __future__ import annotations

import argparse
import json
import os
import selectors
import socket
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from common import recv_stamped, stamp_arrivals

ROOT = Path(__file__).resolve().parent.parent
TOPIC = "/light_sequence"
CYCLE = ("red", "green", "blue", "black")


# --- the publisher process: python bench/light_sequence.py --publisher ---

def publisher_main() -> None:
    """Reads a colour per stdin line, publishes it, answers with the CLOCK_MONOTONIC stamp."""
    import rclpy
    from rclpy.qos import QoSProfile
    from std_msgs.msg import String

    rclpy.init()
    node = rclpy.create_node("bench_light_publisher")
    pub = node.create_publisher(String, TOPIC, QoSProfile(depth=10))
    deadline = time.monotonic() + 20
    while pub.get_subscription_count() < 1:
        if time.monotonic() > deadline:
            print("no subscriber", flush=True)
            return
        time.sleep(0.01)
    print("ready", flush=True)
    for line in sys.stdin:
        text = line.rstrip("\n")
        if text == "quit":
            break
        msg = String(data=text)
        t = time.monotonic()
        pub.publish(msg)
        sys.stdout.write(f"{t!r}\n")
        sys.stdout.flush()
    node.destroy_node()
    rclpy.shutdown()


class Publisher:
    def __init__(self, env: dict):
        self.proc = subprocess.Popen([sys.executable, __file__, "--publisher"], stdin=subprocess.PIPE,
                                     stdout=subprocess.PIPE, text=True, env=env, cwd=ROOT)
        if self.proc.stdout.readline().strip() != "ready":
            raise RuntimeError("the publisher never matched the app's subscription")

    def publish(self, text: str) -> float:
        self.proc.stdin.write(text + "\n")
        self.proc.stdin.flush()
        return float(self.proc.stdout.readline())

    def close(self) -> None:
        try:
            self.proc.stdin.write("quit\n")
            self.proc.stdin.flush()
            self.proc.wait(5)
        except (OSError, subprocess.TimeoutExpired):
            self.proc.kill()


# --- many raw SSE clients on one epoll loop ---

LIGHT_EVENT = b"event: light_sequence\n"


class Stream:
    """One raw SSE client. While a message is in flight it only receives (recvmsg, append, count):
    parsing waits until every client has its frame, so this process's own work interrupts the
    server as little as it can."""

    def __init__(self, port: int, channels: str):
        self.sock = socket.create_connection(("127.0.0.1", port), timeout=10)
        stamp_arrivals(self.sock)
        self.sock.sendall(f"GET /api/events?channels={channels} HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\n"
                          "Accept: text/event-stream\r\n\r\n".encode())
        self.sock.setblocking(False)
        self.chunks: list[tuple[float, float, bytes]] = []  # (wake-up, kernel arrival, bytes), unparsed
        self.light_events_seen = 0  # `event: light_sequence` lines received, parsed or not
        self._tail = b""
        self.raw = b""
        self.body = b""
        self.headers_done = False
        self.chunked = False
        # (woken at, arrived at, light_sequence data); both CLOCK_MONOTONIC
        self.frames: list[tuple[float, float, dict]] = []

    def receive(self, t_wake: float) -> None:
        try:
            data, t_arrived = recv_stamped(self.sock, t_wake)
        except BlockingIOError:
            return
        if not data:
            raise RuntimeError("an event stream closed")
        self.chunks.append((t_wake, t_arrived, data))
        window = self._tail + data
        self.light_events_seen += window.count(LIGHT_EVENT)
        self._tail = window[-(len(LIGHT_EVENT) - 1):]

    def parse(self) -> None:
        """Turn the received chunks into frames; a frame's times are those of the chunk that ended it."""
        chunks, self.chunks = self.chunks, []
        for t_wake, t_arrived, data in chunks:
            self._feed(data, t_wake, t_arrived)

    def _feed(self, data: bytes, t_wake: float, t_arrived: float) -> None:
        self.raw += data
        if not self.headers_done:
            if b"\r\n\r\n" not in self.raw:
                return
            head, self.raw = self.raw.split(b"\r\n\r\n", 1)
            if not head.startswith(b"HTTP/1.1 200"):
                raise RuntimeError(f"event stream refused: {head[:80]!r}")
            self.chunked = b"chunked" in head.lower()
            self.headers_done = True
        if self.chunked:
            while b"\r\n" in self.raw:
                size_text, rest = self.raw.split(b"\r\n", 1)
                size = int(size_text.split(b";")[0], 16)
                if len(rest) < size + 2:
                    break
                self.body += rest[:size]
                self.raw = rest[size + 2:]
        else:
            self.body, self.raw = self.body + self.raw, b""
        while b"\n\n" in self.body:
            block, self.body = self.body.split(b"\n\n", 1)
            event, payload = None, None
            for line in block.decode().split("\n"):
                if line.startswith("event: "):
                    event = line[7:]
                elif line.startswith("data: "):
                    payload = line[6:]
            if event == "light_sequence" and payload:
                self.frames.append((t_wake, t_arrived, json.loads(payload)))


class Streams:
    def __init__(self, port: int, count: int):
        self.selector = selectors.DefaultSelector()
        self.streams = [Stream(port, "status,light_sequence") for _ in range(count)]
        for stream in self.streams:
            self.selector.register(stream.sock, selectors.EVENT_READ, stream)

    def pump(self, until, timeout_s: float) -> None:
        """Receive until `until()` holds. `until` should be cheap: it runs after every wake-up."""
        deadline = time.monotonic() + timeout_s
        while not until():
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                raise TimeoutError("the event streams did not deliver in time")
            ready = self.selector.select(remaining)
            t = time.monotonic()  # one stamp per wake-up, before anything else
            for key, _ in ready:
                key.data.receive(t)

    def parse(self) -> None:
        for stream in self.streams:
            stream.parse()

    def close(self) -> None:
        for stream in self.streams:
            self.selector.unregister(stream.sock)
            stream.sock.close()
        self.selector.close()


# --- the server ---

def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def start_server(kind: str, port: int, env: dict, threads: int, log_path: str) -> subprocess.Popen:
    if kind == "gunicorn":
        cmd = [sys.executable, "-m", "gunicorn", "-c", "gunicorn.conf.py", "--threads", str(threads),
               "--bind", f"127.0.0.1:{port}", "rover_web:create_app()"]
    else:
        cmd = [sys.executable, "-m", "flask", "--app", "rover_web", "run", "--no-reload",
               "--host", "127.0.0.1", "--port", str(port)]
    log = open(log_path, "wb")
    proc = subprocess.Popen(cmd, cwd=ROOT, env=env, stdout=log, stderr=subprocess.STDOUT)
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline:
        if proc.poll() is not None:
            raise RuntimeError(f"server exited: {Path(log_path).read_text()[-2000:]}")
        try:
            with socket.create_connection(("127.0.0.1", port), timeout=1) as s:
                s.sendall(f"GET /api/status HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nConnection: close\r\n\r\n".encode())
                if s.recv(64).startswith(b"HTTP/1.1 200"):
                    return proc
        except OSError:
            time.sleep(0.1)
    proc.kill()
    raise RuntimeError("server did not answer")


def percentile(values: list[float], q: float) -> float:
    ordered = sorted(values)
    index = min(len(ordered) - 1, max(0, int(round(q / 100 * len(ordered) + 0.5)) - 1))
    return ordered[index]


def run(streams: Streams, publisher: Publisher, messages: int, interval_s: float, index: int) -> dict[str, list]:
    """Publish `messages` colour changes one at a time. Latencies from publish() to each client's
    frame: `arrived` (in the client's socket), `woken` (this process woken with it readable), and
    `last` (per message, the last client's arrival)."""
    out: dict[str, list] = {"arrived": [], "woken": [], "last": []}
    for _ in range(messages):
        text = CYCLE[index % len(CYCLE)]
        index += 1
        started = time.monotonic()
        streams.parse()
        marks = [len(s.frames) for s in streams.streams]
        waiting = [s.light_events_seen for s in streams.streams]
        t_pub = publisher.publish(text)

        def frame(stream, mark, text=text):
            return next(((w, a) for w, a, d in stream.frames[mark:] if d["light"] == text), None)

        while True:
            streams.pump(lambda waiting=waiting: all(
                s.light_events_seen > n for s, n in zip(streams.streams, waiting, strict=True)), 10)
            streams.parse()
            found = [frame(s, m) for s, m in zip(streams.streams, marks, strict=True)]
            if all(found):
                break
            # a frame cut in two, or another change first: wait for more on those streams only
            waiting = [-1 if f else s.light_events_seen for s, f in zip(streams.streams, found, strict=True)]
        out["arrived"] += [a - t_pub for _, a in found]
        out["woken"] += [w - t_pub for w, _ in found]
        out["last"].append(max(a for _, a in found) - t_pub)
        time.sleep(max(0.0, started + interval_s - time.monotonic()))
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--clients", default="1,10,50", help="client counts to measure (default 1,10,50)")
    parser.add_argument("--messages", type=int, default=200, help="messages per client count (default 200)")
    parser.add_argument("--interval", type=float, default=0.05, help="seconds between messages (default 0.05)")
    parser.add_argument("--server", choices=("flask", "gunicorn"), default="flask")
    parser.add_argument("--threads", type=int, default=64, help="gunicorn threads (each stream holds one)")
    parser.add_argument("--domain-id", type=int, default=int(os.environ.get("ROS_DOMAIN_ID", "87")))
    parser.add_argument("--publisher", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.publisher:
        publisher_main()
        return

    import psutil

    counts = [int(c) for c in args.clients.split(",")]
    tmp = tempfile.mkdtemp(prefix="bench-light-")
    env = {k: v for k, v in os.environ.items() if not k.startswith("ROVER_WEB_")}
    env.update(ROS_DOMAIN_ID=str(args.domain_id), ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST", PYTHONUNBUFFERED="1",
               PYTHONPATH=str(ROOT), ROVER_WEB_DB_PATH=f"{tmp}/bench.sqlite3",
               ROVER_WEB_SSE_MAX_CLIENTS=str(max(counts) + 16))
    port = free_port()
    server = start_server(args.server, port, env, args.threads, f"{tmp}/server.log")
    publisher = None
    try:
        publisher = Publisher(env)
        server_ps = psutil.Process(server.pid)
        if args.server == "gunicorn":  # the worker, not the arbiter, is the ROS node
            server_ps = server_ps.children()[0]
        warm = Streams(port, 1)
        index = 0
        while True:  # discovery: publish until the app has heard one
            publisher.publish(CYCLE[index % len(CYCLE)])
            index += 1
            try:
                warm.pump(lambda: warm.streams[0].light_events_seen > 1, 0.2)  # past the snapshot
                break
            except TimeoutError:
                continue
        warm.close()
        print(f"server: {args.server}, {args.messages} messages per run, one every >= {args.interval * 1000:.0f} ms, "
              f"channels status,light_sequence; latency from publish() to the frame in each client's socket "
              f"(kernel receive time), and to this process waking with it")
        print(f"{'clients':>7} {'median ms':>10} {'p99 ms':>8} {'max ms':>8} {'last client p50/p99':>20} "
              f"{'woken p50/p99':>15} {'server CPU %':>12} {'RSS MiB':>8}")
        for count in counts:
            streams = Streams(port, count)
            streams.pump(lambda streams=streams: all(s.light_events_seen for s in streams.streams),
                         10)  # every snapshot is in
            cpu_before, wall_before = server_ps.cpu_times(), time.monotonic()
            result = run(streams, publisher, args.messages, args.interval, index)
            index += args.messages
            cpu_after, wall = server_ps.cpu_times(), time.monotonic() - wall_before
            cpu = 100 * ((cpu_after.user + cpu_after.system) - (cpu_before.user + cpu_before.system)) / wall
            rss = server_ps.memory_info().rss / 2**20
            ms, last, woken = ([v * 1000 for v in result[k]] for k in ("arrived", "last", "woken"))
            print(f"{count:>7} {statistics.median(ms):>10.3f} {percentile(ms, 99):>8.3f} {max(ms):>8.3f} "
                  f"{statistics.median(last):>9.3f} / {percentile(last, 99):<8.3f} "
                  f"{statistics.median(woken):>6.3f} / {percentile(woken, 99):<6.3f} {cpu:>12.1f} {rss:>8.1f}",
                  flush=True)
            streams.close()
            time.sleep(0.5)  # let the server notice the closed streams
    finally:
        if publisher is not None:
            publisher.close()
        server.terminate()
        try:
            server.wait(15)
        except subprocess.TimeoutExpired:
            server.kill()


if __name__ == "__main__":
    main()
