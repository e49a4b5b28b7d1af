"""The one thread that repeats the held teleop command and enforces its deadlines."""

from __future__ import annotations

import logging
import threading

from .control import TeleopController

log = logging.getLogger(__name__)


class Repeater:
    """Sleeps on the controller's condition until the next tick or deadline, whichever is first;
    every input notifies it so it re-plans at once. Idle (nothing held), it waits without a timeout.
    While a held command ramps down (ramp.py), each tick publishes the ramped value, on the same grid.
    """

    def __init__(self, controller: TeleopController):
        self.controller = controller
        self._thread = threading.Thread(target=self._run, name="teleop-repeater", daemon=True)

    def start(self) -> Repeater:
        self._thread.start()
        return self

    def _run(self) -> None:
        c = self.controller
        with c._cond:
            while not c.closed:
                try:
                    wake_at = c.tick()
                except Exception:  # pragma: no cover - a bug; keep enforcing the deadman anyway
                    log.exception("teleop repeater tick failed")
                    wake_at = c._clock() + c.period_s
                timeout = None if wake_at is None else max(0.0, wake_at - c._clock())
                if timeout is None or timeout > 0:
                    c._cond.wait(timeout)

    def stop(self, timeout_s: float = 2.0) -> None:
        self.controller.close()
        if self._thread.is_alive():
            self._thread.join(timeout_s)

    @property
    def alive(self) -> bool:
        return self._thread.is_alive()
