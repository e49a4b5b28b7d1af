"""The fence's rules: which GeoJSON is a fence, and where the robot may go. Pure Python on shapely.

A fence is a GeoJSON FeatureCollection of Polygon and MultiPolygon features, each with
`"properties": {"kind": "keep_in" | "keep_out"}` (and an optional `name`). A position is allowed
when it lies in at least one keep-in area (or there is none) and in no keep-out area.

Edges, decided once: every area is a closed set. A point on the edge of a keep-in area is inside
it (allowed); a point on the edge of a keep-out area is inside the keep-out (refused). So the
boundary of a forbidden place is forbidden, and an operator who clicks exactly on the keep-in line
is not surprised. Holes follow from the same rule: a hole in a keep-in is outside it, a hole in a
keep-out (an island of open water in a closed zone) is allowed, and each hole's edge belongs to
its polygon.

A leg (the straight line between two consecutive waypoints, in longitude/latitude, which is
exact enough for the short legs of a boat or a rover) is refused when it touches any keep-out
area or leaves the union of the keep-in areas.

Out of scope and refused: polygons that cross the antimeridian (an edge longer than 180 degrees of
longitude, or a polygon wider than 180 degrees); RFC 7946 asks writers to cut them in two anyway.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from rover_web.web.api_messages import Text, explain, said
from rover_web.web.validate import InvalidInput

if TYPE_CHECKING:
    from shapely.geometry import MultiPolygon, Polygon

# shapely (with numpy's and GEOS's libraries, ~3.5 MB) is imported where a fence is built or
# checked, not here: a robot with no fence never loads it (issue 32: idle RSS).

KINDS = ("keep_in", "keep_out")
MAX_NAME_CHARS = 80


class OutsideGeofence(Exception):
    """A position or leg the fence does not allow; `details` is the JSON body's extra fields."""

    def __init__(self, message: str, **details: Any):
        super().__init__(message)
        self.details = details


@dataclass(frozen=True)
class Area:
    index: int
    kind: str
    name: str
    geometry: Polygon | MultiPolygon

    @property
    def title(self) -> Text:
        # Shown in the breach banner of every viewer: said, in each viewer's language.
        if self.kind == "keep_in":
            return (said("keep-in area %(name)s", name=repr(self.name)) if self.name
                    else said("keep-in area features[%(index)s]", index=self.index))
        return (said("keep-out area %(name)s", name=repr(self.name)) if self.name
                else said("keep-out area features[%(index)s]", index=self.index))


class Fence:
    """A checked fence with prepared geometries: a point test costs microseconds."""

    def __init__(self, areas: Sequence[Area] = ()):
        self.areas = tuple(areas)
        self.keep_out = tuple(a for a in self.areas if a.kind == "keep_out")
        self.keep_in = None
        if not self.areas:
            return
        import shapely
        from shapely.ops import unary_union
        keep_in = [a.geometry for a in self.areas if a.kind == "keep_in"]
        self.keep_in = unary_union(keep_in) if keep_in else None
        for geometry in [self.keep_in, *(a.geometry for a in self.keep_out)]:
            if geometry is not None:
                shapely.prepare(geometry)

    @property
    def empty(self) -> bool:
        return not self.areas

    def to_geojson(self) -> dict:
        return {"type": "FeatureCollection", "features": [_feature(a) for a in self.areas]}

    # --- rules ---

    def refusal(self, lng: float, lat: float) -> OutsideGeofence | None:
        """Why the point is not allowed, or None."""
        if self.empty:
            return None
        from shapely.geometry import Point
        point = Point(lng, lat)
        if self.keep_in is not None and not self.keep_in.covers(point):
            return OutsideGeofence(said("(%(lng)s, %(lat)s) is outside every keep-in area of the geofence",
                                           lng=format(lng, ".7f"), lat=format(lat, ".7f")),
                                   reason="outside_keep_in", lng=lng, lat=lat)
        for area in self.keep_out:
            if area.geometry.intersects(point):
                return OutsideGeofence(said("(%(lng)s, %(lat)s) is inside the geofence's %(title)s",
                                               lng=format(lng, ".7f"), lat=format(lat, ".7f"), title=area.title),
                                       reason="inside_keep_out", lng=lng, lat=lat, feature=area.index,
                                       name=area.name)
        return None

    def allows(self, lng: float, lat: float) -> bool:
        return self.refusal(lng, lat) is None

    def check_point(self, lng: float, lat: float) -> None:
        refused = self.refusal(lng, lat)
        if refused is not None:
            raise refused

    def check_route(self, points: Sequence[tuple[float, float]]) -> None:
        """Every waypoint, then every leg between consecutive ones; OutsideGeofence at the first fault."""
        if self.empty:
            return
        from shapely.geometry import LineString
        for i, (lng, lat) in enumerate(points):
            refused = self.refusal(lng, lat)
            if refused is not None:
                refused.details["waypoint"] = i
                raise OutsideGeofence(
                    explain("waypoint %(value)s: %(refused)s", value=i + 1, refused=refused), **refused.details
                )
        for i in range(len(points) - 1):
            a, b = points[i], points[i + 1]
            if a == b:
                continue
            leg = LineString([a, b])
            where = dict(leg=[i, i + 1], lng=None, lat=None)
            if self.keep_in is not None and not self.keep_in.covers(leg):
                raise OutsideGeofence(explain("the leg from waypoint %(value)s to %(value2)s leaves the keep-in "
                                              "area of the geofence",
                                              value=i + 1, value2=i + 2), reason="leg_leaves_keep_in", **where)
            for area in self.keep_out:
                if area.geometry.intersects(leg):
                    raise OutsideGeofence(
                        explain(
                            "the leg from waypoint %(value)s to %(value2)s crosses the geofence's %(title)s",
                            value=i + 1,
                            value2=i + 2,
                            title=area.title,
                        ),
                        reason="leg_crosses_keep_out",
                        feature=area.index,
                        name=area.name,
                        **where,
                    )


