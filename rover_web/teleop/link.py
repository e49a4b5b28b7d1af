"""How good one teleop socket's link is, measured from what crosses it. Pure Python, injectable clock.

What is measured, and from what:

- **Round trip** (`rtt_ms`): WebSocket pings carrying a 4-byte id (`ping()`), answered by the
  client's pong (`pong()`). Browsers answer pings in their network stack, without the page's
  JavaScript, so the figure is the path's own and cannot be made to look better by a page; the
  server measures it, so it needs no trust in the client and no extra client code. The median of
  the last RTT_SAMPLES: one spike (a page loading its scripts) does not read as a poor link, a
  real change shows within three samples. A ping still unanswered counts as at least its age, so
  a link that has gone quiet shows a growing round trip, not the last good one.
- **Jitter** (`jitter_ms`): RFC 3550's inter-arrival jitter of drive frames against the client's
  send time `t` (its own millisecond clock: only differences are used, so the two clocks need not
  agree): J += (|D| - J) / 16, with D the change in transit time between consecutive frames.
- **Stalls**: a frame that arrives more than STALL_S later than its send time says it should
  (arrival gap minus send gap; without `t`, the arrival gap) ended a stall. `stalls` counts them
  over the last WINDOW_S, `last_stall_ms` is the longest of those.
- **Lost and out of order** from `seq`: a jump forward counts the frames skipped as lost; a frame
  no newer than one already seen is out of order, and `arrived()` tells the caller to drop it.
- **Lateness** of each frame: its transit time minus the best transit of the last BASE_WINDOW_S
  (a sliding minimum, so a drift between the two clocks or a lasting change of route is forgotten).
  A frame held up in a stall arrives late by about the stall; the controller dates its freshness
  from when it was sent, not when it came, so a frame that waited in a buffer never extends the
  motion it asks for (teleop/ramp.py, docs/teleop.md).

The verdict `quality` is `ok`, `poor` or `too_poor`, whichever band the worst figure falls in
(POOR and TOO_POOR), with `why` naming it for people ("850 ms round trip").
"""

from __future__ import annotations

import math
import struct
import threading
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass

from rover_web.web.api_messages import said, with_wire

STALL_S = 0.2          # the TCP stalls are 0.2-1 s; shorter gaps are jitter
WINDOW_S = 60.0        # stalls are counted, and the longest reported, over this long
VERDICT_S = 10.0       # the verdict looks at stalls and losses this recent
BASE_WINDOW_S = 20.0   # the best transit over this long is the reference for lateness
RTT_SAMPLES = 5        # two and a half seconds of pings at the socket's LINK_S
JITTER_GAIN = 1 / 16   # RFC 3550
PINGS_KEPT = 16        # unanswered pings remembered; older ones are taken as lost
MIN_FRAMES_FOR_LOSS = 20


@dataclass(frozen=True)
class Thresholds:
    """A band's lower edges: reaching any one of them puts the link in the band."""

    rtt_ms: float
    jitter_ms: float
    stall_ms: float   # a stall at least this long within VERDICT_S
    loss: float       # share of frames lost within VERDICT_S


# Poor: driving works but feels it (a stall made the robot hold or ease off, video lags a little).
POOR = Thresholds(rtt_ms=250, jitter_ms=50, stall_ms=STALL_S * 1000, loss=0.02)
# Too poor: the picture the operator steers by is more than half a second old, or the robot has
# had to stop (a stall beyond the default hard bound, ROVER_WEB_TELEOP_DEADMAN_MAX_S).
TOO_POOR = Thresholds(rtt_ms=600, jitter_ms=150, stall_ms=1000, loss=0.10)

QUALITIES = ("ok", "poor", "too_poor")


