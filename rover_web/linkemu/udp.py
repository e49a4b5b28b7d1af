"""The UDP relay: datagrams to the listening port go to the target from a socket of their own per
client address (as a NAT does), and the target's answers come back the same way, both through the
link's shared directions, where they may be lost, queued, dropped when the buffer is full, or
dropped in an outage."""

from __future__ import annotations

import asyncio
import logging
import socket

from .bottleneck import Flow
from .direction import Direction

log = logging.getLogger(__name__)

MAX_CLIENTS = 256  # a relay for a few WebRTC flows, not a NAT for a network
# Room in the kernel for a burst (a video frame is dozens of datagrams) while the loop is busy:
# datagrams the kernel drops before the relay reads them would be loss the profile did not ask for.
SOCKET_BUFFER = 1024 * 1024


def _roomy(transport: asyncio.DatagramTransport) -> None:
    transport.get_extra_info("socket").setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, SOCKET_BUFFER)


class _Back(asyncio.DatagramProtocol):
    """The socket towards the target for one client."""

    def __init__(self, client: _Client):
        self.client = client

    def datagram_received(self, data: bytes, addr) -> None:
        self.client.relay.down.push(self.client.down, data)

    def error_received(self, exc: Exception) -> None:  # e.g. ICMP port unreachable: UDP carries on
        log.debug("udp relay: %s", exc)


class _Client:
    def __init__(self, relay: UdpRelay, addr):
        self.relay, self.addr = relay, addr
        self.transport: asyncio.DatagramTransport | None = None
        self._waiting: list[bytes] = []
        self.up = Flow(f"udp up {addr}", datagrams=True, deliver=self._to_target)
        self.down = Flow(f"udp down {addr}", datagrams=True, deliver=self._to_client)

    def _to_target(self, data: bytes) -> None:
        if self.transport is None:
            self._waiting.append(data)
        else:
            self.transport.sendto(data)

    def _to_client(self, data: bytes) -> None:
        if self.relay.transport is not None:
            self.relay.transport.sendto(data, self.addr)

    async def connect(self) -> None:
        loop = asyncio.get_running_loop()
        try:
            self.transport, _ = await loop.create_datagram_endpoint(lambda: _Back(self),
                                                                    remote_addr=self.relay.target)
        except OSError as exc:
            log.info("udp relay: cannot reach %s:%d: %s", *self.relay.target, exc)
            self._waiting.clear()
            self.relay.clients.pop(self.addr, None)
            return
        _roomy(self.transport)
        for data in self._waiting:
            self.transport.sendto(data)
        self._waiting.clear()

    def close(self) -> None:
        if self.transport is not None:
            self.transport.close()


class UdpRelay(asyncio.DatagramProtocol):
    def __init__(self, listen: tuple[str, int], target: tuple[str, int], up: Direction, down: Direction):
        self.listen, self.target = listen, target
        self.up, self.down = up, down
        self.transport: asyncio.DatagramTransport | None = None
        self.clients: dict[object, _Client] = {}
        self._tasks: set[asyncio.Task] = set()

    async def start(self) -> tuple[str, int]:
        loop = asyncio.get_running_loop()
        await loop.create_datagram_endpoint(lambda: self, local_addr=self.listen)
        return self.transport.get_extra_info("sockname")[:2]

    def connection_made(self, transport) -> None:
        self.transport = transport
        _roomy(transport)

    def datagram_received(self, data: bytes, addr) -> None:
        client = self.clients.get(addr)
        if client is None:
            if len(self.clients) >= MAX_CLIENTS:
                return
            client = self.clients[addr] = _Client(self, addr)
            task = asyncio.get_running_loop().create_task(client.connect())
            self._tasks.add(task)
            task.add_done_callback(self._tasks.discard)
        self.up.push(client.up, data)

    def error_received(self, exc: Exception) -> None:
        log.debug("udp relay: %s", exc)

    async def stop(self) -> None:
        await asyncio.gather(*self._tasks, return_exceptions=True)
        for client in self.clients.values():
            client.close()
        if self.transport is not None:
            self.transport.close()
