"""LinkEmulator: the link between clients and a server, with its own event loop on a thread.

    with LinkEmulator("wifi-edge", listen="127.0.0.1:0", target="127.0.0.1:5000") as link:
        requests.get(f"http://127.0.0.1:{link.port}/api/status")
        link.outage(3)            # nothing passes for 3 s
        link.counters()           # bytes passed and dropped, queue depth, stalls, outages

Every TCP connection and UDP flow through one emulator shares its two bottlenecks (up: towards
the target, down: back to the clients) and one schedule of stalls and outages.
"""

from __future__ import annotations

import asyncio
import concurrent.futures
import random
import threading
import time

from .bottleneck import OUTAGE, SEGMENT_BYTES, STALL, Bottleneck, Schedule
from .direction import Direction
from .profiles import Profile, profile
from .tcp import TcpRelay
from .udp import UdpRelay

Address = tuple[str, int]


def parse_address(text: str | Address) -> Address:
    """'127.0.0.1:8000' (or a (host, port) pair) → ('127.0.0.1', 8000)."""
    if isinstance(text, tuple):
        return text
    host, sep, port = text.rpartition(":")
    if not sep or not host or not port.isdigit() or not 0 <= int(port) <= 65535:
        raise ValueError(f"address {text!r}: expected HOST:PORT, e.g. 127.0.0.1:8000")
    return host.strip("[]"), int(port)


def chunk_bytes(p: Profile) -> int:
    """How much a TCP relay reads at once: about 5 ms of the link, at least a segment, at most 16 kB.
    Small enough that a frame queued behind video waits for bytes, not for a whole read."""
    return int(min(16384, max(SEGMENT_BYTES, p.rate_bytes_per_s * 0.005)))


