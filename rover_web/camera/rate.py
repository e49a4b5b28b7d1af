"""Per-viewer MJPEG rate control: what each viewer's path really delivers, and the frame rate,
JPEG quality and size that fit it. Pure Python; the clock is injected.

The server learns the path from its own socket, with no help from the client (curl and <img>
work as before): after writing a frame it watches the socket's queued bytes (SIOCOUTQ: sent but
not yet acknowledged, plus not yet sent) until they fall below a budget (a quarter of the frame,
2 to 16 kB). That drain time is the measurement, and the rule that follows from it is what keeps the bottleneck's buffer
empty: a new frame never goes into the socket while the previous one is still queued beyond the
budget, so at most about one frame of video stands in front of an e-stop reply or a teleop frame.

From the drain times a viewer keeps a target rate (bytes/s) and paces its frames to it:
- a frame that took longer to drain than its pacing interval means the path is slower than the
  target: the target drops to BACKOFF × the rate that frame was delivered at (by at most half
  at a time);
- a frame that drained in less than half its interval means there is room: the target goes
  back at once to BACKOFF × the path's median rate over its last SAMPLES frames, and beyond
  that climbs slowly (probing, in case the link got better; faster once the path has not pushed
  back for CALM_S). So a brief stall or a busy reader costs a moment, a path that holds up most
  frames lowers the rate within a dozen frames, and a deep buffer is not refilled at once.
The target is also held under the per-viewer cap and the viewer's fair share of the total video
budget (Budget). Frame rate is lowered first (frames are paced, the freshest one is sent); when
even FPS_FLOOR frames a second do not fit, the JPEG quality steps down, then the size (Ladder);
they step up again only when the better step would run at UP_MARGIN × the floor for UP_HOLD_S.
"""

from __future__ import annotations

import math
import statistics
import threading
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass

# Bytes a viewer's socket may still hold when the next frame is written: small, so the video
# never builds a queue at the bottleneck; not zero, so the next frame's first bytes can follow
# the previous frame's last ones without a round trip of silence on a fast path. A quarter of
# the last frame, between 2 and 16 kB: the queue left is always a small part of one frame.
QUEUE_BUDGET_BYTES = 16 * 1024
MIN_QUEUE_BUDGET_BYTES = 2048
# A frame that drained within this time was not held up: the path is at least bytes / this fast.
MIN_SAMPLE_S = 0.010
BACKOFF = 0.85  # share of the measured rate aimed at, leaving room for teleop and events
PROBE_PER_S = 0.05  # how fast it climbs beyond that soon after the path last pushed back (+5 % a second)
FREE_PER_S = 0.5  # ... and once it has not for CALM_S (the link may have got better: find out soon)
CALM_S = 5.0
# The path's rate is the median of the last SAMPLES drain samples (of at most SAMPLE_WINDOW_S):
# a frame held up now and then (a busy reader, a retransmission) does not lower it, while a path
# that holds up most frames does within a dozen of them.
SAMPLES = 20
SAMPLE_WINDOW_S = 10.0
# Below this frame rate, quality and then size are lowered instead. It also bounds how long one
# frame holds the bottleneck (about BACKOFF / FPS_FLOOR s), which is what an e-stop reply may
# wait behind: 85 ms at 10.
FPS_FLOOR = 10.0
UP_MARGIN = 1.5  # a better step must fit at this × the floor before it is taken again
DOWN_HOLD_S = 1.0  # how long the rate must be too low before stepping down (a stall is not a trend)
UP_HOLD_S = 3.0  # how long a better step must fit before stepping up
REPORT_WINDOW_S = 3.0  # the window fps and kbit/s are measured over

QUALITY_STEPS = (60, 40, 25)
SCALE_STEPS = (1.0, 0.75, 0.5, 0.25)
# JPEG size against quality, relative to quality 80 (measured on a 640×480 camera image with grain).
_QUALITY_SIZE = ((15, 0.11), (25, 0.18), (40, 0.32), (50, 0.4), (60, 0.5), (70, 0.67), (80, 1.0), (90, 1.75),
                 (100, 4.0))


@dataclass(frozen=True)
class Step:
    """One output choice: JPEG quality and a scale of the asked (or camera's) size."""

    quality: int
    scale: float = 1.0


def quality_size(quality: int) -> float:
    """Rough JPEG size at `quality` relative to quality 80 (a first guess; real sizes are learned)."""
    points = _QUALITY_SIZE
    if quality <= points[0][0]:
        return points[0][1]
    for (q0, s0), (q1, s1) in zip(points, points[1:], strict=False):
        if quality <= q1:
            return s0 + (s1 - s0) * (quality - q0) / (q1 - q0)
    return points[-1][1]


