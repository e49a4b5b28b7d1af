"""What an acknowledging MJPEG viewer has received: the server's count of body bytes written, the
page's count of body bytes received, and the difference, which is the queue the rate control
(rate.py) must see. Pure Python; the clock is injected.

Why: the rate control reads the server socket's queued bytes (SIOCOUTQ), which see the bottleneck
only when the path's TCP ends at the browser. A hop that terminates TCP on the way (nginx in front
of the app, a satellite link's performance-enhancing proxy, the link emulator) acknowledges
everything at once, so the socket looks empty while video piles up in the hop's own buffer, in
front of the e-stop. A page that says how many bytes it has really received shows that queue
again: `written - acked` is everything between the server and the page, wherever it waits.
"""

from __future__ import annotations

import secrets
import threading
import time
from collections.abc import Callable

from rover_web.web.validate import InvalidInput

# An acknowledged stream whose page has said nothing new for this long while bytes were
# outstanding is ended (the page reconnects): a page that stopped acknowledging must not hold a
# stream, its producer and a thread for ever.
ACK_STALL_S = 30.0


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
            if self._written == self._acked:
                self._moved = self._clock()  # the wait for an acknowledgement starts now
            self._written += nbytes

    def ack(self, value) -> bool:
        """The page has received `value` body bytes in all. True if that moved the count forward;
        an older (smaller) count changes nothing. InvalidInput for anything but a whole number
        from 0 to the bytes written."""
        if isinstance(value, bool) or not isinstance(value, int):
            raise InvalidInput("'bytes' must be a whole number: the body bytes received on the stream in all",
                               "bad_type")
        with self._lock:
            if not 0 <= value <= self._written:
                raise InvalidInput(f"'bytes' must be between 0 and {self._written} (the bytes sent so far), "
                                   f"got {value if abs(value) < 10**30 else 'a larger number'}", "out_of_range")
            if value <= self._acked:
                return False
            self._acked = value
            self._moved = self._clock()
            return True

    def queued(self, socket_queued: int | None) -> int:
        """The queue the rate control sees: what is in the server's socket, or what the page has
        not yet received, whichever is more."""
        return max(socket_queued or 0, self.unacked)

    def stalled(self) -> bool:
        """Bytes outstanding and no acknowledgement for ACK_STALL_S: the page stopped reading."""
        with self._lock:
            return self._written > self._acked and self._clock() - self._moved >= ACK_STALL_S

    def report(self) -> dict:
        with self._lock:
            return {"acked_bytes": self._acked, "unacked_bytes": self._written - self._acked}


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
