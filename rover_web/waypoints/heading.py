"""The robot's heading on the GPS map, from an orientation in an ENU-aligned frame. Pure Python.

REP 103 and 105: yaw 0 is east and grows counter-clockwise, as robot_localization's
navsat_transform expects of its IMU. A compass bearing (0 north, clockwise) is what a map shows,
so bearing = 90 - yaw in degrees, after the configured offset (for an odometry frame whose x axis
is not east, or a magnetometer's declination). Stale after a set time: an arrow that stopped
turning because its topic died would lie.
"""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Callable


def bearing_deg(yaw_rad: float, offset_deg: float = 0.0) -> float:
    """Compass bearing in [0, 360) of an ENU yaw (radians, counter-clockwise from east)."""
    return round((90.0 - math.degrees(yaw_rad) - offset_deg) % 360.0, 1) % 360.0


def yaw_of_quaternion(x: float, y: float, z: float, w: float) -> float | None:
    """Yaw (radians) of an orientation, None for one that is not a rotation (all zero, NaN)."""
    values = (x, y, z, w)
    if not all(math.isfinite(v) for v in values):
        return None
    norm = math.sqrt(sum(v * v for v in values))
    if norm < 1e-6:
        return None
    x, y, z, w = (v / norm for v in values)
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


class Heading:
    """The latest heading and when it came (monotonic clock), thread-safe."""

    def __init__(self, topic: str, offset_deg: float, stale_after_s: float,
                 clock: Callable[[], float] = time.monotonic):
        self.topic = topic
        self.offset_deg = offset_deg
        self.stale_after_s = stale_after_s
        self.skipped = 0  # messages with no usable orientation
        self._clock = clock
        self._lock = threading.Lock()
        self._state: dict | None = None
        self._at = 0.0

    def update(self, yaw_rad: float | None) -> dict | None:
        """Take one yaw; returns the `heading` channel's payload, or None when it was skipped."""
        if yaw_rad is None:
            with self._lock:
                self.skipped += 1
            return None
        state = {"heading_deg": bearing_deg(yaw_rad, self.offset_deg), "yaw_rad": round(yaw_rad, 6),
                 "topic": self.topic, "stale": False}
        with self._lock:
            self._state, self._at = state, self._clock()
        return state

    def went_stale(self) -> dict | None:
        """The payload to announce once when the heading has just gone stale, else None."""
        with self._lock:
            if self._state is None or self._state["stale"] or self._clock() - self._at < self.stale_after_s:
                return None
            self._state = {**self._state, "stale": True}
            return self._state

    def state(self) -> dict | None:
        with self._lock:
            return self._state
