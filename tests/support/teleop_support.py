"""Teleop test helpers: a WebSocket client for /ws/teleop, a TCP proxy that can stall, /cmd_vel reads."""

from __future__ import annotations

import json
import socket
import struct
import threading
import time
from urllib.parse import quote

TWIST = "geometry_msgs/msg/Twist"
TWIST_STAMPED = "geometry_msgs/msg/TwistStamped"


# Every client not yet closed; conftest closes what a test left open (a socket left to the
# garbage collector is a ResourceWarning, and warnings are errors).
OPEN_CLIENTS: set = set()


def close_open_clients() -> None:
    for client in list(OPEN_CLIENTS):
        client.close()


class TeleopClient:
    """websocket-client on /ws/teleop with a reader thread that keeps every message received."""

    def __init__(self, base_url: str, name: str | None = None, **options):
        import websocket

        url = base_url.replace("http://", "ws://", 1) + "/ws/teleop" + (f"?name={quote(name)}" if name else "")
        self.ws = websocket.create_connection(url, timeout=10, **options)
        self.ws.settimeout(0.05)  # the reader wakes often, so abort() can take the socket back
        self.messages: list[dict] = []
        self.close_code: int | None = None
        self.closed = threading.Event()
        self._cond = threading.Condition()
        self._stop = threading.Event()
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()
        OPEN_CLIENTS.add(self)
        self.hello = self.wait_for(lambda m: m["type"] == "hello")

    def _read(self) -> None:
        import websocket

        while not self._stop.is_set():
            try:
                opcode, frame = self.ws.recv_data_frame(control_frame=True)
            except websocket.WebSocketTimeoutException:
                continue
            except (websocket.WebSocketException, OSError):
                break
            if opcode == websocket.ABNF.OPCODE_CLOSE:
                self.close_code = struct.unpack("!H", frame.data[:2])[0] if len(frame.data) >= 2 else 1005
                break
            if opcode == websocket.ABNF.OPCODE_TEXT:
                message = json.loads(frame.data)
                message["t"] = time.monotonic()
                with self._cond:
                    self.messages.append(message)
                    self._cond.notify_all()
        self.closed.set()
        with self._cond:
            self._cond.notify_all()

    # --- sending ---

    @property
    def epoch(self) -> int:
        with self._cond:
            for message in reversed(self.messages):
                if message["type"] in ("hello", "state"):
                    return message["epoch"]
        return 0

    def send(self, frame) -> None:
        self.ws.send(frame if isinstance(frame, (str, bytes)) else json.dumps(frame, allow_nan=True),
                     opcode=0x2 if isinstance(frame, bytes) else 0x1)

    def drive(self, linear: float, angular: float = 0.0, epoch: int | None = None, **extra) -> float:
        """Send one drive frame; returns the monotonic time just before it left."""
        frame = {"linear": linear, "angular": angular, "epoch": self.epoch if epoch is None else epoch, **extra}
        t = time.monotonic()
        self.send(frame)
        return t

    # --- receiving ---

    def wait_for(self, predicate, timeout: float = 10.0) -> dict:
        deadline = time.monotonic() + timeout
        seen = 0
        with self._cond:
            while True:
                for message in self.messages[seen:]:
                    if predicate(message):
                        return message
                seen = len(self.messages)
                remaining = deadline - time.monotonic()
                if remaining <= 0 or self.closed.is_set():
                    raise TimeoutError(f"no matching message within {timeout} s: {self.messages[-5:]}")
                self._cond.wait(remaining)

    def errors(self, code: str | None = None) -> list[dict]:
        with self._cond:
            return [m for m in self.messages if m["type"] == "error" and (code is None or m["error"] == code)]

    def wait_errors(self, count: int, timeout: float = 5.0) -> list[dict]:
        """Until at least `count` error frames have arrived (replies follow the effect they report:
        the robot is already at zero when the error frame leaves)."""
        with self._cond:
            if not self._cond.wait_for(lambda: len(self.errors()) >= count, timeout):
                raise TimeoutError(f"{len(self.errors())} error frames, expected {count}")
        return self.errors()

    def wait_closed(self, timeout: float = 5.0) -> int | None:
        assert self.closed.wait(timeout), "the server did not close the socket"
        return self.close_code

    # --- ending ---

    def send_close(self, status: int = 1000) -> float:
        """Send the close frame now; returns the monotonic time just before it left."""
        t = time.monotonic()
        self.ws.send_close(status)
        return t

    def abort(self) -> float:
        """Drop the connection with a TCP reset and no close frame (a crashed or unplugged client)."""
        self._stop.set()
        self._reader.join(2)
        sock = self.ws.sock
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
        t = time.monotonic()
        sock.close()
        OPEN_CLIENTS.discard(self)
        return t

    def close(self) -> None:
        OPEN_CLIENTS.discard(self)
        self._stop.set()
        self._reader.join(2)
        try:
            self.ws.close(timeout=1)
        except Exception:
            pass
        self.ws.shutdown()  # closes the socket even when the close handshake did not complete


