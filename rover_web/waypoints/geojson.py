"""The mission as GeoJSON (RFC 7946): a FeatureCollection of Points, in mission order. Pure Python.

Export writes `[lng, lat]` coordinates and the label and 1-based number as properties. Import is
strict about what matters (a FeatureCollection, Point geometries, coordinates in range) and
lenient about what does not (extra properties, an altitude as third coordinate, `name` instead
of `label`, as files converted from GPX have); every refusal names the feature and field.
"""

from __future__ import annotations

from typing import Any

from rover_web.web.validate import InvalidInput

from .store import Mission, check_label, check_lat, check_lng

MEDIA_TYPE = "application/geo+json"


def mission_to_geojson(mission: Mission) -> dict:
    return {
        "type": "FeatureCollection",
        "features": [
            {
                "type": "Feature",
                "geometry": {"type": "Point", "coordinates": [w.lng, w.lat]},
                "properties": {"number": w.index + 1, "label": w.label},
            }
            for w in mission.waypoints
        ],
    }


def waypoints_from_geojson(doc: Any, max_waypoints: int) -> list[tuple[float, float, str]]:
    """(lng, lat, label) for every feature, in order; InvalidInput naming the first problem."""
    if not isinstance(doc, dict) or doc.get("type") != "FeatureCollection":
        kind = doc.get("type") if isinstance(doc, dict) else type(doc).__name__
        raise InvalidInput("expected a GeoJSON FeatureCollection, got %(kind)s", "bad_geojson",
                           kind=repr(str(kind)[:40]))
    features = doc.get("features")
    if not isinstance(features, list):
        raise InvalidInput("'features' must be a list of Point features", "bad_geojson")
    if len(features) > max_waypoints:
        raise InvalidInput("the file has %(count)s waypoints; the most a mission may hold is %(max_waypoints)s "
                           "(ROVER_WEB_MAX_WAYPOINTS)", "too_many_waypoints",
                           count=len(features), max_waypoints=max_waypoints)
    points = []
    for i, feature in enumerate(features):
        where = f"features[{i}]"
        if not isinstance(feature, dict) or feature.get("type") != "Feature":
            raise InvalidInput("%(where)s must be a GeoJSON Feature", "bad_geojson", where=where)
        geometry = feature.get("geometry")
        if not isinstance(geometry, dict) or geometry.get("type") != "Point":
            kind = geometry.get("type") if isinstance(geometry, dict) else geometry
            raise InvalidInput("%(where)s.geometry must be a Point, got %(kind)s", "bad_geojson",
                               where=where, kind=repr(str(kind)[:40]))
        coordinates = geometry.get("coordinates")
        if not isinstance(coordinates, list) or len(coordinates) not in (2, 3):
            raise InvalidInput("%(where)s.geometry.coordinates must be [lng, lat] or [lng, lat, altitude]",
                               "bad_geojson", where=where)
        lng = check_lng(coordinates[0], f"{where}.geometry.coordinates[0] (lng)")
        lat = check_lat(coordinates[1], f"{where}.geometry.coordinates[1] (lat)")
        if len(coordinates) == 3:  # an altitude is allowed and ignored, but it must be a number
            altitude = coordinates[2]
            if isinstance(altitude, bool) or not isinstance(altitude, (int, float)):
                raise InvalidInput("%(where)s.geometry.coordinates[2] (altitude) must be a number", "bad_type",
                                   where=where)
        properties = feature.get("properties")
        if properties is None:
            properties = {}
        if not isinstance(properties, dict):
            raise InvalidInput("%(where)s.properties must be an object or null", "bad_geojson", where=where)
        key = "label" if "label" in properties else "name"
        label = check_label(properties.get(key), f"{where}.properties.{key}")
        points.append((lng, lat, label))
    return points