class LinkEmulator:
    def __init__(self, link: Profile | str, listen: str | Address | None = None, target: str | Address | None = None,
                 *, udp_listen: str | Address | None = None, udp_target: str | Address | None = None,
                 seed: int | None = None):
        self.profile = profile(link) if isinstance(link, str) else link
        if (listen is None) != (target is None) or (udp_listen is None) != (udp_target is None):
            raise ValueError("give a listen address with its target (TCP, UDP or both)")
        if listen is None and udp_listen is None:
            raise ValueError("nothing to relay: give listen/target, udp_listen/udp_target or both")
        self._tcp_addrs = (parse_address(listen), parse_address(target)) if listen is not None else None
        self._udp_addrs = (parse_address(udp_listen), parse_address(udp_target)) if udp_listen is not None else None
        self.seed = seed if seed is not None else random.randrange(2**32)
        self.address: Address | None = None      # where TCP clients connect (the real port if 0 was asked)
        self.udp_address: Address | None = None
        self._loop: asyncio.AbstractEventLoop | None = None
        self._thread: threading.Thread | None = None
        self._stopping: asyncio.Event | None = None

    @property
    def port(self) -> int:
        return self.address[1]

    @property
    def udp_port(self) -> int:
        return self.udp_address[1]

    # --- life ---

    def start(self) -> LinkEmulator:
        ready: concurrent.futures.Future = concurrent.futures.Future()
        self._thread = threading.Thread(target=self._run, args=(ready,), name="link-emulator", daemon=True)
        self._thread.start()
        try:
            ready.result(timeout=10)
        except BaseException:
            self._thread.join(5)
            raise
        return self

    def stop(self) -> None:
        if self._loop is not None and self._thread is not None and self._thread.is_alive():
            self._loop.call_soon_threadsafe(self._stopping.set)
            self._thread.join(10)

    def __enter__(self) -> LinkEmulator:
        return self.start()

    def __exit__(self, *exc) -> None:
        self.stop()

    def _run(self, ready: concurrent.futures.Future) -> None:
        loop = asyncio.new_event_loop()
        try:
            loop.run_until_complete(self._main(loop, ready))
        except BaseException as exc:
            if not ready.done():
                ready.set_exception(exc)
        finally:
            loop.run_until_complete(loop.shutdown_asyncgens())
            loop.close()

    async def _main(self, loop: asyncio.AbstractEventLoop, ready: concurrent.futures.Future) -> None:
        self._loop = loop
        self._stopping = asyncio.Event()
        now = time.monotonic()
        self.schedule = Schedule(self.profile, random.Random(self.seed), now)
        self.up = Direction("up", Bottleneck(self.profile, self.schedule, random.Random(self.seed + 1)))
        self.down = Direction("down", Bottleneck(self.profile, self.schedule, random.Random(self.seed + 2)))
        self.tcp = (TcpRelay(*self._tcp_addrs, self.up, self.down, chunk_bytes(self.profile))
                    if self._tcp_addrs else None)
        self.udp = UdpRelay(*self._udp_addrs, self.up, self.down) if self._udp_addrs else None
        tasks = [loop.create_task(self.up.run()), loop.create_task(self.down.run()),
                 loop.create_task(self._reset_on_outages())]
        try:
            if self.tcp:
                self.address = await self.tcp.start()
            if self.udp:
                self.udp_address = await self.udp.start()
            ready.set_result(None)
            await self._stopping.wait()
        finally:
            for relay in (self.tcp, self.udp):
                if relay:
                    await relay.stop()
            for task in tasks:
                task.cancel()
            await asyncio.gather(*tasks, return_exceptions=True)

    async def _reset_on_outages(self) -> None:
        """With reset_on_outage, every TCP connection is cut when an outage begins."""
        was_down = False
        while True:
            down = self.schedule.down(time.monotonic())
            is_down = bool(down and down[1] == OUTAGE)
            if is_down and not was_down and self.profile.reset_on_outage and self.tcp:
                self.tcp.reset_all()
            was_down = is_down
            await asyncio.sleep(0.05)

    def _call(self, fn):
        """Run fn on the emulator's loop (where all its state lives) and return its result."""
        if self._loop is None:
            raise RuntimeError("the link emulator is not running")
        done: concurrent.futures.Future = concurrent.futures.Future()

        def run() -> None:
            try:
                done.set_result(fn())
            except BaseException as exc:
                done.set_exception(exc)

        self._loop.call_soon_threadsafe(run)
        return done.result(timeout=10)

    # --- live controls (for tests and benches) ---

    def outage(self, seconds: float) -> None:
        """From now, nothing passes for `seconds` (TCP bytes wait, datagrams are lost)."""
        self._window(OUTAGE, seconds)

    def stall(self, ms: float) -> None:
        """From now, every byte is held for `ms` milliseconds."""
        self._window(STALL, ms / 1000)

    def _window(self, kind: str, seconds: float) -> None:
        def add() -> None:
            self.schedule.add(kind, time.monotonic(), seconds)
            self.up.kick()
            self.down.kick()
        self._call(add)

    def set_profile(self, link: Profile | str) -> None:
        new = profile(link) if isinstance(link, str) else link

        def swap() -> None:
            self.profile = new
            self.schedule.set_profile(new, time.monotonic())
            for direction in (self.up, self.down):
                direction.bottleneck.set_profile(new)
                direction.kick()
            if self.tcp:
                self.tcp.chunk_bytes = chunk_bytes(new)
        self._call(swap)

    def windows(self) -> list[tuple[float, float, str]]:
        """(start, end, "stall"|"outage") of every window begun so far, on time.monotonic()."""
        return self._call(lambda: [(w.start, w.end, w.kind) for w in self.schedule.begun(time.monotonic())])

    def counters(self) -> dict:
        """Bytes in, passed and dropped, queue depth now and at its peak, per direction; stalls and
        outages begun; connections."""
        def read() -> dict:
            now = time.monotonic()
            out = {}
            for direction in (self.up, self.down):
                b = direction.bottleneck
                out[direction.name] = {"bytes_in": b.bytes_in, "bytes_passed": b.bytes_passed,
                                       "bytes_dropped": b.bytes_dropped, "packets_dropped": b.packets_dropped,
                                       "queue_bytes": b.queued_bytes, "queue_peak": b.queue_peak,
                                       "in_flight": b.in_flight()}
            out["stalls"] = self.schedule.count(STALL, now)
            out["outages"] = self.schedule.count(OUTAGE, now)
            out["connections"] = len(self.tcp.connections) if self.tcp else 0
            out["accepted"] = self.tcp.accepted if self.tcp else 0
            out["udp_clients"] = len(self.udp.clients) if self.udp else 0
            return out
        return self._call(read)
