"""Background loops that stop with the app: `every(period_s, fn)` instead of hand-written threads.

A loop calls `fn` every `period_s` until its stop event is set; an exception is logged and the
loop goes on (a heartbeat or a watchdog must outlive a bug). The owner joins it at shutdown.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable

log = logging.getLogger(__name__)

# A gated loop whose gate is closed checks for shutdown this often (and not at its own rate).
GATE_CHECK_S = 1.0


class Loop:
    def __init__(self, name: str, period_s: float, fn: Callable[[], object], stopping: threading.Event, *,
                 immediately: bool = False, only_while: threading.Event | None = None):
        if not period_s > 0:
            raise ValueError(f"loop {name!r}: period_s must be positive, got {period_s!r}")
        self.name = name
        self.period_s = period_s
        self._fn = fn
        self._stopping = stopping
        self._immediately = immediately
        self._gate = only_while
        self._thread = threading.Thread(target=self._run, name=name, daemon=True)

    def start(self) -> Loop:
        self._thread.start()
        return self

    def _run(self) -> None:
        if self._immediately:
            self._call()
        while not self._stopping.is_set():
            if self._gate is not None and not self._gate.is_set():
                self._gate.wait(GATE_CHECK_S)  # asleep while there is nothing to do; opens at once
                continue
            if self._stopping.wait(self.period_s):
                return
            self._call()

    def _call(self) -> None:
        try:
            self._fn()
        except Exception:
            if not self._stopping.is_set():  # errors while the app stops are expected, not news
                log.exception("background loop %r failed; it keeps running", self.name)

    def join(self, timeout_s: float | None = None) -> bool:
        """True once the thread has ended (call after setting the stop event)."""
        if self._gate is not None and self._stopping.is_set():
            # A gated loop asleep on its closed gate would see the stop only at its next gate
            # check, a second away: every app's shutdown took a second. Opened now, it wakes,
            # finds the stop set and ends without calling fn. Its gate is read by nothing else.
            self._gate.set()
        if self._thread.ident is not None:
            self._thread.join(timeout_s)
        return not self._thread.is_alive()

    @property
    def alive(self) -> bool:
        return self._thread.is_alive()


def every(period_s: float, fn: Callable[[], object], *, name: str, stopping: threading.Event,
          immediately: bool = False, only_while: threading.Event | None = None) -> Loop:
    """Start a loop that calls `fn` every `period_s` (first right away with `immediately`); with
    `only_while`, only while that event is set (a 40 Hz job that is idle most of the day). The
    event is the loop's alone: the loop's join at shutdown sets it, to wake the loop."""
    return Loop(name, period_s, fn, stopping, immediately=immediately, only_while=only_while).start()
