"""Every SSE stream is written without waking a thread per browser.

Waking one thread per browser for every event costs a context switch and four small socket writes
(Werkzeug's chunked framing) per client. Instead the stream's request thread sends the response
head and snapshot itself, hands the socket to the Broadcaster and sleeps until the stream ends.

When the hub changes, the thread that changed it (a ROS callback, a request) sends each client
what changed since its cursor at once, with one non-blocking send: no hand-off to another thread
stands between a ROS message and the browser. The Broadcaster's own thread does the rest on
epoll: new clients, closed peers, the remainder of a partial write, keep-alives. A client whose
socket buffer is full keeps its unsent bytes and takes no new frames until they are out; then it
gets the newest value of each channel: slow browsers skip stale values, and nothing per client
grows. No Flask here.

Locks: the hub's lock is always taken before `_send_lock`, never the other way round.
"""

from __future__ import annotations

import os
import selectors
import socket
import threading
import time
from collections import deque

from .hub import EventHub, Subscription

_IDLE_CHECK_S = 1.0
# Each stream's kernel send buffer, fixed (the kernel doubles it for its own bookkeeping). Left to
# autotuning it grows to megabytes behind a slow or congested link, and the "full socket, skip to
# the newest value" rule below only starts once megabytes of old events wait in it: through a
# 2 Mbit/s link an odometry value was 3 s old at the median, 14 s at worst (bench/link.py). Event
# streams are a few kB/s; this holds a few seconds of them and lets a slow link skip the rest.
SEND_BUFFER_BYTES = 32 * 1024
# As a plain int: `MSG_DONTWAIT | MSG_NOSIGNAL` is an enum operation, a tenth of each client's cost
# on the event path when it was computed per send (cProfile, 200 clients).
_SEND_FLAGS = int(socket.MSG_DONTWAIT | socket.MSG_NOSIGNAL)


class _Client:
    __slots__ = ("sock", "sub", "done", "out", "last_write", "dead")

    def __init__(self, sock: socket.socket, sub: Subscription):
        self.sock = sock
        self.sub = sub
        self.done = threading.Event()
        self.out = b""
        self.last_write = time.monotonic()
        self.dead = False

    def wait(self, timeout_s: float | None = None) -> bool:
        """Until the stream has ended."""
        return self.done.wait(timeout_s)


