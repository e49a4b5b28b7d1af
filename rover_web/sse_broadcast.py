"""One thread writes every SSE stream.

Waking one thread per browser for every event costs a context switch and four small socket writes
(Werkzeug's chunked framing) per client. Instead the stream's request thread sends the response
head and snapshot itself, hands the socket to the Broadcaster and sleeps until the stream ends.
The Broadcaster waits on epoll for hub changes (a self-pipe), writable sockets and closed peers,
and sends each client what changed since its cursor with one non-blocking send. A client whose
socket buffer is full keeps its unsent bytes and takes no new frames until they are out; then it
gets the newest value of each channel: slow browsers skip stale values, and nothing per client
grows. No Flask here.
"""

from __future__ import annotations

import os
import selectors
import socket
import threading
import time
from collections import deque

from .events import EventHub, Subscription

_IDLE_CHECK_S = 1.0


class _Client:
    __slots__ = ("sock", "sub", "done", "out", "last_write")

    def __init__(self, sock: socket.socket, sub: Subscription):
        self.sock = sock
        self.sub = sub
        self.done = threading.Event()
        self.out = b""
        self.last_write = time.monotonic()


class Broadcaster:
    def __init__(self, hub: EventHub, keepalive_s: float):
        self._hub = hub
        self._keepalive_s = keepalive_s
        self._idle_check_s = min(_IDLE_CHECK_S, keepalive_s)
        self._wake_r, self._wake_w = os.pipe()
        os.set_blocking(self._wake_r, False)
        os.set_blocking(self._wake_w, False)
        self._incoming: deque[_Client] = deque()
        self._lock = threading.Lock()
        self._thread: threading.Thread | None = None
        self._clients: dict[int, _Client] = {}
        hub.add_listener(self._wake)

    def _wake(self) -> None:
        try:
            os.write(self._wake_w, b"\0")
        except (BlockingIOError, OSError):
            pass  # a wake-up is already pending (or we are closing)

    def attach(self, sock: socket.socket, sub: Subscription) -> threading.Event:
        """Serve `sock` from now on; the returned Event is set once the stream has ended."""
        client = _Client(sock, sub)
        with self._lock:
            if self._hub.closed:
                client.done.set()
                sub.close()
                return client.done
            self._incoming.append(client)
            if self._thread is None:
                self._thread = threading.Thread(target=self._run, name="sse-broadcaster", daemon=True)
                self._thread.start()
        self._wake()
        return client.done

    @property
    def client_count(self) -> int:
        return len(self._clients)

    # --- the one writer thread ---

    def _run(self) -> None:
        sel = selectors.DefaultSelector()
        sel.register(self._wake_r, selectors.EVENT_READ, None)
        next_idle_check = time.monotonic() + self._idle_check_s
        try:
            while True:
                timeout = max(0.0, next_idle_check - time.monotonic())
                for key, mask in sel.select(timeout):
                    client = key.data
                    if client is None:
                        self._drain_wake_pipe()
                    elif mask & selectors.EVENT_READ and self._peer_gone(client):
                        self._drop(sel, client)
                    elif mask & selectors.EVENT_WRITE:
                        self._flush(sel, client)
                self._accept(sel)
                if self._hub.closed:
                    break
                for client in list(self._clients.values()):
                    if not client.out:
                        data = client.sub.poll()
                        if data:
                            self._send(sel, client, data)
                now = time.monotonic()
                if now >= next_idle_check:
                    next_idle_check = now + self._idle_check_s
                    for client in list(self._clients.values()):
                        if not client.out and now - client.last_write >= self._keepalive_s:
                            self._send(sel, client, b": keep-alive\n\n")
        finally:
            for client in list(self._clients.values()):
                self._drop(sel, client)
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

    def _accept(self, sel: selectors.BaseSelector) -> None:
        with self._lock:
            while self._incoming:
                client = self._incoming.popleft()
                self._clients[client.sock.fileno()] = client
                sel.register(client.sock, selectors.EVENT_READ, client)

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

    def _send(self, sel: selectors.BaseSelector, client: _Client, data: bytes) -> None:
        try:
            sent = client.sock.send(data, socket.MSG_DONTWAIT | socket.MSG_NOSIGNAL)
        except BlockingIOError:
            sent = 0
        except OSError:
            self._drop(sel, client)
            return
        client.last_write = time.monotonic()
        if sent < len(data):
            client.out = data[sent:]
            sel.modify(client.sock, selectors.EVENT_READ | selectors.EVENT_WRITE, client)

    def _flush(self, sel: selectors.BaseSelector, client: _Client) -> None:
        data, client.out = client.out, b""
        sel.modify(client.sock, selectors.EVENT_READ, client)
        self._send(sel, client, data)

    def _drop(self, sel: selectors.BaseSelector, client: _Client) -> None:
        if self._clients.pop(client.sock.fileno(), None) is not None:
            try:
                sel.unregister(client.sock)
            except (KeyError, ValueError):
                pass
        self._end(client)

    @staticmethod
    def _end(client: _Client) -> None:
        # shutdown, never close: the server that accepted the socket still owns its descriptor.
        try:
            client.sock.shutdown(socket.SHUT_RDWR)
        except OSError:
            pass
        client.sub.close()
        client.done.set()
