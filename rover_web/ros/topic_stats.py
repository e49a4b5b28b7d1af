"""Per-topic message age and rate, for /api/status and the link-health bar. Pure Python."""

from __future__ import annotations

import threading
import time
from collections import deque


class TopicStats:
    """Arrival times of the last few seconds of messages; rate is measured, not assumed."""

    def __init__(self, topic: str, type_name: str, window_s: float = 5.0, max_samples: int = 512):
        self.topic = topic
        self.type_name = type_name
        self.count = 0
        self._window_s = window_s
        self._arrivals: deque[float] = deque(maxlen=max_samples)
        self._lock = threading.Lock()

    def record(self, now: float | None = None) -> None:
        now = time.monotonic() if now is None else now
        with self._lock:
            self.count += 1
            self._arrivals.append(now)

    def snapshot(self, stale_after_s: float, now: float | None = None) -> dict:
        now = time.monotonic() if now is None else now
        with self._lock:
            last = self._arrivals[-1] if self._arrivals else None
            recent = [t for t in self._arrivals if now - t <= self._window_s]
            count = self.count
        age = None if last is None else max(0.0, now - last)
        rate = 0.0
        if len(recent) >= 2 and recent[-1] > recent[0]:
            # Messages per second over the span they cover, not over the whole window.
            rate = (len(recent) - 1) / (recent[-1] - recent[0])
            # A topic that just went silent must not keep showing its old rate.
            if age is not None and age > 2.0 / rate:
                rate = (len(recent) - 1) / (now - recent[0])
        return {
            "topic": self.topic,
            "type": self.type_name,
            "count": count,
            "age_s": None if age is None else round(age, 3),
            "rate_hz": round(rate, 2),
            "fresh": age is not None and age <= stale_after_s,
        }