class StallingProxy:
    """A TCP proxy on 127.0.0.1 whose both directions can be stalled, as a bad Wi-Fi link does.

    While paused it keeps reading (so the sender's writes succeed, as they do into a congested
    network) and holds the bytes; resume() delivers everything held in one burst.
    """

    def __init__(self, target_port: int):
        self.target_port = target_port
        self._listener = socket.create_server(("127.0.0.1", 0))
        self.port = self._listener.getsockname()[1]
        self.url = f"http://127.0.0.1:{self.port}"
        self._lock = threading.Lock()
        self._paused = False
        self._pipes: list[_Pipe] = []
        self._sockets: list[socket.socket] = []
        threading.Thread(target=self._accept, daemon=True).start()

    def _accept(self) -> None:
        while True:
            try:
                client, _ = self._listener.accept()
            except OSError:
                return
            upstream = socket.create_connection(("127.0.0.1", self.target_port))
            for s in (client, upstream):
                s.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            with self._lock:
                self._sockets += [client, upstream]
                pipes = [_Pipe(self, client, upstream), _Pipe(self, upstream, client)]
                self._pipes += pipes
            for pipe in pipes:
                threading.Thread(target=pipe.run, daemon=True).start()

    def pause(self) -> None:
        with self._lock:
            self._paused = True

    def resume(self) -> None:
        with self._lock:
            self._paused = False
            for pipe in self._pipes:
                pipe.flush()

    def held_bytes(self) -> int:
        with self._lock:
            return sum(len(chunk) for pipe in self._pipes for chunk in pipe.held)

    def close(self) -> None:
        self._listener.close()
        with self._lock:
            for s in self._sockets:
                try:
                    s.close()
                except OSError:
                    pass


class _Pipe:
    def __init__(self, proxy: StallingProxy, src: socket.socket, dst: socket.socket):
        self.proxy, self.src, self.dst = proxy, src, dst
        self.held: list[bytes] = []
        self.eof = False

    def run(self) -> None:
        while True:
            try:
                data = self.src.recv(65536)
            except OSError:
                data = b""
            with self.proxy._lock:
                if not data:
                    self.eof = True
                    if not self.proxy._paused:
                        self._shutdown()
                    return
                if self.proxy._paused:
                    self.held.append(data)
                else:
                    self._send(data)

    def flush(self) -> None:  # with the proxy's lock held
        if self.held:
            self._send(b"".join(self.held))
            self.held.clear()
        if self.eof:
            self._shutdown()

    def _send(self, data: bytes) -> None:
        try:
            self.dst.sendall(data)
        except OSError:
            pass

    def _shutdown(self) -> None:
        try:
            self.dst.shutdown(socket.SHUT_WR)
        except OSError:
            pass


# --- what a ROS subscriber saw on /cmd_vel ---

def twists(peer, topic: str = "/cmd_vel") -> list[tuple[float, float, float]]:
    """(t, linear.x, angular.z) of every Twist or TwistStamped the peer received."""
    out = []
    for event in peer.received(topic):
        msg = event["msg"]
        twist = msg.get("twist", msg)
        out.append((event["t"], twist["linear"]["x"], twist["angular"]["z"]))
    return out


def is_zero(msg: dict) -> bool:
    twist = msg.get("twist", msg)
    return twist["linear"]["x"] == 0.0 and twist["angular"]["z"] == 0.0


def subscribe_cmd_vel(peer, type_name: str = TWIST, topic: str = "/cmd_vel") -> None:
    # Keep-last 1000: a peer process starved of CPU by a parallel run must not drop commands from
    # its reader's history before it takes them (the default keeps 10).
    peer.subscribe(topic, type_name, qos=1000, max_items=8)
    peer.wait_match(topic)


def warm_up(peer, base_url: str, topic: str = "/cmd_vel", timeout: float = 10.0, headers: dict | None = None) -> None:
    """Discovery matches the two ends a moment apart: publish zeros (REST stop) until one arrives."""
    import requests

    deadline = time.monotonic() + timeout
    while not peer.received(topic):
        assert time.monotonic() < deadline, "the subscriber never received the app's /cmd_vel"
        requests.post(base_url + "/api/teleop", json={"command": "stop"}, timeout=5, headers=headers)
        time.sleep(0.05)
    time.sleep(0.05)
    peer.clear(topic)


def drive_at(client: TeleopClient, values, rate_hz: float = 40.0, epoch: int | None = None) -> list[float]:
    """Send (linear, angular) frames on a fixed 1/rate_hz grid; returns the send times."""
    period = 1.0 / rate_hz
    start = time.monotonic()
    times = []
    for i, (linear, angular) in enumerate(values):
        delay = start + i * period - time.monotonic()
        if delay > 0:
            time.sleep(delay)
        times.append(client.drive(linear, angular, epoch=epoch))
    return times


class Stick:
    """A page holding the joystick: a frame every 50 ms, with the newest epoch it was told, until
    closed; `value` is the linear input it holds (set it to 0.0 to let go)."""

    def __init__(self, url: str, name: str | None = None, value: float = 0.4):
        self.client = TeleopClient(url, name=name)
        self.value = value
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def _run(self) -> None:
        import websocket

        while not self._stop.wait(0.05):
            try:
                self.client.drive(self.value, 0.0, epoch=self.client.epoch)
            except (websocket.WebSocketException, OSError):  # the server ended the socket
                return

    def close(self) -> None:
        self._stop.set()
        self._thread.join(5)
        self.client.close()
