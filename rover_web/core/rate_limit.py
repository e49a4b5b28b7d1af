"""Per-client rate limits for the requests where one client's volume costs every other client:
refused panel commands (each one writes the operator log), panel unlock attempts and camera
snapshots (each one may open a subscription and encode a frame). Pure Python.

A sliding window on the monotonic clock, so a wall-clock jump neither frees nor locks anyone.
Written here rather than taken from `limits` (Flask-Limiter's engine): its memory storage keeps
wall-clock expiries and polls them on a timer thread a hundred times a second, and a refused
command is only known to count after the view has run.
"""

from __future__ import annotations

import threading
import time
from collections import deque
from collections.abc import Callable

MAX_TRACKED_KEYS = 10_000  # keys come from clients: the table must not grow without bound


class RateLimit:
    """At most `count` events per `window_s` for each key."""

    def __init__(self, count: int, window_s: float = 60.0, clock: Callable[[], float] = time.monotonic):
        self.count = count
        self.window_s = window_s
        self._clock = clock
        self._events: dict[str, deque[float]] = {}
        self._lock = threading.Lock()

    def retry_after_s(self, key: str) -> float:
        """Seconds until `key` may have one more event; 0 when it may now."""
        with self._lock:
            return self._wait(key, self._clock())

    def record(self, key: str) -> None:
        """Count an event that has happened (a command that was refused, say)."""
        now = self._clock()
        with self._lock:
            self._times(key, now).append(now)

    def hit(self, key: str) -> float:
        """Count an event if the key is under its limit and return 0; else the seconds to wait."""
        now = self._clock()
        with self._lock:
            wait = self._wait(key, now)
            if wait == 0.0:
                self._times(key, now).append(now)
            return wait

    def _wait(self, key: str, now: float) -> float:
        times = self._events.get(key)
        if not times:
            return 0.0
        while times and now - times[0] >= self.window_s:
            times.popleft()
        if len(times) < self.count:
            return 0.0
        return times[len(times) - self.count] + self.window_s - now

    def _times(self, key: str, now: float) -> deque[float]:
        times = self._events.get(key)
        if times is None:
            if len(self._events) >= MAX_TRACKED_KEYS:
                self._prune(now)
            times = self._events[key] = deque()
        return times

    def _prune(self, now: float) -> None:
        for key in [k for k, t in self._events.items() if not t or now - t[-1] >= self.window_s]:
            del self._events[key]
        if len(self._events) >= MAX_TRACKED_KEYS:  # all recent: forget the quietest half
            oldest = sorted(self._events, key=lambda k: self._events[k][-1])
            for key in oldest[: len(oldest) // 2]:
                del self._events[key]