def ladder(quality: int) -> tuple[Step, ...]:
    """Best first: the asked quality at full size, lower qualities, then smaller sizes at the lowest."""
    qualities = [quality] + [q for q in QUALITY_STEPS if q < quality]
    return tuple([Step(q, 1.0) for q in qualities] + [Step(qualities[-1], s) for s in SCALE_STEPS[1:]])


def model_size(step: Step) -> float:
    return quality_size(step.quality) * step.scale * step.scale


class Budget:
    """The total video budget, shared by the viewers max-min fairly: a viewer whose own path or cap
    allows less than an equal share gets what it can use, and the rest is split among the others.
    Thread-safe (every viewer's request thread asks)."""

    def __init__(self, total_bps: float | None):
        self.total_bps = total_bps or None
        self._demands: dict[int, float] = {}
        self._lock = threading.Lock()
        self._next = 0

    def join(self) -> int:
        with self._lock:
            self._next += 1
            self._demands[self._next] = math.inf
            return self._next

    def leave(self, member: int) -> None:
        with self._lock:
            self._demands.pop(member, None)

    def share(self, member: int, demand_bps: float) -> float:
        """Record what `member` could use now, and return what it may use (inf without a total)."""
        with self._lock:
            self._demands[member] = demand_bps
            if self.total_bps is None:
                return math.inf
            return fair_shares(self._demands, self.total_bps).get(member, 0.0)


def fair_shares(demands: dict[int, float], total: float) -> dict[int, float]:
    """Max-min fair split of `total` among `demands`."""
    shares, left, waiting = {}, total, sorted(demands.items(), key=lambda item: item[1])
    while waiting:
        equal = left / len(waiting)
        member, demand = waiting[0]
        if demand > equal:
            for member, _ in waiting:
                shares[member] = equal
            break
        shares[member] = demand
        left -= demand
        waiting.pop(0)
    return shares


class Meter:
    """Frames and bytes sent over the last REPORT_WINDOW_S: the fps and kbit/s a viewer gets."""

    def __init__(self, clock: Callable[[], float] = time.monotonic):
        self._clock = clock
        self._sent: deque[tuple[float, int]] = deque()
        self.frames = 0
        self.bytes = 0
        self.size: tuple[int, int] | None = None
        self.quality: int | None = None
        self._lock = threading.Lock()

    def sent(self, nbytes: int, size: tuple[int, int] | None = None, quality: int | None = None) -> None:
        now = self._clock()
        with self._lock:
            self._sent.append((now, nbytes))
            self.frames += 1
            self.bytes += nbytes
            self.size, self.quality = size or self.size, quality or self.quality
            self._trim(now)

    def _trim(self, now: float) -> None:
        while self._sent and now - self._sent[0][0] > REPORT_WINDOW_S:
            self._sent.popleft()

    def rates(self) -> tuple[float, float]:
        """(frames/s, bytes/s) over the window, counted over the full window once it has passed."""
        now = self._clock()
        with self._lock:
            self._trim(now)
            if not self._sent:
                return 0.0, 0.0
            span = max(now - self._sent[0][0], 1.0 / max(1, len(self._sent)), 0.2)
            if len(self._sent) > 1:
                span = max(span, (now - self._sent[0][0]) * len(self._sent) / (len(self._sent) - 1))
            span = min(span, REPORT_WINDOW_S)
            return len(self._sent) / span, sum(n for _, n in self._sent) / span

    def report(self) -> dict:
        fps, bps = self.rates()
        return {"fps": round(fps, 2), "kbps": round(bps * 8 / 1000, 1),
                "width": self.size[0] if self.size else None, "height": self.size[1] if self.size else None,
                "quality": self.quality, "frames": self.frames, "bytes": self.bytes}


