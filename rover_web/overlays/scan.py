"""A LaserScan thinned to what a map view can show, and placed in the map frame. Pure (numpy).

A 1,080-beam scan at 20 Hz is far more than a canvas can tell apart, but a naive decimation (every
third beam) can drop the one beam that hits a thin table leg. So the beams are grouped into
angular bins and each bin keeps its nearest valid return: the extreme point, the one an operator
needs to see ("is the laser seeing the wall?"). It also keeps the bin's farthest valid return when
that is FAR_MIN_GAP_M or more beyond the nearest: a far return among near ones is a doorway or a
gap, and a 25 m beam between walls must not vanish. Returns that are NaN, infinite or outside
[range_min, range_max] are no return at all, as in RViz.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


class BadScan(ValueError):
    """A scan that cannot be drawn; the message is the reason counted."""


@dataclass(frozen=True)
class Scan:
    frame_id: str
    stamp: float
    angle_min: float
    angle_increment: float
    range_min: float
    range_max: float
    ranges: np.ndarray  # float32, one per beam


def check(scan: Scan) -> None:
    """BadScan for what no drawing can make sense of (a scan whose ranges are all NaN is fine: it saw nothing)."""
    if len(scan.ranges) == 0:
        raise BadScan("empty")
    numbers = (scan.angle_min, scan.angle_increment, scan.range_min, scan.range_max)
    if not all(math.isfinite(v) for v in numbers) or scan.angle_increment == 0:
        raise BadScan("bad_header")


FAR_MIN_GAP_M = 0.25  # a bin's farthest return this much beyond its nearest is drawn too


@dataclass(frozen=True)
class Thinned:
    angles: np.ndarray  # the nearest valid return of each bin, in beam order
    ranges: np.ndarray
    far_angles: np.ndarray  # the farthest of each bin, where it is FAR_MIN_GAP_M beyond the nearest
    far_ranges: np.ndarray
    invalid: int  # beams with no valid return


def thin_both(scan: Scan, bins: int, far_gap_m: float = FAR_MIN_GAP_M) -> Thinned:
    """The nearest and (where it stands out) the farthest valid return of each of `bins` equal
    angular bins; one sort for both."""
    ranges = np.asarray(scan.ranges, dtype=np.float64)
    n = len(ranges)
    valid = np.isfinite(ranges) & (ranges >= scan.range_min) & (ranges <= scan.range_max)
    index = np.flatnonzero(valid)
    invalid = n - index.size
    empty = np.zeros(0)
    if index.size == 0:
        return Thinned(empty, empty, empty, empty, invalid)
    if n <= bins:
        near, far = index, index[:0]  # every beam is its own bin
    else:
        bin_of = index * bins // n
        order = np.lexsort((ranges[index], bin_of))  # by bin, nearest first within it
        sorted_bins = bin_of[order]
        first = np.ones(order.size, dtype=bool)
        first[1:] = sorted_bins[1:] != sorted_bins[:-1]
        last = np.ones(order.size, dtype=bool)
        last[:-1] = first[1:]
        near, far = index[order[first]], index[order[last]]  # both in bin order, one per bin
        far = far[ranges[far] - ranges[near] >= far_gap_m]
    step = scan.angle_increment
    return Thinned(scan.angle_min + near * step, ranges[near], scan.angle_min + far * step, ranges[far], invalid)


def thin(scan: Scan, bins: int) -> tuple[np.ndarray, np.ndarray, int]:
    """(angles, ranges, invalid beams): the nearest valid return in each of `bins` equal angular bins,
    in beam order, and how many beams had no valid return."""
    t = thin_both(scan, bins)
    return t.angles, t.ranges, t.invalid


def in_sensor_frame(angles: np.ndarray, ranges: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The returns as (x, y) in the laser's own frame (its scan plane is z = 0), for a TF transform."""
    return ranges * np.cos(angles), ranges * np.sin(angles)


def to_map(angles: np.ndarray, ranges: np.ndarray, robot: tuple[float, float, float],
           laser: tuple[float, float, float]) -> np.ndarray:
    """Points (N, 2) in the map frame: the laser's pose on the robot composed with the robot's map pose."""
    rx, ry, ryaw = robot
    lx, ly, lyaw = laser
    c, s = math.cos(ryaw), math.sin(ryaw)
    ox, oy = rx + c * lx - s * ly, ry + s * lx + c * ly
    theta = angles + ryaw + lyaw
    return np.column_stack((ox + ranges * np.cos(theta), oy + ranges * np.sin(theta)))


def payload(topic: str, scan: Scan, robot: tuple[float, float, float], points: np.ndarray,
            far_points: np.ndarray | None = None, placed_by: str = "configured") -> dict:
    """The `scan` channel's value; points flat [x0, y0, x1, y1, ...] in centimetre-rounded metres:
    `points` the nearest return of each bin, `far_points` the farthest where it stands out. `pose`
    is the sensor's origin and heading in the map; `placed_by` "tf" or "configured" (the offsets)."""
    far = [] if far_points is None else np.round(far_points, 2).ravel().tolist()
    return {"topic": topic, "frame_id": scan.frame_id, "stamp": scan.stamp, "beams": int(len(scan.ranges)),
            "pose": [round(v, 4) for v in robot], "range_max": round(scan.range_max, 3),
            "points": np.round(points, 2).ravel().tolist(), "far_points": far, "placed_by": placed_by}


def payload_3d(topic: str, scan: Scan, points: np.ndarray, placed_by: str) -> dict:
    """The `scan3d` channel's value (the 3D view): every return drawn on the map, near and far, flat
    [x0, y0, z0, x1, ...] in centimetre-rounded metres of the map frame, z included."""
    return {"topic": topic, "frame_id": scan.frame_id, "stamp": scan.stamp, "placed_by": placed_by,
            "points": np.round(points, 2).ravel().tolist()}
