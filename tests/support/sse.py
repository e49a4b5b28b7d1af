"""A small SSE client for tests and benchmarks: raw socket, frames timestamped on arrival."""

from __future__ import annotations

import json
import socket
import threading
import time
from urllib.parse import urlsplit


class SseClient:
    def __init__(self, url: str, headers: dict[str, str] | None = None, connect_timeout: float = 10.0,
                 read_delay_s: float = 0.0, keep_events: bool = True):
        """`keep_events=False` keeps only the newest event of each name (memory tests, long runs)."""
        parts = urlsplit(url)
        self.sock = socket.create_connection((parts.hostname, parts.port), timeout=connect_timeout)
        path = parts.path + ("?" + parts.query if parts.query else "")
        lines = [f"GET {path} HTTP/1.1", f"Host: {parts.hostname}:{parts.port}", "Accept: text/event-stream"]
        lines += [f"{k}: {v}" for k, v in (headers or {}).items()]
        self.sock.sendall(("\r\n".join(lines) + "\r\n\r\n").encode())
        self.sock.settimeout(None)
        self.read_delay_s = read_delay_s
        self.keep_events = keep_events
        self.status: int | None = None
        self.events: list[dict] = []
        self.comments: list[tuple[float, str]] = []
        self.retry_ms: int | None = None
        self.first_field: str | None = None
        self.closed = threading.Event()
        self._cond = threading.Condition()
        self._thread = threading.Thread(target=self._read, daemon=True)
        self._thread.start()

    def _read(self) -> None:
        buf = b""
        headers_done = False
        chunked = False
        body = b""
        try:
            while True:
                data = self.sock.recv(65536)
                if not data:
                    break
                t = time.monotonic()
                if self.read_delay_s:
                    time.sleep(self.read_delay_s)
                buf += data
                if not headers_done:
                    if b"\r\n\r\n" not in buf:
                        continue
                    head, buf = buf.split(b"\r\n\r\n", 1)
                    status_line = head.split(b"\r\n")[0].decode()
                    self.status = int(status_line.split()[1])
                    chunked = b"chunked" in head.lower()
                    headers_done = True
                if chunked:
                    while True:  # de-chunk what is complete
                        if b"\r\n" not in buf:
                            break
                        size_text, rest = buf.split(b"\r\n", 1)
                        size = int(size_text.split(b";")[0], 16)
                        if len(rest) < size + 2:
                            break
                        body += rest[:size]
                        buf = rest[size + 2:]
                else:
                    body += buf
                    buf = b""
                while b"\n\n" in body:
                    block, body = body.split(b"\n\n", 1)
                    self._frame(block.decode(), t)
        except OSError:
            pass
        finally:
            self.closed.set()
            with self._cond:
                self._cond.notify_all()

    def _frame(self, block: str, t: float) -> None:
        event = {"t": t, "event": "message", "data": "", "id": None}
        for line in block.split("\n"):
            field, _, value = line.partition(":")
            value = value[1:] if value.startswith(" ") else value
            if self.first_field is None:
                self.first_field = field
            if field == "":
                self.comments.append((t, value))
            elif field == "retry":
                self.retry_ms = int(value)
            elif field == "event":
                event["event"] = value
            elif field == "data":
                event["data"] += value
            elif field == "id":
                event["id"] = int(value)
        if event["data"]:
            event["json"] = json.loads(event["data"])
            with self._cond:
                if not self.keep_events:
                    self.events = [e for e in self.events if e["event"] != event["event"]]
                self.events.append(event)
                self._cond.notify_all()

    def of(self, name: str) -> list[dict]:
        with self._cond:
            return [e for e in self.events if e["event"] == name]

    def wait_for(self, name: str, predicate=lambda data: True, timeout: float = 10.0) -> dict:
        deadline = time.monotonic() + timeout
        seen = 0
        with self._cond:
            while True:
                for event in self.events[seen:]:
                    if event["event"] == name and predicate(event["json"]):
                        return event
                seen = len(self.events) if self.keep_events else 0
                remaining = deadline - time.monotonic()
                if remaining <= 0 or self.closed.is_set():
                    raise TimeoutError(f"no matching {name!r} event within {timeout} s ({len(self.events)} events)")
                self._cond.wait(remaining)

    def close(self) -> None:
        try:
            self.sock.shutdown(socket.SHUT_RDWR)
        except OSError:
            pass
        self.sock.close()
        self._thread.join(2)
