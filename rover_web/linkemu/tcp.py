"""The TCP relay: each accepted connection is joined to a new one to the target, both ways through
the link's shared directions. Bytes are read only while the bottleneck has room, so a full buffer
pushes back into the sender's TCP as a real bottleneck does."""

from __future__ import annotations

import asyncio
import contextlib
import logging
import socket

from .bottleneck import Flow
from .direction import Direction

log = logging.getLogger(__name__)

# Small kernel buffers on the emulator's own sockets: bytes waiting there are invisible to the
# bottleneck, and a large receive window would hide the backpressure the link exerts.
SOCKET_BUFFER = 32 * 1024


# Ethernet-sized segments on loopback (whose MTU is 64 kB). A peer's TCP sizes its congestion
# window, and from it its send buffer, in segments: with 64 kB segments a server streaming video
# behind a 2 Mbit/s link grows its send buffer to 4 MB (16 s queued in the server's kernel); with
# 1448-byte ones to about 1.3 MB (measured). A sender behind a real radio, whose window loss
# keeps near the bottleneck's buffer, holds about half that: see docs/field.md.
SEGMENT = 1448


def _link_like(sock: socket.socket) -> None:
    """Before connect or listen: the sizes a real link's peers would negotiate."""
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, SOCKET_BUFFER)
    sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_MAXSEG, SEGMENT)


def _small_buffers(sock: socket.socket) -> None:
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, SOCKET_BUFFER)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_SNDBUF, SOCKET_BUFFER)
    sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)


class _Connection:
    def __init__(self, relay: TcpRelay, client: asyncio.StreamWriter, server: asyncio.StreamWriter):
        self.relay = relay
        self.writers = (client, server)
        self.up = Flow("up", deliver=lambda data: self._deliver(server, data))
        self.down = Flow("down", deliver=lambda data: self._deliver(client, data))
        self.ended = 0

    def _deliver(self, writer: asyncio.StreamWriter, data: bytes) -> None:
        if writer.is_closing():
            return
        if data:
            writer.write(data)
            return
        # The end of one direction's stream, delivered in order after its last byte.
        if writer.can_write_eof():
            writer.write_eof()
        self.ended += 1
        if self.ended == 2:
            self.close()

    def close(self) -> None:
        for writer in self.writers:
            writer.close()
        self.relay.connections.discard(self)

    def abort(self) -> None:
        for writer in self.writers:
            writer.transport.abort()
        self.relay.connections.discard(self)


class TcpRelay:
    def __init__(self, listen: tuple[str, int], target: tuple[str, int], up: Direction, down: Direction,
                 chunk_bytes: int):
        self.listen, self.target = listen, target
        self.up, self.down = up, down
        self.chunk_bytes = chunk_bytes
        self.connections: set[_Connection] = set()
        self.accepted = 0
        self._server: asyncio.Server | None = None
        self._tasks: set[asyncio.Task] = set()
        self._stopping = False

    async def start(self) -> tuple[str, int]:
        sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        _link_like(sock)  # inherited by accepted sockets
        sock.bind(self.listen)
        # A small read-ahead limit: asyncio reads up to twice this before it stops reading the socket.
        self._server = await asyncio.start_server(self._accepted, sock=sock, limit=self.chunk_bytes)
        return sock.getsockname()[:2]

    async def stop(self) -> None:
        self._stopping = True
        if self._server is not None:
            self._server.close()
        for conn in list(self.connections):
            conn.abort()
        # A connection accepted just before the close has its handler task scheduled but not yet
        # started (so not in _tasks): it starts during the wait below, sees _stopping and aborts.
        while self._tasks:
            for task in list(self._tasks):
                task.cancel()
            await asyncio.gather(*self._tasks, return_exceptions=True)
        if self._server is not None:
            await self._server.wait_closed()
        # An aborted transport closes its socket in a callback on the next turns of the loop: give
        # them those turns, or the loop closes first and the sockets are left to the collector.
        for _ in range(3):
            await asyncio.sleep(0)

    def reset_all(self) -> None:
        """An outage that resets connections: both ends see them close at once."""
        for conn in list(self.connections):
            conn.abort()

    async def _accepted(self, client_r: asyncio.StreamReader, client_w: asyncio.StreamWriter) -> None:
        if self._stopping:
            client_w.transport.abort()
            return
        task = asyncio.current_task()
        self._tasks.add(task)
        self.accepted += 1
        sock = server_w = None
        try:
            _small_buffers(client_w.get_extra_info("socket"))
            sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
            _link_like(sock)
            _small_buffers(sock)
            sock.setblocking(False)
            try:
                await asyncio.get_running_loop().sock_connect(sock, self.target)
            except OSError as exc:
                sock.close()
                log.info("link emulator: target %s:%d refused: %s", *self.target, exc)
                client_w.transport.abort()
                return
            server_r, server_w = await asyncio.open_connection(sock=sock, limit=self.chunk_bytes)
            conn = _Connection(self, client_w, server_w)
            self.connections.add(conn)
            try:
                await asyncio.gather(self._pump(client_r, server_w, self.up, conn.up),
                                     self._pump(server_r, client_w, self.down, conn.down))
            finally:
                # Both ends read to their end, but the last bytes and the EOFs may still be in the
                # link: the connection stays listed (stop() can abort it) until _deliver closes it.
                if all(w.is_closing() for w in conn.writers):
                    self.connections.discard(conn)
        except asyncio.CancelledError:
            client_w.transport.abort()  # cancelled at any point: both ends of it go
            if server_w is not None:
                server_w.transport.abort()
            elif sock is not None:
                sock.close()
            # stop(): end quietly. Python 3.11's start_server asks a finished handler task for its
            # exception, which raises (and is logged) for a cancelled one.
            return
        finally:
            self._tasks.discard(task)

    async def _pump(self, reader: asyncio.StreamReader, dest: asyncio.StreamWriter, direction: Direction,
                    flow: Flow) -> None:
        """Read from one end while the link has room and the far end keeps up; push into the link."""
        try:
            while True:
                room = await direction.wait_room()
                with contextlib.suppress(ConnectionError):
                    await dest.drain()  # a far end that does not read pushes back through the link too
                data = await reader.read(min(self.chunk_bytes, room))
                if dest.is_closing():
                    return
                await direction.wait_room(len(data))  # another connection may have filled it meanwhile
                direction.push(flow, data)  # b"" at the end of the stream: delivered in order as EOF
                if not data:
                    return
                # Let the other connections' pumps in: with its reader's buffer full, this loop
                # would otherwise take all the room the link freed without ever yielding, and one
                # connection would have the link while the others waited (a real queue interleaves).
                await asyncio.sleep(0)
        except (ConnectionError, OSError):
            # A reset: the other side learns at once (a real link would carry the RST too).
            dest.transport.abort()
