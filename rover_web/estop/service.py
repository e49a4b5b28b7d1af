"""The e-stop: one latch that stops everything the GUI can start.

Engaging stops the robot before anything else, without waiting on a lock that I/O holds: zero
velocity goes out, `/e_stop` says true, every navigation action is asked to cancel its goals, and
every feature's engage hook runs (teleop drops its drivers, panels send their `on_estop` command
and then log it). The latch is written to disk after that. While engaged, zero velocity goes out at the teleop rate
and every request that would publish motion is refused (`check_motion`).

Releasing is written to disk first, and only then allowed: if an engage arrives while that write
is under way, the release is abandoned and the e-stop stays engaged.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable

from rover_web.web.api_messages import explain

from .store import EStopStore

log = logging.getLogger(__name__)

CHANNEL = "estop"


class EStopEngaged(Exception):
    """A request that would move the robot while the e-stop is engaged."""

    def __init__(self, state: dict):
        if state.get("by"):
            super().__init__(explain("the e-stop is engaged by %(name)s: release it before sending motion",
                                     name=state["by"]))
        else:
            super().__init__(explain("the e-stop is engaged: release it before sending motion"))
        self.state = state


class ReleaseRefused(Exception):
    """The release could not be made safe (not recorded, or engaged again meanwhile)."""

    def __init__(self, code: str, message: str, status: int):
        super().__init__(message)
        self.code, self.status = code, status


class EStopService:
    def __init__(self, store: EStopStore, *, zero: Callable[[], None], publish_flag: Callable[[bool], None],
                 canceller=None,
                 on_change: Callable[[dict], None], clock: Callable[[], float] = time.time,
                 hold: Callable[[], None] | None = None, unhold: Callable[[], None] | None = None):
        self._store = store
        self._zero = zero
        # The velocity output's hold (rover_web/ros/cmd_vel.py): from the engage's zero to the
        # release, whatever else would publish goes out as zero, teleop not yet told included.
        self._hold = hold or zero
        self._unhold = unhold
        self._publish_flag = publish_flag
        self._canceller = canceller  # has cancel_all(on_done) and running() (rover_web.ros.actions)
        self._on_change = on_change
        self._clock = clock
        loaded = store.load()
        self._engaged = bool(loaded["engaged"])
        self.engaged_event = threading.Event()  # set while engaged: gates the zero-velocity loop
        if self._engaged:
            self.engaged_event.set()
            self._hold()  # engaged since the last run
        self._state = {**loaded, "via": None, "persisted": True, "cancel": None}
        self._epoch = 0  # +1 per engage, so a release can tell that one came while it wrote
        self._lock = threading.Lock()  # guards the state in memory; never held across I/O
        self._release_lock = threading.Lock()  # one release at a time (engaging never takes it)
        self._engage_hooks: list[Callable[[str], None]] = []
        self._release_hooks: list[Callable[[str], None]] = []

    # --- for other features ---

    @property
    def engaged(self) -> bool:
        return self._engaged

    def check_motion(self) -> None:
        """Raise EStopEngaged if motion may not be published now."""
        if self._engaged:
            raise EStopEngaged(self.state())

    def on_engage(self, hook: Callable[[str], None]) -> None:
        """hook(by) runs right after every engage, after zero velocity went out."""
        self._engage_hooks.append(hook)

    def on_release(self, hook: Callable[[str], None]) -> None:
        self._release_hooks.append(hook)

    def state(self) -> dict:
        with self._lock:
            return dict(self._state)

    def cancellable_actions(self) -> list[str]:
        """Navigation actions with a server right now: an engage would cancel their goals."""
        return self._canceller.running() if self._canceller is not None else []

    # --- engage and release ---

    def engage(self, by: str, via: str = "api") -> dict:
        with self._lock:
            first = not self._engaged
            self._engaged = True
            self.engaged_event.set()
            self._epoch += 1
            if first:
                self._state = {"engaged": True, "since": self._clock(), "by": by, "via": via, "persisted": None,
                               "cancel": None}
            state = dict(self._state)
        self._stop_everything(by, first=first)
        if not first:
            return self.state()
        log.warning("e-stop engaged by %s (%s)", by, via)
        persisted = self._persist(state)
        with self._lock:
            if self._state.get("since") == state["since"]:
                self._state["persisted"] = persisted
            state = dict(self._state)
        self._on_change(state)
        return state

    def release(self, by: str) -> dict:
        with self._release_lock:
            with self._lock:
                if not self._engaged:
                    return dict(self._state)
                epoch = self._epoch
            released = {"engaged": False, "since": self._clock(), "by": by}
            try:
                self._store.save(released)
            except Exception:
                log.exception("could not record the e-stop release")
                raise ReleaseRefused("estop_not_recorded", explain("the release could not be written to the "
                                                                   "database; the e-stop stays engaged"), 503) from None
            with self._lock:
                if self._epoch != epoch:  # engaged again while the release was written
                    again = dict(self._state)
                else:
                    self._engaged = False
                    self.engaged_event.clear()
                    if self._unhold is not None:  # under the lock: an engage from now on holds again
                        self._unhold()
                    self._state = {**released, "via": None, "persisted": True, "cancel": None}
                    again = None
            if again is not None:
                self._persist(again)  # the disk must not keep the abandoned release
                raise ReleaseRefused("estop_engaged", explain("the e-stop was engaged again while releasing"), 409)
        log.warning("e-stop released by %s", by)
        for hook in self._release_hooks:
            self._run_hook(hook, by)
        self._publish_flag_safely(False)
        state = self.state()
        self._on_change(state)
        return state

    # --- while engaged ---

    def hold(self) -> None:
        """Called at the teleop rate: zero velocity keeps going out while engaged."""
        if self._engaged:
            self._zero()

    def republish(self) -> None:
        """Called every ROVER_WEB_ESTOP_REPEAT_S: a safety node that missed a change learns it."""
        self._publish_flag_safely(self._engaged)

    # --- internals ---

    def _stop_everything(self, by: str, first: bool) -> None:
        # What needs no disk first; hooks last, since one may write a log entry. Pressed again
        # while engaged, zero and the flag go out again, and nothing else: the hooks (a panel's
        # Stop, its log line on disk) already ran, and a held or repeated press must stay fast.
        try:
            self._hold()
        except Exception:
            log.exception("e-stop: zero velocity could not be published")
        self._publish_flag_safely(True)
        if not first:
            return
        if self._canceller is not None:
            self._canceller.cancel_all(self._goals_canceled)
        for hook in self._engage_hooks:
            self._run_hook(hook, by)

    def _persist(self, state: dict) -> bool:
        try:
            self._store.save(state)
            return True
        except Exception:
            log.exception("e-stop engaged but not recorded on disk")
            return False

    def _goals_canceled(self, outcomes: list[dict]) -> None:
        with self._lock:
            if not self._engaged:
                return
            self._state["cancel"] = outcomes
            state = dict(self._state)
        for outcome in outcomes:
            if outcome["result"] not in ("not_running", "no_goals"):
                log.warning("e-stop: cancel of %s: %s", outcome["action"], outcome["result"])
        self._on_change(state)

    def _publish_flag_safely(self, engaged: bool) -> None:
        try:
            self._publish_flag(engaged)
        except Exception:
            log.exception("e-stop: %s could not be published", "true" if engaged else "false")

    @staticmethod
    def _run_hook(hook: Callable[[str], None], by: str) -> None:
        try:
            hook(by)
        except Exception:
            log.exception("e-stop hook %r failed", hook)
