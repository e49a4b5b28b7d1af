"""The link's scheduling maths, with no sockets and no event loop: testable with any clock.

A bottleneck is one direction of the link, shared by every connection through it: a FIFO of at
most `buffer_bytes` waiting to be serialised at `rate`, then a one-way delay with jitter. Bytes of
one flow (a TCP connection, a UDP client) never overtake each other: a link is a queue, and a byte
stream keeps its order. A Schedule, shared by both directions, says when the link is down: stalls
(everything held, as a TCP retransmission timeout does) and outages (nothing passes).

The async relays (tcp.py, udp.py) call push() when bytes arrive, and due() to collect what has
reached the far end; next_wakeup() says when to look again.
"""

from __future__ import annotations

import heapq
import itertools
import math
import random
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field

from .profiles import Profile

STALL, OUTAGE = "stall", "outage"
SEGMENT_BYTES = 1448  # one TCP segment's payload on Ethernet: what a packet loss costs
RTO_MIN_S = 0.2  # Linux's minimum retransmission timeout


@dataclass(order=True)
class Window:
    start: float
    end: float
    kind: str = field(compare=False)


class Schedule:
    """When the link is down. Windows are made lazily as time goes on, from a seeded random source,
    plus any added by hand (LinkEmulator.outage / .stall)."""

    def __init__(self, profile: Profile, rng: random.Random, now: float):
        self._rng = rng
        self._windows: list[Window] = []
        self._made_until = now
        self.started = {STALL: 0, OUTAGE: 0}  # windows whose start has passed (counted by prune)
        self.history: deque[Window] = deque(maxlen=10_000)  # windows that have ended, for benches
        self.set_profile(profile, now)

    def set_profile(self, profile: Profile, now: float) -> None:
        self.profile = profile
        self._next_stall = now + self._stall_gap() if profile.stall_every_s and profile.stall_ms else math.inf
        self._next_outage = (now + profile.outage_every_s / 2
                             if profile.outage_every_s and profile.outage_s else math.inf)
        self._windows = [w for w in self._windows if w.start <= now]  # the rest followed the old profile
        self._made_until = now

    def _stall_gap(self) -> float:
        return self.profile.stall_every_s * self._rng.uniform(0.5, 1.5)

    def _make_until(self, t: float) -> None:
        if t <= self._made_until:
            return
        while self._next_stall <= t:
            heapq.heappush(self._windows, Window(self._next_stall, self._next_stall + self.profile.stall_ms / 1000,
                                                 STALL))
            self._next_stall += self._stall_gap()
        while self._next_outage <= t:
            heapq.heappush(self._windows, Window(self._next_outage, self._next_outage + self.profile.outage_s, OUTAGE))
            self._next_outage += self.profile.outage_every_s
        self._made_until = t

    def add(self, kind: str, start: float, seconds: float) -> None:
        heapq.heappush(self._windows, Window(start, start + seconds, kind))

    def prune(self, now: float) -> None:
        """Forget windows that have ended, counting them."""
        self._make_until(now)
        while self._windows and self._windows[0].end <= now:
            window = heapq.heappop(self._windows)
            self.started[window.kind] += 1
            self.history.append(window)

    def down(self, t: float) -> tuple[float, str] | None:
        """If the link is down at t: when it comes up (through back-to-back windows) and why
        (an outage wins over a stall). None when it is up."""
        self._make_until(t)
        up, kind = t, None
        changed = True
        while changed:
            changed = False
            for w in self._windows:
                if w.start <= up < w.end:
                    up, changed = w.end, True
                    kind = OUTAGE if OUTAGE in (kind, w.kind) else STALL
        return (up, kind) if kind else None

    def next_outage_start(self, now: float) -> float:
        self._make_until(now)
        starts = [w.start for w in self._windows if w.kind == OUTAGE and w.start > now]
        return min([*starts, self._next_outage])

    def begun(self, now: float) -> list[Window]:
        """Every window that has begun by now (ended ones from the history), in order of start."""
        self.prune(now)
        return sorted([*self.history, *(w for w in self._windows if w.start <= now)])

    def count(self, kind: str, now: float) -> int:
        return self.started[kind] + sum(1 for w in self._windows if w.kind == kind and w.start <= now)


class Flow:
    """One TCP connection's direction, or one UDP client's: its bytes keep their order.
    `datagrams` (UDP): loss drops, a full buffer drops the newcomer (drop-tail), an outage drops
    everything. Otherwise (TCP) nothing is ever dropped: the relay reads no more than room()
    (backpressure), a loss becomes a retransmission delay and an outage holds the bytes."""

    _ids = itertools.count(1)

    def __init__(self, name: str = "", *, datagrams: bool = False,
                 deliver: Callable[[bytes], None] | None = None):
        self.id = next(self._ids)
        self.name = name or f"flow {self.id}"
        self.datagrams = datagrams
        self.deliver = deliver  # called by the relay with each chunk that arrives (b"" = end of stream)
        self.last_arrival = -math.inf


