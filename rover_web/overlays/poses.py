"""The robot's recent map poses: where it was when a scan was taken, and its recent path. Pure.

There is no TF in rover_web. A sensor message says when it was measured (its header stamp), and
the robot's map pose (AMCL's, `ROVER_WEB_AMCL_POSE_TOPIC`) is kept for the last minute with its
stamps; the pose at a stamp is interpolated between the two samples around it. AMCL publishes
only when the robot moves, so a stamp after the newest sample takes the newest (the robot stood
still), and a stamp long before the oldest finds nothing.
"""

from __future__ import annotations

import bisect
import math
import threading
from collections import deque

PATH_MIN_STEP_M = 0.05  # a path sample closer than this to the last one adds nothing visible


def _lerp_angle(a: float, b: float, t: float) -> float:
    return a + t * math.atan2(math.sin(b - a), math.cos(b - a))


class PoseHistory:
    def __init__(self, keep_s: float = 60.0, max_samples: int = 4096, before_oldest_s: float = 1.0):
        self.keep_s = keep_s
        self.before_oldest_s = before_oldest_s
        self._stamps: deque[float] = deque(maxlen=max_samples)
        self._poses: deque[tuple[float, float, float]] = deque(maxlen=max_samples)
        self._path: deque[tuple[float, float, float]] = deque(maxlen=max_samples)  # (stamp, x, y)
        self._lock = threading.Lock()

    def add(self, stamp: float, x: float, y: float, yaw: float) -> None:
        with self._lock:
            if self._stamps and stamp < self._stamps[-1]:
                # Time went back (a bag replayed, a sim restarted): the old samples belong to another run.
                self._stamps.clear()
                self._poses.clear()
                self._path.clear()
            self._stamps.append(stamp)
            self._poses.append((x, y, yaw))
            while self._stamps and self._stamps[0] < stamp - self.keep_s:
                self._stamps.popleft()
                self._poses.popleft()
            if not self._path or math.hypot(x - self._path[-1][1], y - self._path[-1][2]) >= PATH_MIN_STEP_M:
                self._path.append((stamp, x, y))
            while self._path and self._path[0][0] < stamp - self.keep_s:
                self._path.popleft()

    def latest(self) -> tuple[float, float, float] | None:
        with self._lock:
            return self._poses[-1] if self._poses else None

    def at(self, stamp: float) -> tuple[float, float, float] | None:
        """The map pose at `stamp` (0: unstamped, the newest), or None when none is known then."""
        with self._lock:
            if not self._stamps:
                return None
            if stamp <= 0 or stamp >= self._stamps[-1]:
                return self._poses[-1]
            i = bisect.bisect_left(self._stamps, stamp)
            if i == 0:
                return self._poses[0] if self._stamps[0] - stamp <= self.before_oldest_s else None
            t0, t1 = self._stamps[i - 1], self._stamps[i]
            a, b = self._poses[i - 1], self._poses[i]
        t = 0.0 if t1 == t0 else (stamp - t0) / (t1 - t0)
        return (a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), _lerp_angle(a[2], b[2], t))

    def path(self) -> list[list[float]]:
        """The recent path [[x, y], ...], oldest first, one point per 5 cm moved."""
        with self._lock:
            return [[round(x, 3), round(y, 3)] for _, x, y in self._path]
