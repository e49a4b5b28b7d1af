"""Placing a message's geometry in the map frame: through TF when TF knows its frame, else the
configured fallback. Pure (no rclpy, no Flask); shared by the overlays, LiveMap and the GPS map.

What tf2's MessageFilter would do, without holding messages back: a message is placed with the
transform map <- its frame at its own stamp (interpolated by the buffer). A stamp newer than the
newest transform by at most FUTURE_TOLERANCE_S (the scan came before the TF of the same instant,
or a float stamp rounded a few hundred nanoseconds) takes the newest transform instead of waiting
for the next one, as a MessageFilter would: a queued scan would be a late scan. Beyond that, and
for a stamp older than the buffer's cache, the message is skipped and counted with tf2's reason
(`tf_extrapolation_future`, `tf_extrapolation_past`). A stamp of 0 means "the latest" (tf2's Time(0)).

The fallback (configured offsets, AMCL's pose, map -> odom rebuilt from two poses) is used only
when TF has not heard of the message's frame or of the map frame at all (`unknown_frame`,
`not_connected` before any tree joins them): a robot that publishes no TF is drawn as before, and a
robot that does is never drawn from guesses. Every placement says which it was: "tf",
"configured" or "map" (already in the map frame), so a page can show it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np

FUTURE_TOLERANCE_S = 0.25
FALLBACK_KINDS = ("unknown_frame", "not_connected")

TF, CONFIGURED, MAP = "tf", "configured", "map"


class Unplaceable(ValueError):
    """TF knows the frame but cannot place this message (its stamp); the message is the reason counted."""


class Placement(Protocol):
    """map <- a frame: what a TF Transform offers (apply, apply_many, yaw), also made from a 2D pose."""

    def apply(self, x: float, y: float, z: float = 0.0) -> tuple[float, float, float]: ...

    def apply_many(self, xs, ys, zs=None): ...


@dataclass(frozen=True)
class Planar:
    """A 2D pose (x, y, yaw) as a placement: the fallback's, made from AMCL's pose and offsets."""

    x: float
    y: float
    yaw: float

    def apply(self, x: float, y: float, z: float = 0.0) -> tuple[float, float, float]:
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        return self.x + c * x - s * y, self.y + s * x + c * y, z

    def apply_many(self, xs, ys, zs=None):
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        xs, ys = np.asarray(xs, dtype=np.float64), np.asarray(ys, dtype=np.float64)
        return self.x + c * xs - s * ys, self.y + s * xs + c * ys, np.zeros_like(xs) if zs is None else zs


    def compose_2d(self, pose: tuple[float, float, float]) -> Planar:
        """self ∘ pose: a pose given in this frame (a laser's configured offset on the robot)."""
        x, y, _ = self.apply(pose[0], pose[1])
        yaw = self.yaw + pose[2]
        return Planar(x, y, math.atan2(math.sin(yaw), math.cos(yaw)))


IDENTITY = Planar(0.0, 0.0, 0.0)


def heading(placement: Placement, x: float, y: float, yaw: float) -> tuple[float, float, float]:
    """A pose (x, y, yaw) in the placement's frame, in the map plane: its position placed and its
    heading the direction its x axis points to there (right for any frame, tilted or upside down)."""
    px, py, _ = placement.apply(x, y, 0.0)
    ax, ay, _ = placement.apply(x + math.cos(yaw), y + math.sin(yaw), 0.0)
    return px, py, math.atan2(ay - py, ax - px)


def stamp_ns(stamp_s: float) -> int:
    return int(round(stamp_s * 1e9)) if math.isfinite(stamp_s) and stamp_s > 0 else 0


class MapPlacer:
    """Looks up map <- frame in a TF buffer (None: no TF in this app); one lookup per message or tick."""

    def __init__(self, buffer: Any | None, map_frame: str = "map", future_tolerance_s: float = FUTURE_TOLERANCE_S):
        self.buffer = buffer
        self.map_frame = map_frame
        self.future_tolerance_s = future_tolerance_s

    def lookup(self, frame: str, stamp_s: float = 0.0) -> Placement | None:
        """map <- frame at stamp_s (0: latest); None when TF does not know the frame (use the fallback);
        Unplaceable("tf_<kind>") when it knows it but not at that time."""
        if self.buffer is None:
            return None
        from rover_web.tf.buffer import TfError  # the buffer's own module: present whenever a buffer is

        frame = frame.lstrip("/")
        try:
            return self.buffer.lookup(self.map_frame, frame, stamp_ns(stamp_s) or None)
        except TfError as exc:
            error = exc
        ahead_s = float(error.detail.get("by_s", math.inf))
        if error.kind == "extrapolation_future" and ahead_s <= self.future_tolerance_s:
            try:
                return self.buffer.lookup(self.map_frame, frame, None)
            except TfError as exc:
                error = exc
        if error.kind in FALLBACK_KINDS:
            return None
        raise Unplaceable(f"tf_{error.kind}")


def tf_buffer(rover) -> Any | None:
    """The robot's TF buffer, or None when this app has no TF feature (rover_web/tf not set up)."""
    try:
        from rover_web.tf.service import TfService
    except ImportError:
        return None
    from rover_web.core.state import NotSetUp

    try:
        return rover.feature(TfService).buffer
    except NotSetUp:
        return None