@dataclass
class _Chunk:
    flow: Flow
    data: bytes
    enqueued: float
    depart: float | None = None


class Bottleneck:
    """One direction of the link, carrying TCP and UDP flows alike through one FIFO."""

    def __init__(self, profile: Profile, schedule: Schedule, rng: random.Random,
                 clock: Callable[[], float] = time.monotonic):
        self.profile = profile
        self.schedule = schedule
        self._rng = rng
        self._clock = clock
        self._fifo: deque[_Chunk] = deque()
        self._queued = 0
        self._busy_until = -math.inf  # when the chunk being serialised has left
        self._flight: list[tuple[float, int, _Chunk]] = []  # heap by arrival time
        self._seq = itertools.count()
        self.bytes_in = self.bytes_passed = self.bytes_dropped = 0
        self.packets_dropped = 0
        self.queue_peak = 0

    # --- input ---

    @property
    def capacity(self) -> int:
        return self.profile.buffer_bytes

    @property
    def queued_bytes(self) -> int:
        return self._queued

    def room(self) -> int:
        return max(0, self.capacity - self._queued)

    def push(self, flow: Flow, data: bytes) -> bool:
        """Queue bytes at the link's entrance. False if they were dropped (datagrams only)."""
        now = self._clock()
        self._advance(now)
        size = len(data)
        self.bytes_in += size
        if flow.datagrams:
            down = self.schedule.down(now)
            if (down and down[1] == OUTAGE) or size > self.room() or self._rng.random() < self.profile.loss:
                self._drop(size)
                return False
        elif size > self.room() and self._queued:
            raise OverflowError("a TCP relay must read no more than room()")
        self._fifo.append(_Chunk(flow, data, now))
        self._queued += size
        self.queue_peak = max(self.queue_peak, self._queued)
        return True

    def _drop(self, size: int) -> None:
        self.bytes_dropped += size
        self.packets_dropped += 1

    # --- the link ---

    def _depart(self, chunk: _Chunk) -> float:
        """When the chunk has been serialised: after the one before it, never while the link is down."""
        start = max(self._busy_until, chunk.enqueued)
        if (down := self.schedule.down(start)) is not None:
            start = down[0]
        return start + len(chunk.data) / self.profile.rate_bytes_per_s

    def _advance(self, now: float) -> None:
        while self._fifo:
            head = self._fifo[0]
            if head.depart is None:
                head.depart = self._busy_until = self._depart(head)
            if head.depart > now:
                return
            self._fifo.popleft()
            self._queued -= len(head.data)
            if head.flow.datagrams and (down := self.schedule.down(head.depart)) and down[1] == OUTAGE:
                self._drop(len(head.data))  # an outage began while it waited: the radio lost it
                continue
            heapq.heappush(self._flight, (self._arrival(head), next(self._seq), head))

    def _arrival(self, chunk: _Chunk) -> float:
        p = self.profile
        delay_s = max(0.0, p.delay_ms + self._rng.uniform(-p.jitter_ms, p.jitter_ms)) / 1000
        arrival = chunk.depart + delay_s
        if not chunk.flow.datagrams and p.loss and chunk.data:
            segments = math.ceil(len(chunk.data) / SEGMENT_BYTES)
            if self._rng.random() < 1 - (1 - p.loss) ** segments:
                # A lost segment is sent again after a retransmission timeout: the stream waits for it.
                arrival += RTO_MIN_S + 2 * p.delay_ms / 1000
        arrival = max(arrival, chunk.flow.last_arrival)  # a flow's bytes keep their order
        chunk.flow.last_arrival = arrival
        return arrival

    # --- output ---

    def due(self) -> list[tuple[Flow, bytes]]:
        """Chunks that have reached the far end by now, in arrival order. While the link is down,
        TCP bytes wait and datagrams are lost."""
        now = self._clock()
        self._advance(now)
        self.schedule.prune(now)
        out: list[tuple[Flow, bytes]] = []
        down = self.schedule.down(now)
        held = []
        while self._flight and self._flight[0][0] <= now:
            chunk = heapq.heappop(self._flight)[2]
            if not down:
                self.bytes_passed += len(chunk.data)
                out.append((chunk.flow, chunk.data))
            elif chunk.flow.datagrams and down[1] == OUTAGE:
                self._drop(len(chunk.data))
            else:
                held.append(chunk)  # waits for the link, in order
        for chunk in held:
            heapq.heappush(self._flight, (down[0], next(self._seq), chunk))
        return out

    def next_wakeup(self) -> float | None:
        """The next time due() may return something or room() may grow; None when idle."""
        now = self._clock()
        self._advance(now)
        times = []
        if self._fifo:
            times.append(self._fifo[0].depart)
        if self._flight:
            first = self._flight[0][0]
            if first <= now and (down := self.schedule.down(now)):
                first = down[0]
            times.append(first)
        return min(times) if times else None

    def set_profile(self, profile: Profile) -> None:
        self.profile = profile

    def in_flight(self) -> int:
        return len(self._flight)
