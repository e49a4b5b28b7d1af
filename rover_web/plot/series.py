"""One plotted series: a bounded ring of (time, value) and its decimation for a chart. Pure Python."""

from __future__ import annotations

import threading
from collections import deque

MAX_POINTS = 2000


def decimate(t: list[float], v: list[float], max_points: int = MAX_POINTS) -> tuple[list[float], list[float]]:
    """At most `max_points` points: per bucket of neighbours its minimum and its maximum, in time order,
    so a spike survives thinning (a plain every-nth sample would hide it)."""
    n = len(t)
    if n <= max_points:
        return list(t), list(v)
    buckets = max_points // 2
    size = -(-n // buckets)  # ceil
    out_t: list[float] = []
    out_v: list[float] = []
    for start in range(0, n, size):
        end = min(start + size, n)
        chunk = v[start:end]
        lo = start + chunk.index(min(chunk))
        hi = start + chunk.index(max(chunk))
        for i in sorted({lo, hi}):
            out_t.append(t[i])
            out_v.append(v[i])
    return out_t, out_v


class SeriesRing:
    def __init__(self, keep: int):
        self.keep = keep
        self._t: deque[float] = deque(maxlen=keep)
        self._v: deque[float] = deque(maxlen=keep)
        self.skipped_nonfinite = 0
        self._lock = threading.Lock()

    def add_many(self, points: list[tuple[float, float]]) -> None:
        with self._lock:
            for t, v in points:
                self._t.append(t)
                self._v.append(v)

    def __len__(self) -> int:
        with self._lock:
            return len(self._t)

    def window(self, since: float, max_points: int = MAX_POINTS) -> tuple[list[float], list[float], bool]:
        """Points at or after `since`, decimated; (t, v, decimated)."""
        with self._lock:
            t, v = list(self._t), list(self._v)
        # Times only grow (they are arrival times), so the window is a suffix.
        lo, hi = 0, len(t)
        while lo < hi:
            mid = (lo + hi) // 2
            if t[mid] < since:
                lo = mid + 1
            else:
                hi = mid
        t, v = t[lo:], v[lo:]
        dt, dv = decimate(t, v, max_points)
        return dt, dv, len(dt) < len(t)