def _feature(area: Area) -> dict:
    properties = {"kind": area.kind}
    if area.name:
        properties["name"] = area.name
    return {"type": "Feature", "properties": properties,
            "geometry": {"type": area.geometry.geom_type, "coordinates": _coordinates(area.geometry)}}


def _coordinates(geometry) -> list:
    def ring(r):
        return [[x, y] for x, y in r.coords]

    def polygon(p):
        return [ring(p.exterior), *(ring(h) for h in p.interiors)]

    if geometry.geom_type == "MultiPolygon":
        return [polygon(p) for p in geometry.geoms]
    return polygon(geometry)


# --- parsing ---

def parse_fence(doc: Any, max_vertices: int) -> Fence:
    """A Fence from a GeoJSON FeatureCollection; InvalidInput naming the feature and what is wrong."""
    if not isinstance(doc, dict) or doc.get("type") != "FeatureCollection":
        kind = doc.get("type") if isinstance(doc, dict) else type(doc).__name__
        raise InvalidInput("expected a GeoJSON FeatureCollection, got %(kind)s", "bad_geojson",
                           kind=repr(str(kind)[:40]))
    features = doc.get("features")
    if not isinstance(features, list):
        raise InvalidInput("'features' must be a list of Polygon or MultiPolygon features", "bad_geojson")
    counter = _VertexCounter(max_vertices)
    return Fence([_area(i, feature, counter) for i, feature in enumerate(features)])


class _VertexCounter:
    def __init__(self, limit: int):
        self.limit, self.count = limit, 0

    def add(self, n: int, where: str) -> None:
        self.count += n
        if self.count > self.limit:
            raise InvalidInput("%(where)s: the fence has more than %(limit)s vertices "
                               "(ROVER_WEB_GEOFENCE_MAX_VERTICES); simplify it", "too_many_vertices",
                               where=where, limit=self.limit)


