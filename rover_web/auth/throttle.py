"""Sign-in throttling: after `max_failures` failed sign-ins for one name within `window_s`, that
name is refused (429) for `lockout_s`. Pure Python, monotonic clock (a wall-clock jump changes nothing).

Keyed by the name tried, not the client address: an attacker guessing one operator's password from
many addresses is stopped all the same, and the robot's other users are not locked out with them.
"""

from __future__ import annotations

import threading
import time
from collections import deque
from collections.abc import Callable

MAX_TRACKED_NAMES = 10_000  # names are attacker-chosen: the table must not grow without bound


class LoginThrottle:
    def __init__(self, max_failures: int = 5, window_s: float = 60.0, lockout_s: float = 60.0,
                 clock: Callable[[], float] = time.monotonic):
        self.max_failures = max_failures
        self.window_s = window_s
        self.lockout_s = lockout_s
        self._clock = clock
        self._failures: dict[str, deque[float]] = {}
        self._locked_until: dict[str, float] = {}
        self._lock = threading.Lock()

    def retry_after_s(self, name: str) -> float:
        """Seconds this name must still wait; 0 when it may try."""
        with self._lock:
            until = self._locked_until.get(name)
            if until is None:
                return 0.0
            left = until - self._clock()
            if left <= 0:
                del self._locked_until[name]
                return 0.0
            return left

    def failed(self, name: str) -> None:
        now = self._clock()
        with self._lock:
            if len(self._failures) >= MAX_TRACKED_NAMES and name not in self._failures:
                self._prune(now)
            times = self._failures.setdefault(name, deque())
            times.append(now)
            while times and now - times[0] > self.window_s:
                times.popleft()
            if len(times) >= self.max_failures:
                self._locked_until[name] = now + self.lockout_s
                del self._failures[name]

    def succeeded(self, name: str) -> None:
        with self._lock:
            self._failures.pop(name, None)

    def _prune(self, now: float) -> None:
        for key in [k for k, times in self._failures.items() if not times or now - times[-1] > self.window_s]:
            del self._failures[key]
        if len(self._failures) >= MAX_TRACKED_NAMES:  # all recent: forget the oldest half
            oldest = sorted(self._failures, key=lambda k: self._failures[k][-1])
            for key in oldest[: len(oldest) // 2]:
                del self._failures[key]
        for key in [k for k, until in self._locked_until.items() if until <= now]:
            del self._locked_until[key]
