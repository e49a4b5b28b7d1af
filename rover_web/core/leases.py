"""Shared resources that exist only while someone uses them. Pure Python.

A camera stream or a topic echo is a ROS subscription shared by every viewer of the same thing:
the first viewer creates it, the others reuse it, and it is closed `linger_s` after the last one
leaves (a page reload or a quick topic switch then does not tear down and rebuild it).

Users may be told apart (`client`): one client may then hold at most `share` different resources
at once, so a single client cannot take every subscription the cap allows (issue 27).
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable, Hashable
from typing import Generic, TypeVar

log = logging.getLogger(__name__)

T = TypeVar("T")


class Closed(RuntimeError):
    """The registry is shutting down: no new users."""


class Full(RuntimeError):
    """`max_keys` different resources are in use: a new one would pass the cap."""


class ShareUsed(Full):
    """This client holds its share of different resources already; others may still open more."""


class _Entry(Generic[T]):
    __slots__ = ("value", "users", "idle_since", "clients")

    def __init__(self, value: T):
        self.value = value
        self.users = 0
        self.idle_since: float | None = None
        self.clients: dict[Hashable, int] = {}  # client -> its users of this resource


class Leases(Generic[T]):
    """key -> resource, made by `open(key)` on first use and closed by `close(resource)` when idle."""

    def __init__(self, open: Callable[[Hashable], T], close: Callable[[T], None], linger_s: float,
                 clock: Callable[[], float] = time.monotonic, max_keys: int | None = None):
        self._open, self._close = open, close
        self.linger_s = linger_s
        self.max_keys = max_keys
        self._clock = clock
        self._entries: dict[Hashable, _Entry[T]] = {}
        self._cond = threading.Condition()
        self._closed = False
        self._reaper: threading.Thread | None = None

    def acquire(self, key: Hashable, client: Hashable | None = None, share: int | None = None) -> T:
        """The resource for `key`, opened now if nobody holds it; exceptions from open propagate.
        Full when `max_keys` resources are all in use; ShareUsed when `client` already holds
        `share` other resources (release it with the same client)."""
        evicted = None
        try:
            with self._cond:
                if self._closed:
                    raise Closed("shutting down")
                entry = self._entries.get(key)
                if client is not None and share is not None and (entry is None or client not in entry.clients):
                    held = sum(1 for e in self._entries.values() if client in e.clients)
                    if held >= share:
                        raise ShareUsed(f"this client holds {held} already")
                if entry is None:
                    evicted = self._make_room()
                    # Opened under the lock so two first viewers cannot both create a subscription.
                    entry = self._entries[key] = _Entry(self._open(key))
                entry.users += 1
                entry.idle_since = None
                if client is not None:
                    entry.clients[client] = entry.clients.get(client, 0) + 1
                return entry.value
        finally:
            if evicted is not None:  # closed outside the lock, and even when opening the new one failed
                self._safe_close(*evicted)

    def _make_room(self) -> tuple[Hashable, T] | None:
        """At the cap, the longest-idle resource goes now rather than after its linger: a lingering
        one only saves a re-subscription, while a refused viewer gets nothing. Called locked."""
        if self.max_keys is None or len(self._entries) < self.max_keys:
            return None
        idle = [(e.idle_since, k) for k, e in self._entries.items() if e.users == 0 and e.idle_since is not None]
        if not idle:
            raise Full(f"{len(self._entries)} in use already")
        _, key = min(idle, key=lambda pair: pair[0])
        return key, self._entries.pop(key).value

    def release(self, key: Hashable, client: Hashable | None = None) -> None:
        with self._cond:
            entry = self._entries.get(key)
            if entry is None or entry.users <= 0:
                return
            entry.users -= 1
            if client is not None and client in entry.clients:
                entry.clients[client] -= 1
                if not entry.clients[client]:
                    del entry.clients[client]
            if entry.users == 0:
                entry.idle_since = self._clock()
                self._cond.notify_all()  # the reaper learns of a new deadline

    def reap(self, now: float | None = None) -> list[Hashable]:
        """Close what has been idle for linger_s; returns the keys closed."""
        now = self._clock() if now is None else now
        with self._cond:
            expired = [(k, e) for k, e in self._entries.items()
                       if e.users == 0 and e.idle_since is not None and now - e.idle_since >= self.linger_s]
            for key, _ in expired:
                del self._entries[key]
        for key, entry in expired:
            self._safe_close(key, entry.value)
        return [key for key, _ in expired]

    def _next_deadline(self) -> float | None:
        deadlines = [e.idle_since + self.linger_s for e in self._entries.values()
                     if e.users == 0 and e.idle_since is not None]
        return min(deadlines) if deadlines else None

    def start_reaper(self, name: str = "leases-reaper") -> threading.Thread:
        """A daemon thread that closes idle resources on time; it ends with close_all()."""
        def run() -> None:
            while True:
                with self._cond:
                    if self._closed:
                        return
                    deadline = self._next_deadline()
                    timeout = None if deadline is None else max(0.0, deadline - self._clock())
                    if timeout is None or timeout > 0:
                        self._cond.wait(timeout)
                    if self._closed:
                        return
                self.reap()

        self._reaper = threading.Thread(target=run, name=name, daemon=True)
        self._reaper.start()
        return self._reaper

    def close_all(self, join_timeout_s: float = 1.0) -> None:
        """Shutdown: refuse new users, close everything, stop the reaper."""
        with self._cond:
            self._closed = True
            entries, self._entries = list(self._entries.items()), {}
            self._cond.notify_all()
        for key, entry in entries:
            self._safe_close(key, entry.value)
        if self._reaper is not None and self._reaper is not threading.current_thread():
            self._reaper.join(join_timeout_s)

    def _safe_close(self, key: Hashable, value: T) -> None:
        try:
            self._close(value)
        except Exception:
            log.exception("closing %r failed", key)

    # --- inspection ---

    def items(self) -> list[tuple[Hashable, T, int]]:
        with self._cond:
            return [(k, e.value, e.users) for k, e in self._entries.items()]

    def users(self, key: Hashable) -> int:
        with self._cond:
            entry = self._entries.get(key)
            return 0 if entry is None else entry.users

    def __contains__(self, key: Hashable) -> bool:
        with self._cond:
            return key in self._entries

    def __len__(self) -> int:
        with self._cond:
            return len(self._entries)
