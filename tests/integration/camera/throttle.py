"""A slow link for one TCP connection, on 127.0.0.1: a proxy thread that carries server-to-client
bytes at a fixed rate and reads from the server only as fast as it forwards, through a small
receive buffer, so the server's socket fills up exactly as it would behind a slow radio.

Also: `server_queue(port, peer_port)`, the bytes a server-side socket holds (sent, not yet
acknowledged, or not sent), read from /proc/net/tcp, independently of the app's own figures.
"""

from __future__ import annotations

import socket
import threading
import time


class Throttle:
    def __init__(self, target_port: int, bytes_per_s: float, rcvbuf: int = 8192, chunk: int = 2048):
        self.target_port = target_port
        self.bytes_per_s = bytes_per_s
        self.rcvbuf, self.chunk = rcvbuf, chunk
        self.listener = socket.create_server(("127.0.0.1", 0))
        self.port = self.listener.getsockname()[1]
        self.url = f"http://127.0.0.1:{self.port}"
        self.upstream_port: int | None = None  # the proxy's own port on its connection to the server
        self.carried = 0
        self._stop = threading.Event()
        self._sockets: list[socket.socket] = []
        self._threads: list[threading.Thread] = []
        self._start(self._accept)

    def _start(self, target, *args):
        thread = threading.Thread(target=target, args=args, daemon=True)
        thread.start()
        self._threads.append(thread)

    def _accept(self):
        try:
            client, _ = self.listener.accept()
        except OSError:
            return
        upstream = socket.socket()
        upstream.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, self.rcvbuf)  # before connect: the window
        upstream.connect(("127.0.0.1", self.target_port))
        self.upstream_port = upstream.getsockname()[1]
        self._sockets += [client, upstream]
        self._start(self._pipe, client, upstream)  # the request, at full speed
        self._start(self._slow, upstream, client)

    def _pipe(self, src, dst):
        try:
            while data := src.recv(65536):
                dst.sendall(data)
        except OSError:
            pass

    def _slow(self, src, dst):
        started = time.monotonic()
        try:
            while not self._stop.is_set():
                due = started + self.carried / self.bytes_per_s
                if due > time.monotonic():
                    time.sleep(max(0.0, min(0.05, due - time.monotonic())))  # due may pass meanwhile
                    continue
                data = src.recv(self.chunk)
                if not data:
                    break
                dst.sendall(data)
                self.carried += len(data)
        except OSError:
            pass
        finally:
            for sock in (src, dst):
                try:
                    sock.shutdown(socket.SHUT_RDWR)
                except OSError:
                    pass

    def close(self):
        self._stop.set()
        self.listener.close()
        for sock in self._sockets:
            try:
                sock.shutdown(socket.SHUT_RDWR)
            except OSError:
                pass
            sock.close()
        for thread in self._threads:
            thread.join(2)


def server_queue(port: int, peer_port: int) -> int | None:
    """tx_queue of the server's socket on 127.0.0.1:`port` connected to 127.0.0.1:`peer_port`."""
    local, remote = f"0100007F:{port:04X}", f"0100007F:{peer_port:04X}"
    with open("/proc/net/tcp") as table:
        for line in table.readlines()[1:]:
            fields = line.split()
            if fields[1] == local and fields[2] == remote:
                return int(fields[4].split(":")[0], 16)
    return None
