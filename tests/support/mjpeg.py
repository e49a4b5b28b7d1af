"""A small MJPEG (multipart/x-mixed-replace) client for tests and benchmarks: raw socket, one thread.

Each part is kept as (arrival time, headers, JPEG bytes), or only counted with keep_frames=False
(benchmarks with many viewers). `latencies` collects wall-clock arrival minus the part's
X-Timestamp (the image's header stamp), in seconds.

With ack=True, and a stream asked with `ack=1` whose response names itself (X-Camera-Viewer), it
acknowledges as the camera card's page does (static/js/camera/acked_stream.js): after each
complete part, the body bytes received so far go to POST /api/camera/viewers/<id>/ack, at most
one request in flight (the newest count is sent when it returns). `received` counts body bytes.
"""

from __future__ import annotations

import socket
import threading
import time
from urllib.parse import urlsplit

import requests


class Acker:
    """Sends the newest received-bytes count of one acknowledged stream, one request at a time,
    over one kept-alive connection (as a browser does). `sending` off: counts are kept, not sent."""

    def __init__(self, url: str, headers: dict[str, str] | None = None):
        self.url = url
        self.session = requests.Session()
        self.session.headers.update(headers or {})
        self.sending = True
        self.newest = 0  # the newest count offered
        self.acked = 0  # the newest count the server took (204)
        self.answers: list[int] = []  # every status the server gave
        self._cond = threading.Condition()
        self._closed = False
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def offer(self, received: int) -> None:
        with self._cond:
            self.newest = max(self.newest, received)
            self._cond.notify_all()

    def _run(self) -> None:
        while True:
            with self._cond:
                while not self._closed and not (self.sending and self.newest > self.acked):
                    self._cond.wait(0.5)
                if self._closed:
                    return
                count = self.newest
            try:
                status = self.session.post(self.url, json={"bytes": count}, timeout=30).status_code
            except requests.RequestException:
                status = 0
            with self._cond:
                self.answers.append(status)
                if status == 204:
                    self.acked = max(self.acked, count)
            if status != 204:
                time.sleep(0.2)  # refused or not reached: not a tight loop

    def close(self) -> None:
        with self._cond:
            self._closed = True
            self._cond.notify_all()
        self._thread.join(5)
        self.session.close()


