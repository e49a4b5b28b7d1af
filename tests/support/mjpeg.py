"""A small MJPEG (multipart/x-mixed-replace) client for tests and benchmarks: raw socket, one thread.

Each part is kept as (arrival time, headers, JPEG bytes), or only counted with keep_frames=False
(benchmarks with many viewers). `latencies` collects wall-clock arrival minus the part's
X-Timestamp (the image's header stamp), in seconds.
"""

from __future__ import annotations

import socket
import threading
import time
from urllib.parse import urlsplit


class MjpegClient:
    def __init__(self, url: str, keep_frames: bool = True, connect_timeout: float = 10.0):
        parts = urlsplit(url)
        self.sock = socket.create_connection((parts.hostname, parts.port), timeout=connect_timeout)
        path = parts.path + ("?" + parts.query if parts.query else "")
        request = f"GET {path} HTTP/1.1\r\nHost: {parts.hostname}:{parts.port}\r\nAccept: */*\r\n\r\n"
        self.sock.sendall(request.encode())
        self.sock.settimeout(None)
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

    def _fill(self) -> bool:
        if self.done:
            return False
        if not self.chunked:
            if not self.reader.buf and not self.reader._fill():
                self.done = True
                return False
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
        return True

    def read_all(self) -> bytes:
        while self._fill():
            if self.length is not None and len(self.buf) >= self.length:
                break
        return bytes(self.buf)