class Broadcaster:
    def __init__(self, hub: EventHub, keepalive_s: float):
        self._hub = hub
        self._keepalive_s = keepalive_s
        self._idle_check_s = min(_IDLE_CHECK_S, keepalive_s)
        self._wake_r, self._wake_w = os.pipe()
        os.set_blocking(self._wake_r, False)
        os.set_blocking(self._wake_w, False)
        self._incoming: deque[_Client] = deque()
        self._lock = threading.Lock()  # _incoming and the thread's start
        self._send_lock = threading.Lock()  # _clients and every write to their sockets
        self._thread: threading.Thread | None = None
        self._clients: dict[int, _Client] = {}
        hub.add_listener(self._on_change)

    def _wake(self) -> None:
        try:
            os.write(self._wake_w, b"\0")
        except (BlockingIOError, OSError):
            pass  # a wake-up is already pending (or we are closing)

    def _on_change(self) -> None:
        """Called by the hub, under its lock, in the thread that changed it: deliver now.

        The usual case, every client one change behind, is done here without a call into the
        subscription per client: this loop is the per-viewer cost of every event."""
        hub = self._hub
        if hub.closed:
            self._wake()
            return
        needs_thread = False
        seq, channel, frame = hub.last_change
        behind = seq - 1
        now = time.monotonic()
        with self._send_lock:
            for client in self._clients.values():
                if client.out or client.dead:
                    continue
                sub = client.sub
                if sub.cursor == behind:
                    sub.cursor = seq
                    if channel not in sub.channels:
                        continue
                    data = frame
                else:
                    data = sub.poll()
                    if not data:
                        continue
                if not self._try_send(client, data, now):
                    needs_thread = True
        if needs_thread:
            self._wake()

    def attach(self, sock: socket.socket, sub: Subscription) -> _Client:
        """Serve `sock` from now on; the returned stream's wait() returns once it has ended."""
        client = _Client(sock, sub)
        try:
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_SNDBUF, SEND_BUFFER_BYTES)
        except OSError:
            pass  # a socket that is already gone: the thread finds it dead
        with self._lock:
            if self._hub.closed:
                client.done.set()
                sub.close()
                return client
            self._incoming.append(client)
            if self._thread is None:
                self._thread = threading.Thread(target=self._run, name="sse-broadcaster", daemon=True)
                self._thread.start()
        self._wake()
        return client

    def end(self, client: _Client) -> None:
        """End a stream from another thread (its user's access was revoked): the Broadcaster's
        thread shuts its socket down at its next turn, which this call starts."""
        client.dead = True
        self._wake()

    @property
    def client_count(self) -> int:
        return len(self._clients)

    @staticmethod
    def _try_send(client: _Client, data: bytes, now: float | None = None) -> bool:
        """One non-blocking send; True if all of it went. Caller holds _send_lock."""
        try:
            sent = client.sock.send(data, _SEND_FLAGS)
        except BlockingIOError:
            sent = 0
        except OSError:
            client.dead = True
            return False
        client.last_write = time.monotonic() if now is None else now
        if sent < len(data):
            client.out = data[sent:]
            return False
        return True

    # --- the broadcaster's own thread ---

    def _run(self) -> None:
        sel = selectors.DefaultSelector()
        sel.register(self._wake_r, selectors.EVENT_READ, None)
        writing: set[int] = set()  # fds registered for EVENT_WRITE
        next_idle_check = time.monotonic() + self._idle_check_s
        try:
            while not self._hub.closed:
                timeout = max(0.0, next_idle_check - time.monotonic())
                behind = []  # clients that may have missed changes: their buffer just drained, or new
                for key, mask in sel.select(timeout):
                    client = key.data
                    if client is None:
                        self._drain_wake_pipe()
                    elif mask & selectors.EVENT_READ and self._peer_gone(client):
                        client.dead = True
                    elif mask & selectors.EVENT_WRITE:
                        with self._send_lock:
                            data, client.out = client.out, b""
                            if data and self._try_send(client, data):
                                behind.append(client)
                behind += self._accept(sel)
                # They catch up with the newest values here; every other client was served by
                # _on_change as each change happened (with 500 viewers, polling them all on every
                # wake-up of this thread was most of its work).
                if behind:
                    with self._hub.lock, self._send_lock:
                        for client in behind:
                            if not client.out and not client.dead:
                                data = client.sub.poll()
                                if data:
                                    self._try_send(client, data)
                now = time.monotonic()
                if now >= next_idle_check:
                    next_idle_check = now + self._idle_check_s
                    with self._send_lock:
                        for client in self._clients.values():
                            if not client.out and not client.dead and now - client.last_write >= self._keepalive_s:
                                self._try_send(client, b": keep-alive\n\n")
                self._reconcile(sel, writing)
        finally:
            with self._send_lock:
                for client in self._clients.values():
                    client.dead = True
            self._reconcile(sel, writing)
            with self._lock:
                while self._incoming:
                    self._end(self._incoming.popleft())
            sel.close()

    def _drain_wake_pipe(self) -> None:
        try:
            while os.read(self._wake_r, 4096):
                pass
        except BlockingIOError:
            pass

    def _accept(self, sel: selectors.BaseSelector) -> list[_Client]:
        with self._lock:
            incoming = list(self._incoming)
            self._incoming.clear()
        if incoming:
            with self._send_lock:
                for client in incoming:
                    self._clients[client.sock.fileno()] = client
            for client in incoming:
                sel.register(client.sock, selectors.EVENT_READ, client)
        return incoming

    def _reconcile(self, sel: selectors.BaseSelector, writing: set[int]) -> None:
        """Match the selector to each client's state; end the dead ones (outside _send_lock)."""
        ended = []
        with self._send_lock:
            for fd, client in list(self._clients.items()):
                if client.dead:
                    del self._clients[fd]
                    ended.append(client)
                elif client.out and fd not in writing:
                    sel.modify(client.sock, selectors.EVENT_READ | selectors.EVENT_WRITE, client)
                    writing.add(fd)
                elif not client.out and fd in writing:
                    sel.modify(client.sock, selectors.EVENT_READ, client)
                    writing.discard(fd)
        for client in ended:
            writing.discard(client.sock.fileno())
            try:
                sel.unregister(client.sock)
            except (KeyError, ValueError):
                pass
            self._end(client)

    @staticmethod
    def _peer_gone(client: _Client) -> bool:
        # An SSE client never sends after its request: readable means it closed (b"") or is
        # misbehaving (data); both end the stream. Only a spurious wake-up keeps it.
        try:
            client.sock.recv(1, socket.MSG_PEEK | socket.MSG_DONTWAIT)
        except BlockingIOError:
            return False
        except OSError:
            pass
        return True

    @staticmethod
    def _end(client: _Client) -> None:
        # shutdown, never close: the server that accepted the socket still owns its descriptor.
        try:
            client.sock.shutdown(socket.SHUT_RDWR)
        except OSError:
            pass
        client.sub.close()
        client.done.set()
