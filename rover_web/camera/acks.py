"""What an acknowledging MJPEG viewer has received: the server's count of body bytes written, the
page's count of body bytes received, and the difference, which is the queue the rate control
(rate.py) must see. Pure Python; the clock is injected.

Why: the rate control reads the server socket's queued bytes (SIOCOUTQ), which see the bottleneck
only when the path's TCP ends at the browser. A hop that terminates TCP on the way (nginx in front
of the app, a satellite link's performance-enhancing proxy, the link emulator) acknowledges
everything at once, so the socket looks empty while video piles up in the hop's own buffer, in
front of the e-stop. A page that says how many bytes it has really received shows that queue
again: `written - acked` is everything between the server and the page, wherever it waits.

Not all of that is a queue: bytes on their way (one round trip's worth at the rate the path
delivers, as TCP's own window keeps in flight) are not waiting anywhere. Counting them would make
every frame wait a whole acknowledgement round trip before the next is written (at most one frame
per round trip: a few frames a second on a radio, and on a busy machine even on loopback, whose
round trip through the page's script is tens of ms). So the queue the rate control sees is
`written - acked - in_flight`, where in_flight = the shortest acknowledgement delay seen lately ×
the rate acknowledged over the last second: the path's bandwidth-delay product, as BBR estimates it.
It is 0 until acks have been measured and decays to 0 within a second of a page that stops
acknowledging, so a silent page gets about a frame and no more.
"""

from __future__ import annotations

import secrets
import threading
import time
from collections import deque
from collections.abc import Callable

from rover_web.web.api_messages import explain
from rover_web.web.validate import InvalidInput

# An acknowledged stream whose page has said nothing new for this long while bytes were
# outstanding is ended (the page reconnects): a page that stopped acknowledging must not hold a
# stream, its producer and a thread for ever.
ACK_STALL_S = 30.0
# The shortest acknowledgement delay (write → ack) over this window is the path's round trip: long
# enough to have seen a moment with no queue, short enough to follow a path that changed.
MIN_DELAY_WINDOW_S = 10.0
# The rate acknowledged over this window is the path's delivery rate (0 when the page fell silent).
RATE_WINDOW_S = 1.0


class AckedStream:
    """One /stream?ack=1 response: bytes written, bytes the page acknowledged. Thread-safe: the
    stream's thread writes, the ack route's threads acknowledge."""

    def __init__(self, owner: str | None, clock: Callable[[], float] = time.monotonic):
        self.id = secrets.token_urlsafe(16)  # unguessable: an ack route's only name for the stream
        self.owner = owner  # the signed-in name that opened it (None with sign-in off)
        self._clock = clock
        self._lock = threading.Lock()
        self._written = 0
        self._acked = 0
        self._moved = clock()  # when the page last acknowledged new bytes, or bytes became outstanding
        self._writes: deque[tuple[int, float]] = deque()  # (written in all after a write, when) not yet acked
        self._delays: deque[tuple[float, float]] = deque()  # (when acked, write → ack seconds), min kept first
        self._acks: deque[tuple[float, int]] = deque()  # (when, bytes newly acknowledged) over RATE_WINDOW_S

    @property
    def written(self) -> int:
        with self._lock:
            return self._written

    @property
    def acked(self) -> int:
        with self._lock:
            return self._acked

    @property
    def unacked(self) -> int:
        with self._lock:
            return self._written - self._acked

    def wrote(self, nbytes: int) -> None:
        """The stream hands `nbytes` more body bytes to the server (call it before the write, so
        a page quick to acknowledge them never acknowledges more than was counted)."""
        with self._lock:
            now = self._clock()
            if self._written == self._acked:
                self._moved = now  # the wait for an acknowledgement starts now
            self._written += nbytes
            self._writes.append((self._written, now))

    def ack(self, value) -> bool:
        """The page has received `value` body bytes in all. True if that moved the count forward;
        an older (smaller) count changes nothing. InvalidInput for anything but a whole number
        from 0 to the bytes written."""
        if isinstance(value, bool) or not isinstance(value, int):
            raise InvalidInput("'bytes' must be a whole number: the body bytes received on the stream in all",
                               "bad_type")
        with self._lock:
            if not 0 <= value <= self._written:
                raise InvalidInput(
                    "'bytes' must be between 0 and %(written)s (the bytes sent so far), got %(value)s",
                    "out_of_range",
                    written=self._written,
                    value=value if abs(value) < 10**30 else explain("a larger number"),
                )
            if value <= self._acked:
                return False
            now = self._clock()
            self._acks.append((now, value - self._acked))
            self._acked = value
            self._moved = now
            self._measure(now, value)
            return True

    def _measure(self, now: float, acked: int) -> None:
        """The delay of the write whose last acknowledged byte this is, into the windowed minimum."""
        while self._writes and self._writes[0][0] < acked:
            self._writes.popleft()
        if not self._writes:
            return
        total, written_at = self._writes[0]  # the write that held the last byte acknowledged
        if total == acked:
            self._writes.popleft()
        delay = now - written_at
        # A monotonic deque: the front is the least delay of the window.
        while self._delays and self._delays[-1][1] >= delay:
            self._delays.pop()
        self._delays.append((now, delay))

    def in_flight(self) -> int:
        """The bytes the path holds on their way: shortest recent ack delay × recent ack rate."""
        with self._lock:
            return self._in_flight(self._clock())

    def _in_flight(self, now: float) -> int:
        while self._delays and now - self._delays[0][0] > MIN_DELAY_WINDOW_S:
            self._delays.popleft()
        while self._acks and now - self._acks[0][0] > RATE_WINDOW_S:
            self._acks.popleft()
        if not self._delays or not self._acks:
            return 0
        rate = sum(n for _, n in self._acks) / RATE_WINDOW_S
        return int(rate * self._delays[0][1])

    def queued(self, socket_queued: int | None) -> int:
        """The queue the rate control sees: what is in the server's socket, or what the page has
        not yet received beyond what is on its way, whichever is more."""
        with self._lock:
            waiting = self._written - self._acked - self._in_flight(self._clock())
        return max(socket_queued or 0, waiting, 0)

    def stalled(self) -> bool:
        """Bytes outstanding and no acknowledgement for ACK_STALL_S: the page stopped reading."""
        with self._lock:
            return self._written > self._acked and self._clock() - self._moved >= ACK_STALL_S

    def report(self) -> dict:
        with self._lock:
            return {"acked_bytes": self._acked, "unacked_bytes": self._written - self._acked,
                    "in_flight_bytes": self._in_flight(self._clock())}


class AckedStreams:
    """The open acknowledged streams of one robot, by id."""

    def __init__(self, clock: Callable[[], float] = time.monotonic):
        self._clock = clock
        self._streams: dict[str, AckedStream] = {}
        self._lock = threading.Lock()

    def open(self, owner: str | None) -> AckedStream:
        stream = AckedStream(owner, self._clock)
        with self._lock:
            self._streams[stream.id] = stream
        return stream

    def close(self, stream: AckedStream) -> None:
        with self._lock:
            self._streams.pop(stream.id, None)

    def find(self, stream_id: str, requester: str | None) -> AckedStream | None:
        """The stream `requester` (a signed-in name, or None) may acknowledge; None for an unknown
        or ended id and for another identity's stream alike, so an id's existence is not revealed."""
        with self._lock:
            stream = self._streams.get(stream_id)
        if stream is None or stream.owner != requester:
            return None
        return stream

    def __len__(self) -> int:
        with self._lock:
            return len(self._streams)