class LinkMeter:
    """One session's link. Thread-safe: frames and pongs come from the socket's reader thread,
    pings and snapshots from its request thread and the controller."""

    def __init__(self, clock: Callable[[], float] = time.monotonic):
        self._clock = clock
        self._lock = threading.Lock()
        # seq
        self._seq: int | None = None
        self._lost_before = 0  # frames skipped just before the one admit() let in last
        self.lost = 0
        self.out_of_order = 0
        self.frames = 0
        # transit (arrival on our clock minus the client's send time), the run of frames
        self._base: deque[tuple[float, float]] = deque()  # (arrival, transit), transit increasing
        self._prev: tuple[float, float | None, float | None] | None = None  # arrival, sent_s, transit
        self._jitter_s: float | None = None
        # Pruned by snapshot(); bounded so a socket nobody asks about cannot grow them.
        self._stalls: deque[tuple[float, float]] = deque(maxlen=1024)  # (when it ended, how long)
        self._recent: deque[tuple[float, int]] = deque(maxlen=4096)    # (arrival, frames lost before it)
        # round trip
        self._next_ping = 1
        self._pings: dict[int, float] = {}
        self._rtts: deque[float] = deque(maxlen=RTT_SAMPLES)

    # --- frames ---

    def arrived(self, seq: int | None = None, sent_ms: float | None = None, now: float | None = None) -> float | None:
        """A drive frame has just come in: admit() then record()."""
        if now is None:
            now = self._clock()
        late = self.admit(seq, sent_ms, now)
        if late is not None:
            self.record(sent_ms, now)
        return late

    def admit(self, seq: int | None, sent_ms: float | None, now: float) -> float | None:
        """What the controller must know before it acts on a frame that came in at `now` (this
        meter's clock): None if it is out of order (not newer than a frame already seen), to be
        dropped; otherwise how late it is, in seconds (0 without `t`). Then record() it."""
        with self._lock:
            self._lost_before = 0
            if seq is not None:
                if self._seq is not None:
                    if seq <= self._seq:
                        self.out_of_order += 1
                        return None
                    self._lost_before = seq - self._seq - 1
                self._seq = seq
            if sent_ms is None:
                return 0.0
            transit = now - sent_ms / 1000.0
            base = self._base
            while base and base[-1][1] >= transit:
                base.pop()
            base.append((now, transit))
            while base[0][0] < now - BASE_WINDOW_S:
                base.popleft()
            return max(0.0, transit - base[0][1])

    def fence(self, seq: int | None) -> bool:
        """A stop frame numbered `seq` has come: no drive frame numbered up to it may be admitted
        after it, as it was sent before the stop (the data channel is unordered). False if a frame
        at least as new came first: this stop is older than input already acted on (or a repeat
        of a stop already seen) and must be ignored. Without a seq the floor stays where it is,
        at the highest seq seen, which admit() already holds."""
        if seq is None:
            return True
        with self._lock:
            if self._seq is not None:
                if seq <= self._seq:
                    return False
                self.lost += seq - self._seq - 1
            self._seq = seq
            return True

    def record(self, sent_ms: float | None, now: float) -> None:
        """The figures of an admitted frame. Kept apart from admit() so the controller can do
        this after it has published: measuring never delays a command."""
        with self._lock:
            self.frames += 1
            lost = self._lost_before
            if lost:
                self.lost += lost
            if self._seq is not None:
                self._recent.append((now, lost))  # only numbered frames tell of losses
            sent_s = None if sent_ms is None else sent_ms / 1000.0
            transit = None if sent_s is None else now - sent_s
            prev = self._prev
            if prev is not None:
                p_arrival, p_sent, p_transit = prev
                send_gap = sent_s - p_sent if sent_s is not None and p_sent is not None else 0.0
                stall = (now - p_arrival) - max(0.0, send_gap)
                if stall >= STALL_S:
                    self._stalls.append((now, stall))
                if transit is not None and p_transit is not None:
                    j = self._jitter_s or 0.0  # RFC 3550 starts at zero
                    self._jitter_s = j + (abs(transit - p_transit) - j) * JITTER_GAIN
            self._prev = (now, sent_s, transit)

    def idle(self) -> None:
        """The operator let go (a stop frame): the silence that follows is theirs, not the link's."""
        with self._lock:
            self._prev = None

    # --- round trip ---

    def ping(self) -> bytes:
        """The payload of a ping to send now."""
        with self._lock:
            number = self._next_ping
            self._next_ping = (number + 1) & 0xFFFFFFFF or 1
            self._pings[number] = self._clock()
            while len(self._pings) > PINGS_KEPT:
                del self._pings[next(iter(self._pings))]
            return struct.pack("!I", number)

    def pong(self, payload: bytes) -> bool:
        """A pong came back; False if it answers no ping of ours (unsolicited pongs are allowed)."""
        if len(payload) != 4:
            return False
        number = struct.unpack("!I", payload)[0]
        with self._lock:
            sent = self._pings.pop(number, None)
            if sent is None:
                return False
            rtt = max(0.0, self._clock() - sent)
            # Pongs come in order: pings sent before this one that are still open were lost.
            for older in [n for n, t in self._pings.items() if t <= sent]:
                del self._pings[older]
            self._rtts.append(rtt)
            return True

    # --- what is shown ---

    def snapshot(self) -> dict:
        now = self._clock()
        with self._lock:
            self._forget(now)
            rtt = sorted(self._rtts)[(len(self._rtts) - 1) // 2] if self._rtts else None  # the lower median
            if rtt is not None and self._pings:
                rtt = max(rtt, now - min(self._pings.values()))  # waiting on an answer counts
            stalls = [s for _, s in self._stalls]
            recent_stall = max((s for t, s in self._stalls if t >= now - VERDICT_S), default=0.0)
            recent = [lost for t, lost in self._recent if t >= now - VERDICT_S]
            figures = {
                "rtt_ms": None if rtt is None else round(rtt * 1000, 1),
                "jitter_ms": None if self._jitter_s is None else round(self._jitter_s * 1000, 1),
                "stalls": len(stalls),
                "last_stall_ms": round(max(stalls, default=0.0) * 1000),
                "lost": self.lost,
                "out_of_order": self.out_of_order,
            }
        loss = sum(recent) / (len(recent) + sum(recent)) if len(recent) >= MIN_FRAMES_FOR_LOSS else 0.0
        quality, why = verdict(figures["rtt_ms"], figures["jitter_ms"], recent_stall * 1000, loss)
        return with_wire({**figures, "quality": quality, "why": why})

    def _forget(self, now: float) -> None:
        while self._stalls and self._stalls[0][0] < now - WINDOW_S:
            self._stalls.popleft()
        while self._recent and self._recent[0][0] < now - VERDICT_S:
            self._recent.popleft()


def verdict(rtt_ms: float | None, jitter_ms: float | None, stall_ms: float, loss: float) -> tuple[str, str]:
    """(quality, why): the worst band any figure reaches, and the first figure that put it there."""
    figures = (
        (rtt_ms, "rtt_ms", lambda v: said("%(ms)d ms round trip", ms=round(v))),
        (jitter_ms, "jitter_ms", lambda v: said("%(ms)d ms jitter", ms=round(v))),
        (stall_ms, "stall_ms", lambda v: said("a %(ms)d ms stall", ms=round(v))),
        (loss, "loss", lambda v: said("%(percent)d %% of frames lost", percent=round(100 * v))),
    )
    for quality, band in (("too_poor", TOO_POOR), ("poor", POOR)):
        for value, name, say in figures:
            if value is not None and math.isfinite(value) and value >= getattr(band, name):
                return quality, say(value)
    return "ok", ""