def _area(i: int, feature: Any, counter: _VertexCounter) -> Area:
    where = f"features[{i}]"
    if not isinstance(feature, dict) or feature.get("type") != "Feature":
        raise InvalidInput("%(where)s must be a GeoJSON Feature", "bad_geojson", where=where)
    properties = feature.get("properties")
    if not isinstance(properties, dict):
        raise InvalidInput("%(where)s.properties must be an object with \"kind\": \"keep_in\" or \"keep_out\"",
                           "bad_geojson", where=where)
    kind = properties.get("kind")
    if kind not in KINDS:
        raise InvalidInput("%(where)s.properties.kind must be \"keep_in\" or \"keep_out\", got %(kind)s",
                           "bad_geojson", where=where, kind=repr(str(kind)[:40]))
    name = properties.get("name") or ""
    if not isinstance(name, str) or len(name) > MAX_NAME_CHARS or any(ord(c) < 32 for c in name):
        raise InvalidInput("%(where)s.properties.name must be a string of at most %(max_name_chars)s printable "
                           "characters", "bad_geojson", where=where, max_name_chars=MAX_NAME_CHARS)
    if name:
        where = f"{where} ({name!r})"
    import shapely
    from shapely.geometry import MultiPolygon

    geometry = feature.get("geometry")
    gtype = geometry.get("type") if isinstance(geometry, dict) else None
    coordinates = geometry.get("coordinates") if isinstance(geometry, dict) else None
    if gtype == "Polygon":
        shape = _polygon(coordinates, f"{where}.geometry.coordinates", counter)
    elif gtype == "MultiPolygon":
        if not isinstance(coordinates, list) or not coordinates:
            raise InvalidInput("%(where)s.geometry.coordinates must be a non-empty list of polygons", "bad_geojson",
                               where=where)
        shape = MultiPolygon([_polygon(p, f"{where}.geometry.coordinates[{j}]", counter)
                              for j, p in enumerate(coordinates)])
    else:
        raise InvalidInput("%(where)s.geometry must be a Polygon or MultiPolygon, got %(gtype)s",
                           "bad_geojson", where=where, gtype=repr(str(gtype)[:40]))
    min_lng, _, max_lng, _ = shape.bounds
    if max_lng - min_lng > 180:
        raise InvalidInput("%(where)s spans more than 180 degrees of longitude: polygons across the antimeridian are "
                           "not supported", "antimeridian", where=where)
    reason = shapely.is_valid_reason(shape)
    if reason != "Valid Geometry":
        raise InvalidInput(
            "%(where)s is not a valid polygon: %(reason)s", "invalid_geometry", where=where, reason=reason
        )
    if shape.area <= 0:
        raise InvalidInput("%(where)s has no area", "invalid_geometry", where=where)
    return Area(i, kind, name, shape)


def _polygon(rings: Any, where: str, counter: _VertexCounter) -> Polygon:
    if not isinstance(rings, list) or not rings:
        raise InvalidInput("%(where)s must be a list of linear rings (the outline, then any holes)", "bad_geojson",
                           where=where)
    from shapely.geometry import Polygon

    parsed = [_ring(r, f"{where}[{k}]", counter) for k, r in enumerate(rings)]
    return Polygon(parsed[0], parsed[1:])


def _ring(ring: Any, where: str, counter: _VertexCounter) -> list[tuple[float, float]]:
    if not isinstance(ring, list) or len(ring) < 4:
        raise InvalidInput("%(where)s must be a closed ring of at least 4 positions (the first repeated last)",
                           "bad_geojson", where=where)
    counter.add(len(ring), where)
    points = [_position(p, f"{where}[{n}]") for n, p in enumerate(ring)]
    if points[0] != points[-1]:
        raise InvalidInput("%(where)s is not closed: its last position must repeat its first", "bad_geojson",
                           where=where)
    for n in range(len(points) - 1):
        if abs(points[n + 1][0] - points[n][0]) > 180:
            raise InvalidInput("%(where)s: the edge from position %(n)s to %(value)s crosses the antimeridian; "
                               "polygons across it are not supported", "antimeridian", where=where, n=n, value=n + 1)
    return points


def _position(position: Any, where: str) -> tuple[float, float]:
    if not isinstance(position, list) or len(position) not in (2, 3):
        raise InvalidInput("%(where)s must be [lng, lat] or [lng, lat, altitude]", "bad_geojson", where=where)
    values = []
    for value, label, limit in zip(position[:2], ("lng", "lat"), (180.0, 90.0), strict=True):
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise InvalidInput("%(where)s (%(label)s) must be a number", "bad_type", where=where, label=label)
        try:
            number = float(value)
        except OverflowError:
            number = math.inf
        if not math.isfinite(number) or not -limit <= number <= limit:
            raise InvalidInput("%(where)s (%(label)s) must be between %(value)s and %(limit)s", "out_of_range",
                               where=where, label=label, value=format(-limit, "g"), limit=format(limit, "g"))
        values.append(number)
    return values[0], values[1]
