"""One cap on long-lived streams (SSE, MJPEG, topic echo, teleop sockets), shared by all of them.

Each open stream holds a server thread for as long as it lasts. Kept below the production
server's thread count (gunicorn.conf.py), the cap leaves threads free for short requests, so a
dashboard with many tabs can never leave the e-stop's POST waiting for a thread.

One client (a user, or an address with sign-in off) may hold only its share of the cap, and the
last `reserved` slots are kept for teleop sockets and operators: a client that opens streams
without end can no longer leave the operator's Drive card with a 503 (issue 27).
"""

from __future__ import annotations

import threading

from rover_web.web.api_messages import explain


class TooManyStreams(Exception):
    def __init__(self, limit: int, message: str | None = None):
        super().__init__(message or explain("%(limit)s streams are open already (ROVER_WEB_MAX_STREAMS); "
                                            "close a tab or a camera view", limit=limit))
        self.limit = limit


class StreamSlot:
    __slots__ = ("_limit", "_released", "kind", "client", "common")

    def __init__(self, limit: StreamLimit, kind: str, client: str | None = None, common: bool = False):
        self._limit = limit
        self._released = False
        self.kind = kind
        self.client = client
        self.common = common  # taken by a caller the reserve is not for

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
        self._by_client: dict[str, int] = {}
        self._common = 0  # slots held by callers the reserve is not for
        self._lock = threading.Lock()

    def acquire(self, kind: str, client: str | None = None, per_client: int | None = None,
                reserved: int = 0, may_reserve: bool = True) -> StreamSlot:
        """A slot, or TooManyStreams. `client` holds at most `per_client` slots (None: no share).
        Callers that may not `may_reserve` (all but teleop and operators) hold at most the cap less
        `reserved` slots between them, so that many are always left for driving. A reserve as large
        as the cap would leave the others nothing: one slot always stays theirs."""
        with self._lock:
            if self._count >= self.limit:
                raise TooManyStreams(self.limit)
            held = self._by_client.get(client, 0) if client is not None else 0
            if per_client is not None and client is not None and held >= per_client:
                raise TooManyStreams(self.limit, explain("this client holds %(held)s streams already, its share "
                                                         "(ROVER_WEB_MAX_STREAMS_PER_CLIENT); close a tab or a "
                                                         "camera view",
                                                         held=held))
            kept = min(reserved, self.limit - 1)
            if not may_reserve and self._common >= self.limit - kept:
                raise TooManyStreams(self.limit, explain("%(common)s streams are open; %(kept)s more are kept for "
                                                         "driving (ROVER_WEB_STREAMS_RESERVED); close a tab or a "
                                                         "camera view",
                                                         common=self._common, kept=kept))
            self._count += 1
            self._common += not may_reserve
            self._open[kind] = self._open.get(kind, 0) + 1
            if client is not None:
                self._by_client[client] = held + 1
        return StreamSlot(self, kind, client, common=not may_reserve)

    def held_by(self, client: str) -> int:
        with self._lock:
            return self._by_client.get(client, 0)

    def _release(self, slot: StreamSlot) -> None:
        with self._lock:
            if slot._released:
                return
            slot._released = True
            self._count -= 1
            self._common -= slot.common
            self._open[slot.kind] -= 1
            if slot.client is not None:
                left = self._by_client[slot.client] - 1
                if left:
                    self._by_client[slot.client] = left
                else:
                    del self._by_client[slot.client]

    @property
    def count(self) -> int:
        return self._count

    def snapshot(self) -> dict:
        with self._lock:
            return {"open": self._count, "limit": self.limit, "by_kind": {k: v for k, v in self._open.items() if v}}