class ViewerRate:
    """One MJPEG viewer's rate control. The stream loop asks `wait_s(queued)` until it says 0, then
    sends the newest frame at `step` and calls `sent(...)`; everything else follows from those."""

    def __init__(self, quality: int, *, max_bps: float | None = None, budget: Budget | None = None,
                 clock: Callable[[], float] = time.monotonic, queue_budget: int = QUEUE_BUDGET_BYTES):
        self.steps = ladder(quality)
        self.index = 0
        self.max_bps = max_bps or math.inf
        self.queue_budget = queue_budget
        self.source_fps: float | None = None  # the camera's measured rate, set by the stream loop
        self.target_bps = math.inf  # from drain times; inf until the path has shown a limit
        self.meter = Meter(clock)
        self._clock = clock
        self._budget = budget
        self._member = budget.join() if budget else None
        self._share = math.inf
        self._sizes: dict[int, float] = {}  # step index -> learned bytes per frame
        self._samples: deque[tuple[float, float]] = deque(maxlen=SAMPLES)  # (time, delivered bytes/s)
        # The frame draining: (written at, bytes, queued before, watched closely since it was written).
        self._pending: tuple[float, int, int, bool] | None = None
        self._last: tuple[float, int] | None = None  # the last frame written: (at, bytes)
        self._adjusted = clock()
        self._pushed_back = -math.inf  # when a frame last drained slower than aimed at
        self._low_since: float | None = None
        self._fits_since: float | None = None
        self._stepped = clock()
        self._blocked: set[int] = set()  # steps the server refused (producer cap)
        self._in_use = 0  # the step of the last frame sent
        self.queued = 0  # the socket's queued bytes at the last look
        self.queued_max = 0  # the most seen just before a frame was written
        self.drain_s: float | None = None

    @property
    def step(self) -> Step:
        return self.steps[self.index]

    def close(self) -> None:
        if self._budget is not None and self._member is not None:
            self._budget.leave(self._member)

    # --- the stream loop's side ---

    def pace_s(self, queued: Callable[[], int]) -> float:
        """Seconds until the next frame is due at the target rate (0: now); `queued()` reads the
        socket's queued bytes (only while pacing holds a frame back). While it says wait, the loop
        asks again within a few ms, so the frame's drain time is measured on the way. The loop then
        takes the newest message and asks hold_s before writing it."""
        now = self._clock()
        self._choose_step(now)
        if self._last is None:
            return 0.0
        at, nbytes = self._last
        pause = max(0.0, at + nbytes / self.rate_bps() - now)
        if pause > 0 and self._pending is not None:
            pause = min(pause, self._look(now, queued()))
        return pause

    def _look(self, now: float, queued: int) -> float:
        """Watch the frame draining: seconds until the next look, or inf once it has left."""
        self.queued = queued
        started, nbytes, before, _ = self._pending
        if queued > self.queue_limit(nbytes):
            self._pending = (started, nbytes, before, True)
            return 0.002 if now - started < 0.02 else 0.01
        self._drained(now, queued)
        return math.inf

    def hold_s(self, queued: int) -> float:
        """Seconds to wait before looking at the socket again (0: write now), given its queued bytes.

        The first look usually comes a frame interval after the write: if the frame has left by
        then, the path kept up with the camera and nothing is measured (when it left is not
        known). If not, the loop watches closely from then on, and the time it took is a sample.
        """
        now = self._clock()
        self.queued = queued
        if self._pending is None:
            return 0.0
        started, nbytes, before, watching = self._pending
        if not watching and queued <= self.queue_limit(nbytes) and now - started > MIN_SAMPLE_S:
            self._pending = None  # left at some time since: not held up by the path
            self._sample(now, math.inf)
            self._room(now)
            return 0.0
        wait = self._look(now, queued)
        return wait if wait < math.inf else 0.0

    def sent(self, nbytes: int, started: float, queued_before: int, *, size: tuple[int, int] | None = None,
             step_index: int | None = None) -> None:
        """A frame of `nbytes` was written (the write began at `started`, with `queued_before` bytes
        already in the socket)."""
        self._pending = (started, nbytes, queued_before, False)
        self._last = (started, nbytes)
        self.queued_max = max(self.queued_max, queued_before)
        index = self.index if step_index is None else step_index
        self._in_use = index
        learned = self._sizes.get(index)
        self._sizes[index] = nbytes if learned is None else 0.7 * learned + 0.3 * nbytes
        self.meter.sent(nbytes, size, self.steps[index].quality)

    def refused(self, index: int) -> None:
        """The server cannot open step `index` (too many different streams): back to the step in use."""
        self._blocked.add(index)
        self.index = self._in_use

    # --- inside ---

    def queue_limit(self, frame_bytes: int) -> int:
        """The bytes the socket may hold when the frame after one of `frame_bytes` is written."""
        return int(max(MIN_QUEUE_BUDGET_BYTES, min(self.queue_budget, frame_bytes / 4)))

    def rate_bps(self) -> float:
        """What this viewer aims at now: its path, its cap and its share of the total budget."""
        return min(self.target_bps, self.max_bps, self._share)

    def path_bps(self) -> float | None:
        """The path's median delivery rate over its last frames (inf when most were not held up),
        None before the first. Also read by GET /api/camera/viewers while the stream's thread adds
        samples: the deque is copied in one step first (tuple() holds the GIL throughout; a
        generator over it let the other thread in, and CI got "deque mutated during iteration")."""
        samples = tuple(self._samples)
        return statistics.median(r for _, r in samples) if samples else None

    def _drained(self, now: float, queued: int) -> None:
        started, nbytes, before, _ = self._pending
        self._pending = None
        took = now - started
        self.drain_s = took
        interval = nbytes / self.rate_bps() if self.rate_bps() < math.inf else 0.0
        held = took > MIN_SAMPLE_S and before + nbytes > self.queue_limit(nbytes)
        # What left while the socket was busy; a frame not held up counts as "fast enough".
        rate = max(1, before + nbytes - queued) / took if held else math.inf
        self._sample(now, rate)
        if held and took > interval:  # slower than aimed at
            # Down to what was delivered, but by at most half at a time: one frame held up
            # (a busy reader) is not yet a slower link.
            sending = self.meter.rates()[1]
            self.target_bps = max(BACKOFF * rate, 0.5 * min(self.target_bps, sending))
            self._pushed_back = self._adjusted = now
            return
        if took < 0.5 * interval or took <= MIN_SAMPLE_S:
            self._room(now)

    def _sample(self, now: float, rate: float) -> None:
        while self._samples and now - self._samples[0][0] > SAMPLE_WINDOW_S:
            self._samples.popleft()
        self._samples.append((now, rate))

    def _room(self, now: float) -> None:
        """The last frame left in good time: the target may rise."""
        dt = min(1.0, now - self._adjusted)
        self._adjusted = now
        if self.target_bps == math.inf:
            return  # nothing has held a frame up yet
        known = self.path_bps()
        if known is not None and self.target_bps < BACKOFF * known:
            # A rate the path has carried lately (or, when most frames were not held up, no
            # limit): at once.
            self.target_bps = BACKOFF * known
        else:
            calm = now - self._pushed_back >= CALM_S
            self.target_bps *= 1 + (FREE_PER_S if calm else PROBE_PER_S) * dt

    def frame_bytes(self, index: int) -> float | None:
        """Bytes a frame at step `index` has (learned), or would have (from the nearest learned step)."""
        if index in self._sizes:
            return self._sizes[index]
        if not self._sizes:
            return None
        near = min(self._sizes, key=lambda i: abs(i - index))
        return self._sizes[near] * model_size(self.steps[index]) / model_size(self.steps[near])

    def _fps_at(self, index: int, rate: float) -> float:
        size = self.frame_bytes(index)
        return math.inf if not size or rate == math.inf else rate / size

    def _choose_step(self, now: float) -> None:
        if self.index == 0 and self._budget is None and self.rate_bps() == math.inf:
            return  # the usual case on a fast path: nothing to choose
        top = self.frame_bytes(0)
        fps = self.source_fps or 30.0
        demand = fps * top * 1.25 if top else math.inf  # the most this viewer could use
        if self._budget is not None:
            self._share = self._budget.share(self._member, min(self.target_bps, self.max_bps, demand))
        rate = self.rate_bps()
        floor = min(FPS_FLOOR, fps)
        if self._fps_at(self.index, rate) < floor:
            self._fits_since = None
            self._low_since = self._low_since if self._low_since is not None else now
            if now - self._low_since >= DOWN_HOLD_S:
                better = self._down(rate, floor)
                if better != self.index:
                    self.index, self._stepped, self._low_since = better, now, None
            return
        self._low_since = None
        up = self.index - 1
        while up >= 0 and up in self._blocked:
            up -= 1
        if up < 0 or self._fps_at(up, rate) < UP_MARGIN * floor:
            self._fits_since = None
            return
        self._fits_since = self._fits_since if self._fits_since is not None else now
        if now - self._fits_since >= UP_HOLD_S and now - self._stepped >= UP_HOLD_S:
            self.index, self._stepped, self._fits_since = up, now, None

    def _down(self, rate: float, floor: float) -> int:
        """The best step below the current one that fits the floor, else the last one."""
        for index in range(self.index + 1, len(self.steps)):
            if index in self._blocked:
                continue
            if self._fps_at(index, rate) >= floor:
                return index
        allowed = [i for i in range(self.index + 1, len(self.steps)) if i not in self._blocked]
        return allowed[-1] if allowed else self.index

    def report(self) -> dict:
        path = self.path_bps()
        path = None if path == math.inf else path
        rate = self.rate_bps()
        return {**self.meter.report(), "step": self._in_use, "steps": len(self.steps),
                "scale": self.steps[self._in_use].scale,
                "target_kbps": None if rate == math.inf else round(rate * 8 / 1000, 1),
                "path_kbps": None if path is None else round(path * 8 / 1000, 1),
                "queued_bytes": self.queued, "queued_max_bytes": self.queued_max,
                "drain_ms": None if self.drain_s is None else round(1000 * self.drain_s, 1)}
