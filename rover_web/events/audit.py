"""AuditHub: one place every operator action is announced, for whoever keeps a record of them.

Features call `record(...)` where an action happens (the e-stop, teleop control, panel commands,
waypoint and geofence edits, ROS admin calls, sign-ins); a recording in progress subscribes and
writes each record into its MCAP file on /rover_web/audit (rover_web/recording). Nothing is kept
here: with no subscriber, a record costs one dict. Pure Python: no Flask, no rclpy.

A record is shaped like foxglove.Event where it fits (timestamp, duration, metadata) plus `action`,
`by` and `detail`, so one file says what the robot saw and what the people did.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable
from typing import Any

log = logging.getLogger(__name__)

Listener = Callable[[dict], None]


class AuditHub:
    def __init__(self, robot: str = "robot"):
        self.robot = robot
        self._listeners: list[Listener] = []
        self._lock = threading.Lock()

    def subscribe(self, listener: Listener) -> Callable[[], None]:
        """Call `listener(record)` for every record from now on; returns the unsubscribe function.
        Listeners run on the thread of the action (a request, the executor): they must only queue."""
        with self._lock:
            self._listeners = [*self._listeners, listener]

        def unsubscribe() -> None:
            with self._lock:
                self._listeners = [fn for fn in self._listeners if fn is not listener]
        return unsubscribe

    def record(self, action: str, by: str = "", detail: str = "", **metadata: Any) -> dict:
        """Announce one action: `action` a dotted name ("estop.engage"), `by` who (user name or
        address), `detail` one human sentence, `metadata` small JSON-able facts."""
        now_ns = time.time_ns()
        record = {
            "timestamp": {"sec": now_ns // 1_000_000_000, "nsec": now_ns % 1_000_000_000},
            "duration": {"sec": 0, "nsec": 0},
            "action": action,
            "by": by,
            "robot": self.robot,
            "detail": detail,
            "metadata": {str(k): _text(v) for k, v in metadata.items() if v is not None},
        }
        for listener in self._listeners:  # a copy-on-write list: no lock held while calling out
            try:
                listener(record)
            except Exception:  # an audit listener must never break the action it reports
                log.exception("audit listener %r failed", listener)
        return record


def _text(value: Any) -> str:
    # foxglove.Event's metadata is string to string: keep it so a viewer can show it as is.
    text = value if isinstance(value, str) else repr(value) if not isinstance(value, (int, float, bool)) \
        else str(value).lower() if isinstance(value, bool) else str(value)
    return text[:500]
