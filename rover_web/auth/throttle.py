"""What one sign-in attempt may cost, and who may try again when. Pure Python, monotonic clock.

- `HashGate`: at most `limit` password hashes at once in the whole process, run on `limit`
  threads of its own. Each Argon2 hash holds its memory cost (19 MiB by default) for tens of
  milliseconds; eight parallel attempts at 64 MiB took a server from 109 to 633 MB (issue 27).
  Beyond the limit a sign-in is answered 503 at once, before any hash is computed. Why threads
  of its own: glibc's malloc keeps a freed block under 32 MiB in the arena of the thread that
  freed it, and `flask run` serves each request on a new thread, so hashes run on request
  threads left 19 MiB behind in up to 8 arenas per core; on `limit` fixed threads, at most `limit`.
- `SignInThrottle`: per client address, at most `attempts_per_min` attempts across all names (a
  sliding minute, `core/rate_limit.py`), and exponential back-off on failures, counted per address
  and per (name, address). A hard lock per name let anyone lock a user out with five wrong
  passwords (issue 27); keyed by address, the guesser waits and the user, from their own address,
  still signs in.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from contextlib import contextmanager
from typing import TypeVar

from rover_web.core.rate_limit import RateLimit
from rover_web.web.api_messages import Text, explain

MAX_TRACKED_KEYS = 10_000  # addresses and names are attacker-chosen: the tables must not grow without bound
FREE_FAILURES_PER_ADDRESS = 10  # failures (any names) from one address before it waits at all
FREE_FAILURES_PER_NAME = 5  # failures for one name from one address before that pair waits
FIRST_DELAY_S = 1.0  # the first wait; each further failure doubles it ...
MAX_DELAY_S = 900.0  # ... up to 15 minutes
FORGET_AFTER_S = 3600.0  # failures older than this (with none since) are forgotten

T = TypeVar("T")


class HashingBusy(RuntimeError):
    """Every hashing slot is taken: the caller answers 503 at once, without hashing."""


class HashGate:
    """A bounded number of concurrent password hashes (a non-blocking semaphore), with counters the
    status and the tests read: how many are running now, the most ever at once, and how many ran."""

    def __init__(self, limit: int):
        self.limit = limit
        self._slots = threading.BoundedSemaphore(limit)
        # Never more than `limit` tasks in it (the semaphore is taken first): no queue forms.
        self._pool = ThreadPoolExecutor(max_workers=limit, thread_name_prefix="argon2")
        self._lock = threading.Lock()
        self.active = 0
        self.peak = 0
        self.hashed = 0
        self.refused = 0

    @contextmanager
    def slot(self, wait: bool = False):
        """Hold one hashing slot; HashingBusy at once when none is free (unless `wait`)."""
        if not self._slots.acquire(blocking=wait):
            with self._lock:
                self.refused += 1
            raise HashingBusy(explain("%(limit)s sign-ins are being checked already", limit=self.limit))
        with self._lock:
            self.active += 1
            self.peak = max(self.peak, self.active)
        try:
            yield
        finally:
            with self._lock:
                self.active -= 1
                self.hashed += 1
            self._slots.release()

    def run(self, fn: Callable[..., T], *args, wait: bool = False) -> T:
        """fn(*args) on one of the gate's threads, in a slot; HashingBusy at once when none is free."""
        with self.slot(wait):
            return self._pool.submit(fn, *args).result()

    def close(self) -> None:
        self._pool.shutdown(wait=False)


class _Backoff:
    """Failures per key; after `free` of them, each key waits FIRST_DELAY_S doubled per further
    failure (capped), counted from its last failure."""

    def __init__(self, free: int, clock: Callable[[], float]):
        self.free = free
        self._clock = clock
        self._failures: dict[object, tuple[int, float]] = {}  # key -> (count, time of the last)

    def wait_s(self, key: object, now: float) -> float:
        entry = self._failures.get(key)
        if entry is None:
            return 0.0
        count, last = entry
        if now - last >= FORGET_AFTER_S:
            del self._failures[key]
            return 0.0
        if count < self.free:
            return 0.0
        delay = min(MAX_DELAY_S, FIRST_DELAY_S * 2.0 ** min(count - self.free, 30))
        return max(0.0, last + delay - now)

    def failed(self, key: object, now: float) -> None:
        if key not in self._failures and len(self._failures) >= MAX_TRACKED_KEYS:
            self._prune(now)
        count, last = self._failures.get(key, (0, now))
        if now - last >= FORGET_AFTER_S:
            count = 0
        self._failures[key] = (count + 1, now)

    def clear(self, key: object) -> None:
        self._failures.pop(key, None)

    def __len__(self) -> int:
        return len(self._failures)

    def _prune(self, now: float) -> None:
        for key in [k for k, (_, last) in self._failures.items() if now - last >= FORGET_AFTER_S]:
            del self._failures[key]
        if len(self._failures) >= MAX_TRACKED_KEYS:  # all recent: forget the oldest half
            oldest = sorted(self._failures, key=lambda k: self._failures[k][1])
            for key in oldest[: len(oldest) // 2]:
                del self._failures[key]


class SignInThrottle:
    def __init__(self, attempts_per_min: int = 20, clock: Callable[[], float] = time.monotonic):
        self._clock = clock
        self._attempts = RateLimit(attempts_per_min, 60.0, clock=clock)
        self._by_address = _Backoff(FREE_FAILURES_PER_ADDRESS, clock)
        self._by_name = _Backoff(FREE_FAILURES_PER_NAME, clock)
        self._lock = threading.Lock()

    def admit(self, name: str, address: str) -> tuple[float, Text | str]:
        """(0, "") and the attempt is counted, or (seconds to wait, why) and nothing is counted."""
        now = self._clock()
        with self._lock:
            wait = self._by_address.wait_s(address, now)
            if wait > 0:
                return wait, explain("too many failed sign-ins from this address")
            wait = self._by_name.wait_s((name, address), now)
            if wait > 0:
                return wait, explain("too many failed sign-ins for %(name)s from this address", name=repr(name))
        wait = self._attempts.hit(address)
        if wait > 0:
            return wait, explain("too many sign-in attempts from this address")
        return 0.0, ""

    def failed(self, name: str, address: str) -> None:
        now = self._clock()
        with self._lock:
            self._by_address.failed(address, now)
            self._by_name.failed((name, address), now)

    def succeeded(self, name: str, address: str) -> None:
        """The pair's failures are cleared; the address's are not (signing in as yourself between
        guesses at others' passwords must not reset the guessing)."""
        with self._lock:
            self._by_name.clear((name, address))
