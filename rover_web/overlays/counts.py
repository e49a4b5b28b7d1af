"""Per-layer message counts: received, sent, and skipped by reason. Pure and thread-safe."""

from __future__ import annotations

import threading
from collections import Counter


class LayerCounts:
    def __init__(self, layer: str, topics: list[str]):
        self.layer = layer
        self.topics = topics
        self.received = 0
        self.sent = 0
        self.skipped: Counter[str] = Counter()
        self.dropped = 0  # items left out of messages that were drawn (a scan's beams with no return)
        self.placed_by: str | None = None  # how the latest drawn message was placed: tf, configured or map
        self._lock = threading.Lock()

    def receive(self) -> None:
        with self._lock:
            self.received += 1

    def send(self, placed_by: str | None = None) -> None:
        with self._lock:
            self.sent += 1
            if placed_by is not None:
                self.placed_by = placed_by

    def skip(self, reason: str, n: int = 1) -> None:
        with self._lock:
            self.skipped[reason] += n

    def drop(self, n: int) -> None:
        with self._lock:
            self.dropped += n

    def snapshot(self) -> dict:
        with self._lock:
            return {"topics": list(self.topics), "received": self.received, "converted": self.sent,
                    "skipped": sum(self.skipped.values()), "skipped_by_reason": dict(self.skipped),
                    "dropped_items": self.dropped, "placed_by": self.placed_by}
