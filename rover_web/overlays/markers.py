"""visualization_msgs/MarkerArray projected on the map plane and kept as RViz keeps them. Pure.

A marker is added or replaced by (ns, id), removed by DELETE, and all of them by DELETEALL; one
with a lifetime disappears when it runs out. Its points are brought into the map frame here, so
the page only draws. Where each marker goes is asked of a `place(frame, stamp)` the service gives
(through TF, any frame: rover_web/placement.py); without TF, markers in the map frame are drawn as
they are, markers in the robot's own frames (`base_link`, `base_footprint`, the laser's) with the
robot's latest map pose, and markers in any other frame skipped and counted. z is dropped: a 2D
projection (a tilted frame's points are placed in 3D first, then projected).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

from rover_web.placement import CONFIGURED, IDENTITY, MAP, Placement, Planar, heading

ARROW, CUBE, SPHERE, CYLINDER, LINE_STRIP, LINE_LIST, CUBE_LIST, SPHERE_LIST, POINTS, TEXT = range(10)
KINDS = {ARROW: "arrow", CUBE: "cube", SPHERE: "sphere", CYLINDER: "cylinder", LINE_STRIP: "line_strip",
         LINE_LIST: "line_list", CUBE_LIST: "cube_list", SPHERE_LIST: "sphere_list", POINTS: "points",
         TEXT: "text"}
ADD, DELETE, DELETEALL = 0, 2, 3
MAP_FRAMES = ("map", "")
ROBOT_FRAMES = ("base_link", "base_footprint", "laser", "base_scan")


class BadMarker(ValueError):
    """A marker that cannot be drawn; the message is the reason counted."""


def _compose(outer: tuple[float, float, float], x: float, y: float) -> tuple[float, float]:
    ox, oy, oyaw = outer
    c, s = math.cos(oyaw), math.sin(oyaw)
    return ox + c * x - s * y, oy + s * x + c * y


Place = Callable[[str, float], tuple[Placement, str]]  # (frame, stamp) -> (map <- frame, placed_by); BadMarker


def robot_frames(robot: tuple[float, float, float] | None) -> Place:
    """The placement without TF: the map frame as is, the robot's own frames at its map pose."""
    def place(frame: str, stamp: float) -> tuple[Placement, str]:
        if frame in MAP_FRAMES:
            return IDENTITY, MAP
        if frame in ROBOT_FRAMES:
            if robot is None:
                raise BadMarker("no_pose")
            return Planar(*robot), CONFIGURED
        raise BadMarker("unknown_frame")
    return place


def _finite(*values: float) -> bool:
    return all(math.isfinite(v) for v in values)


@dataclass
class MarkerSet:
    max_points: int = 5000
    max_markers: int = 1000  # zero-point markers (cubes) cost a dict each: the review grew 100,020 of them
    points: int = 0  # in all the markers kept, against max_points
    markers: dict[tuple[str, int], dict] = field(default_factory=dict)
    _expiry: dict[tuple[str, int], float] = field(default_factory=dict)

    def apply(self, marker: dict, place: Place | tuple[float, float, float] | None, now: float) -> None:
        """Add, replace or delete one marker (a plain dict from msgs.py); BadMarker says why one is skipped.

        `place` puts a frame in the map (or is the robot's map pose, for the robot_frames placement)."""
        key = (marker["ns"], marker["id"])
        if marker["action"] == DELETEALL:
            self.markers.clear()
            self._expiry.clear()
            self.points = 0
            return
        if marker["action"] == DELETE:
            self._remove(key)
            return
        if marker["action"] != ADD:
            raise BadMarker("bad_action")
        if marker["type"] not in KINDS:
            raise BadMarker("unsupported_type")
        replaced = self.markers.get(key)
        if replaced is None and len(self.markers) >= self.max_markers:
            raise BadMarker("too_many_markers")
        drawn = self._project(marker, place if callable(place) else robot_frames(place))
        used = self.points - (len(replaced["points"]) if replaced else 0)
        if used + len(drawn["points"]) > self.max_points:
            raise BadMarker("too_many_points")
        self.markers[key] = drawn
        self.points = used + len(drawn["points"])
        if marker["lifetime_s"] > 0:
            self._expiry[key] = now + marker["lifetime_s"]
        else:
            self._expiry.pop(key, None)

    def expire(self, now: float) -> bool:
        """Drop markers whose lifetime ran out; True if any went."""
        gone = [k for k, t in self._expiry.items() if t <= now]
        for key in gone:
            self._remove(key)
        return bool(gone)

    def _remove(self, key: tuple[str, int]) -> None:
        removed = self.markers.pop(key, None)
        self._expiry.pop(key, None)
        if removed:
            self.points -= len(removed["points"])

    def payload(self, topic: str) -> dict:
        return {"topic": topic, "markers": list(self.markers.values())}

    @staticmethod
    def _project(m: dict, place: Place) -> dict:
        px, py, pyaw = m["pose"]
        if not _finite(px, py, pyaw, *m["scale"], *m["color"]) or not all(_finite(*p) for p in m["points"]):
            raise BadMarker("not_finite")
        outer, placed_by = place(m["frame_id"].lstrip("/"), m.get("stamp", 0.0))
        x, y, yaw = heading(outer, px, py, pyaw)
        # Points are in the marker's pose, that pose in its frame: both placed through `outer`.
        points = []
        for p in m["points"]:
            u, v = _compose((px, py, pyaw), *p)
            points.append([round(c, 3) for c in outer.apply(u, v, 0.0)[:2]])
        kind = KINDS[m["type"]]
        if kind in ("line_strip", "line_list", "points", "cube_list", "sphere_list") and not points:
            raise BadMarker("empty")
        return {"ns": m["ns"], "id": m["id"], "type": kind, "frame_id": m["frame_id"], "placed_by": placed_by,
                "pose": [round(x, 3), round(y, 3), round(yaw, 4)],
                "scale": [round(v, 4) for v in m["scale"]], "color": [round(v, 3) for v in m["color"]],
                "colors": [[round(v, 3) for v in c] for c in m["colors"]] if len(m["colors"]) == len(points) else [],
                "points": points, "text": m["text"][:200]}
