"""The robot's GPS fix and its recent track, as the map shows them. Pure Python.

A NavSatFix with no satellite lock (status < 0) or with a non-finite or impossible position is
"no fix": shown as such, never plotted (a receiver without lock often reports 0, 0, which is
in the Gulf of Guinea). The track is bounded and only grows when the robot has moved, so a
robot parked for an hour does not push its route out of the track.
"""

from __future__ import annotations

import math
import threading
from collections import deque
from dataclasses import dataclass

from rover_web.i18n import N_
from rover_web.web.api_messages import Text, said, with_wire

EARTH_RADIUS_M = 6371008.8
STATUS_NO_FIX = -1  # sensor_msgs/NavSatStatus.STATUS_NO_FIX
STATUS_NAMES = {-1: N_("no fix"), 0: N_("fix"), 1: N_("SBAS fix"), 2: N_("GBAS fix")}  # message ids: pages translate
# A word per NavSatStatus the page styles by: unaugmented, satellite-based augmentation (WAAS,
# EGNOS), ground-based augmentation (DGPS, RTK).
QUALITY = {-1: "none", 0: "fix", 1: "sbas", 2: "gbas"}


@dataclass(frozen=True)
class FixReading:
    """One NavSatFix, as plain numbers (see msgs.fix_reading)."""

    status: int
    lat: float
    lng: float
    alt: float
    horizontal_sigma_m: float | None = None  # from position_covariance when it is known
    frame_id: str = ""  # the antenna's frame (mounts.py places the robot's centre from it through TF)


def distance_m(lng1: float, lat1: float, lng2: float, lat2: float) -> float:
    """Equirectangular approximation: exact enough for the metres between two track points."""
    x = math.radians(lng2 - lng1) * math.cos(math.radians((lat1 + lat2) / 2))
    y = math.radians(lat2 - lat1)
    return EARTH_RADIUS_M * math.hypot(x, y)


def no_fix_reason(reading: FixReading) -> Text | None:
    if reading.status < 0:
        return said("no satellite lock")
    if not (math.isfinite(reading.lat) and math.isfinite(reading.lng)):
        return said("position is not a finite number")
    if not (-90.0 <= reading.lat <= 90.0 and -180.0 <= reading.lng <= 180.0):
        return said("position is outside the valid latitude/longitude range")
    return None


def _finite_or_none(value: float | None, digits: int) -> float | None:
    return round(value, digits) if value is not None and math.isfinite(value) else None


class GpsTrack:
    """Latest fix plus a bounded track of [lng, lat] points; thread-safe."""

    def __init__(self, max_points: int = 500, min_step_m: float = 0.5):
        self.min_step_m = min_step_m
        self._track: deque[tuple[float, float]] = deque(maxlen=max_points)
        self._state: dict | None = None
        self._lock = threading.Lock()

    def update(self, reading: FixReading) -> dict:
        """Take one reading; returns the JSON-ready state for the `fix` channel."""
        reason = no_fix_reason(reading)
        with self._lock:
            if reason is None:
                point = (round(reading.lng, 8), round(reading.lat, 8))
                if not self._track or distance_m(*self._track[-1], *point) >= self.min_step_m:
                    self._track.append(point)
            fix = reason is None
            self._state = with_wire({
                "fix": fix,
                "reason": reason,
                "status": reading.status,
                "status_text": STATUS_NAMES.get(reading.status, f"status {reading.status}"),
                "quality": QUALITY.get(reading.status, "none" if reading.status < 0 else "fix") if fix else "none",
                "lng": round(reading.lng, 8) if fix else None,
                "lat": round(reading.lat, 8) if fix else None,
                "alt": _finite_or_none(reading.alt, 2) if fix else None,
                "accuracy_m": _finite_or_none(reading.horizontal_sigma_m, 2) if fix else None,
                "track": [list(p) for p in self._track],
            })
            return self._state

    def state(self) -> dict | None:
        with self._lock:
            return self._state
