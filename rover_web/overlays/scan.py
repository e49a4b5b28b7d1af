"""A LaserScan thinned to what a map view can show, and placed in the map frame. Pure (numpy).

A 1,080-beam scan at 20 Hz is far more than a canvas can tell apart, but a naive decimation (every
third beam) can drop the one beam that hits a thin table leg. So the beams are grouped into
angular bins and each bin keeps its nearest valid return: the extreme point, the one an operator
needs to see ("is the laser seeing the wall?"). Returns that are NaN, infinite or outside
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


def thin(scan: Scan, bins: int) -> tuple[np.ndarray, np.ndarray, int]:
    """(angles, ranges, invalid beams): the nearest valid return in each of `bins` equal angular bins,
    in beam order, and how many beams had no valid return."""
    ranges = np.asarray(scan.ranges, dtype=np.float64)
    n = len(ranges)
    valid = np.isfinite(ranges) & (ranges >= scan.range_min) & (ranges <= scan.range_max)
    index = np.flatnonzero(valid)
    invalid = n - index.size
    if index.size == 0:
        return np.zeros(0), np.zeros(0), invalid
    if n <= bins:
        keep = index
    else:
        bin_of = index * bins // n
        order = np.lexsort((ranges[index], bin_of))  # by bin, nearest first within it
        first = np.ones(order.size, dtype=bool)
        first[1:] = bin_of[order][1:] != bin_of[order][:-1]
        keep = np.sort(index[order[first]])
    return scan.angle_min + keep * scan.angle_increment, ranges[keep], invalid


def to_map(angles: np.ndarray, ranges: np.ndarray, robot: tuple[float, float, float],
           laser: tuple[float, float, float]) -> np.ndarray:
    """Points (N, 2) in the map frame: the laser's pose on the robot composed with the robot's map pose."""
    rx, ry, ryaw = robot
    lx, ly, lyaw = laser
    c, s = math.cos(ryaw), math.sin(ryaw)
    ox, oy = rx + c * lx - s * ly, ry + s * lx + c * ly
    theta = angles + ryaw + lyaw
    return np.column_stack((ox + ranges * np.cos(theta), oy + ranges * np.sin(theta)))


def payload(topic: str, scan: Scan, robot: tuple[float, float, float], points: np.ndarray) -> dict:
    """The `scan` channel's value; points flat [x0, y0, x1, y1, ...] in centimetre-rounded metres."""
    return {"topic": topic, "frame_id": scan.frame_id, "stamp": scan.stamp, "beams": int(len(scan.ranges)),
            "pose": [round(v, 4) for v in robot], "range_max": round(scan.range_max, 3),
            "points": np.round(points, 2).ravel().tolist()}
