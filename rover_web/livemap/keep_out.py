"""Keep-out areas of a floorplan, in map metres (`keep_out` in all_maps.json). Pure Python on shapely.

    "keep_out": [{"name": "electrical room", "polygon": [[34, 0], [37.5, 0], [37.5, 4], [34, 4]]}]

A polygon is at least three [x, y] points (closing it by repeating the first is optional), simple
(no self-intersection), with an area. A goal on the edge of a keep-out area is inside it, as in the
GPS geofence (rover_web/geofence/rules.py), and refused.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property
from typing import TYPE_CHECKING, Any

from rover_web.geofence import OutsideGeofence
from rover_web.web.api_messages import explain

if TYPE_CHECKING:
    from shapely.geometry import Polygon

# shapely is imported where an area is checked or first used: a robot with no floorplans never loads
# it, and one whose floorplans were checked in a child process at start (map_files.py) loads it at
# its first goal on a map with keep-out areas (issue 32: idle RSS).

MAX_POINTS = 1000


@dataclass(frozen=True)
class KeepOutArea:
    name: str
    points: tuple[tuple[float, float], ...]

    @cached_property
    def polygon(self) -> Polygon:
        """The area as a prepared shapely polygon; its validity was checked when it was read."""
        import shapely
        from shapely.geometry import Polygon

        polygon = Polygon(self.points)
        shapely.prepare(polygon)
        return polygon

    def as_dict(self) -> dict:
        return {"name": self.name, "polygon": [list(p) for p in self.points]}


def parse_keep_out(raw: Any, where: str, *, check_shape: bool = True) -> tuple[KeepOutArea, ...]:
    """The areas, or ValueError naming the key (the map loader turns it into a ConfigError).

    check_shape=False leaves out shapely's validity check, for areas already checked by the child
    process that read the same file at start (map_files.py)."""
    if not isinstance(raw, list):
        raise ValueError(f"{where}: expected a list of {{\"name\": ..., \"polygon\": [[x, y], ...]}}")
    return tuple(_area(item, f"{where}[{i}]", check_shape) for i, item in enumerate(raw))


def _area(item: Any, where: str, check_shape: bool = True) -> KeepOutArea:
    if not isinstance(item, dict) or set(item) - {"name", "polygon"} or "polygon" not in item:
        raise ValueError(f"{where}: expected {{\"name\": ..., \"polygon\": [[x, y], ...]}}")
    name = item.get("name", "")
    if not isinstance(name, str) or len(name) > 80:
        raise ValueError(f"{where}.name: a string of at most 80 characters")
    raw = item["polygon"]
    if not isinstance(raw, list) or not 3 <= len(raw) <= MAX_POINTS:
        raise ValueError(f"{where}.polygon: 3 to {MAX_POINTS} [x, y] points in metres")
    points = []
    for n, p in enumerate(raw):
        if (not isinstance(p, list) or len(p) != 2
                or not all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in p)):
            raise ValueError(f"{where}.polygon[{n}]: expected [x, y], two finite numbers in metres")
        points.append((float(p[0]), float(p[1])))
    if points[0] == points[-1]:
        points.pop()
    if len(points) < 3:
        raise ValueError(f"{where}.polygon: not a simple polygon with an area (fewer than 3 distinct points)")
    area = KeepOutArea(name, tuple(points))
    if check_shape:
        import shapely

        reason = shapely.is_valid_reason(area.polygon)
        if reason != "Valid Geometry" or area.polygon.area <= 0:
            raise ValueError(f"{where}.polygon: not a simple polygon with an area ({reason})")
    return area


def check_goal(areas: tuple[KeepOutArea, ...], map_name: str, x: float, y: float) -> None:
    """OutsideGeofence when (x, y) lies in (or on the edge of) a keep-out area."""
    if not areas:
        return
    from shapely.geometry import Point

    point = Point(x, y)
    for i, area in enumerate(areas):
        if area.polygon.intersects(point):
            title = f"keep-out area {area.name!r}" if area.name else f"keep-out area {i}"
            raise OutsideGeofence(explain("(%(x)s, %(y)s) is inside the %(title)s of %(map_name)s",
                                          x=format(x, "g"), y=format(y, "g"), title=title, map_name=repr(map_name)),
                                  reason="inside_keep_out", x=x, y=y, feature=i, name=area.name)