class MjpegClient:
    def __init__(self, url: str, keep_frames: bool = True, connect_timeout: float = 10.0,
                 headers: dict[str, str] | None = None, ack: bool = False, ack_paused: bool = False):
        parts = urlsplit(url)
        self.sock = socket.create_connection((parts.hostname, parts.port), timeout=connect_timeout)
        path = parts.path + ("?" + parts.query if parts.query else "")
        extra = "".join(f"{name}: {value}\r\n" for name, value in (headers or {}).items())
        request = f"GET {path} HTTP/1.1\r\nHost: {parts.hostname}:{parts.port}\r\nAccept: */*\r\n{extra}\r\n"
        self.sock.sendall(request.encode())
        self.sock.settimeout(None)
        # Where acknowledgements go: beside /stream, under a robot's prefix if the stream has one.
        self._ack_base = f"{parts.scheme}://{parts.netloc}{parts.path.rsplit('/stream', 1)[0]}"
        self._ack_headers = headers
        self._ack, self._ack_paused = ack, ack_paused  # paused: acker.sending starts off
        self.acker: Acker | None = None
        self.received = 0  # body bytes received
        self.keep_frames = keep_frames
        self.status: int | None = None
        self.headers: dict[str, str] = {}
        self.body_prefix = b""  # a non-stream (error) response body
        self.frames: list[tuple[float, dict[str, str], bytes]] = []
        self.count = 0
        self.bytes = 0
        self.first_at: float | None = None
        self.last_at: float | None = None
        self.latencies: list[float] = []
        self.closed = threading.Event()
        self._cond = threading.Condition()
        self._thread = threading.Thread(target=self._read, daemon=True)
        self._thread.start()

    # --- reading ---

    def _read(self) -> None:
        reader = _Reader(self.sock)
        try:
            status_line = reader.line()
            self.status = int(status_line.split()[1])
            while True:
                line = reader.line()
                if not line:
                    break
                name, _, value = line.partition(":")
                self.headers[name.strip().lower()] = value.strip()
            body = _Body(reader, chunked="chunked" in self.headers.get("transfer-encoding", "").lower(),
                         length=int(self.headers["content-length"]) if "content-length" in self.headers else None)
            if self._ack and "x-camera-viewer" in self.headers:
                self.acker = Acker(f"{self._ack_base}/api/camera/viewers/{self.headers['x-camera-viewer']}/ack",
                                   self._ack_headers)
                self.acker.sending = not self._ack_paused
            if not self.headers.get("content-type", "").startswith("multipart/"):
                self.body_prefix = body.read_all()
                return
            boundary = "--" + self.headers["content-type"].split("boundary=", 1)[1].strip().strip('"')
            while True:
                line = body.line()
                if line is None:
                    return
                if line != boundary:
                    continue
                part_headers = {}
                while True:
                    header = body.line()
                    if header is None:
                        return
                    if header == "":
                        break
                    name, _, value = header.partition(":")
                    part_headers[name.strip().lower()] = value.strip()
                if "content-length" not in part_headers:
                    continue
                data = body.read(int(part_headers["content-length"]))
                if data is None:
                    return
                self.received = body.received
                if self.acker is not None:
                    self.acker.offer(body.received)
                now = time.monotonic()
                wall = time.time()
                with self._cond:
                    if "x-timestamp" in part_headers:
                        self.latencies.append(wall - float(part_headers["x-timestamp"]))
                    self.count += 1
                    self.bytes += len(data)
                    self.first_at = self.first_at or now
                    self.last_at = now
                    if self.keep_frames:
                        self.frames.append((now, part_headers, data))
                    self._cond.notify_all()
        except (OSError, ValueError, IndexError):
            pass
        finally:
            self.closed.set()
            with self._cond:
                self._cond.notify_all()

    # --- waiting ---

    def wait_frames(self, n: int, timeout: float = 10.0) -> None:
        deadline = time.monotonic() + timeout
        with self._cond:
            while self.count < n:
                remaining = deadline - time.monotonic()
                if remaining <= 0 or self.closed.is_set():
                    raise TimeoutError(f"{self.count} of {n} frames within {timeout} s (status {self.status}, "
                                       f"{self.body_prefix[:200]!r})")
                self._cond.wait(remaining)

    def close(self) -> None:
        try:
            self.sock.shutdown(socket.SHUT_RDWR)
        except OSError:
            pass
        self.sock.close()
        self._thread.join(2)
        if self.acker is not None:
            self.acker.close()


class _Buffered:
    """Lines and exact byte counts out of `buf`, which `_fill()` tops up; None at end of stream."""

    buf: bytearray

    def _fill(self) -> bool:
        raise NotImplementedError

    def line(self) -> str | None:
        while True:
            end = self.buf.find(b"\r\n")
            if end >= 0:
                text = bytes(self.buf[:end]).decode("latin-1")
                del self.buf[:end + 2]
                return text
            if not self._fill():
                return None

    def read(self, n: int) -> bytes | None:
        while len(self.buf) < n:
            if not self._fill():
                return None
        data = bytes(self.buf[:n])
        del self.buf[:n]
        return data


class _Reader(_Buffered):
    """Buffered reads from a socket."""

    def __init__(self, sock: socket.socket):
        self.sock = sock
        self.buf = bytearray()

    def _fill(self) -> bool:
        data = self.sock.recv(262144)
        if not data:
            return False
        self.buf += data
        return True


class _Body(_Buffered):
    """The response body, de-chunked when the server chunks it (Werkzeug does for streams)."""

    def __init__(self, reader: _Reader, chunked: bool, length: int | None):
        self.reader, self.chunked, self.length = reader, chunked, length
        self.buf = bytearray()
        self.done = False
        self.received = 0  # body bytes taken in so far (de-chunked): what a page acknowledges

    def _fill(self) -> bool:
        if self.done:
            return False
        if not self.chunked:
            if not self.reader.buf and not self.reader._fill():
                self.done = True
                return False
            self.received += len(self.reader.buf)
            self.buf += self.reader.buf
            self.reader.buf.clear()
            return True
        size_line = self.reader.line()
        if size_line is None:
            self.done = True
            return False
        size = int(size_line.split(";")[0], 16)
        if size == 0:
            self.done = True
            return False
        data = self.reader.read(size + 2)
        if data is None:
            self.done = True
            return False
        self.buf += data[:-2]
        self.received += size
        return True

    def read_all(self) -> bytes:
        while self._fill():
            if self.length is not None and len(self.buf) >= self.length:
                break
        return bytes(self.buf)
