"""One cap on long-lived streams (SSE, MJPEG, topic echo, teleop sockets), shared by all of them.

Each open stream holds a server thread for as long as it lasts. Kept below the production
server's thread count (gunicorn.conf.py), the cap leaves threads free for short requests, so a
dashboard with many tabs can never leave the e-stop's POST waiting for a thread.
"""

from __future__ import annotations

import threading


class TooManyStreams(Exception):
    def __init__(self, limit: int):
        super().__init__(f"{limit} streams are open already (ROVER_WEB_MAX_STREAMS); close a tab or a camera view")
        self.limit = limit


class StreamSlot:
    __slots__ = ("_limit", "_released", "kind")

    def __init__(self, limit: StreamLimit, kind: str):
        self._limit = limit
        self._released = False
        self.kind = kind

    def release(self) -> None:
        """Idempotent: a stream's several ways of ending may each call it."""
        self._limit._release(self)

    def __enter__(self) -> StreamSlot:
        return self

    def __exit__(self, *exc) -> None:
        self.release()


class StreamLimit:
    def __init__(self, limit: int):
        self.limit = limit
        self._open: dict[str, int] = {}
        self._count = 0
        self._lock = threading.Lock()

    def acquire(self, kind: str) -> StreamSlot:
        with self._lock:
            if self._count >= self.limit:
                raise TooManyStreams(self.limit)
            self._count += 1
            self._open[kind] = self._open.get(kind, 0) + 1
        return StreamSlot(self, kind)

    def _release(self, slot: StreamSlot) -> None:
        with self._lock:
            if slot._released:
                return
            slot._released = True
            self._count -= 1
            self._open[slot.kind] -= 1

    @property
    def count(self) -> int:
        return self._count

    def snapshot(self) -> dict:
        with self._lock:
            return {"open": self._count, "limit": self.limit, "by_kind": {k: v for k, v in self._open.items() if v}}
