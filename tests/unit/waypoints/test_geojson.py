"""GeoJSON export and import of the mission: order, round trip, and a named reason for each refusal."""

import json

import pytest

from rover_web.waypoints.geojson import mission_to_geojson, waypoints_from_geojson
from rover_web.waypoints.store import Mission, Waypoint
from rover_web.web.validate import InvalidInput


def mission(*points):
    return Mission(3, tuple(Waypoint(10 + i, i, lng, lat, label) for i, (lng, lat, label) in enumerate(points)))


def test_export_is_a_feature_collection_of_points_in_order_lng_first():
    doc = mission_to_geojson(mission((-82.45, 27.37, "dock"), (-82.44, 27.38, "")))
    assert doc["type"] == "FeatureCollection"
    assert [f["geometry"] for f in doc["features"]] == [
        {"type": "Point", "coordinates": [-82.45, 27.37]}, {"type": "Point", "coordinates": [-82.44, 27.38]}]
    assert [f["properties"] for f in doc["features"]] == [{"number": 1, "label": "dock"}, {"number": 2, "label": ""}]


def test_round_trip_through_json_text_keeps_everything():
    original = [(-82.4500873, 27.3742443, "start"), (179.9999999, -89.5, "Süd ⚓"), (0.0, 0.0, "")]
    text = json.dumps(mission_to_geojson(mission(*original)))
    assert waypoints_from_geojson(json.loads(text), 10) == original


def test_import_is_lenient_where_it_is_harmless():
    doc = {"type": "FeatureCollection", "features": [
        {"type": "Feature", "geometry": {"type": "Point", "coordinates": [1, 2, 30.5]}, "properties": None},
        {"type": "Feature", "geometry": {"type": "Point", "coordinates": [3.5, 4]},
         "properties": {"name": "from gpx", "ele": 3}},
        {"type": "Feature", "id": "x", "geometry": {"type": "Point", "coordinates": [5, 6]}}],
        "crs": "ignored"}
    assert waypoints_from_geojson(doc, 10) == [(1.0, 2.0, ""), (3.5, 4.0, "from gpx"), (5.0, 6.0, "")]
    assert waypoints_from_geojson({"type": "FeatureCollection", "features": []}, 10) == []


def feature(coordinates, **extra):
    return {"type": "Feature", "geometry": {"type": "Point", "coordinates": coordinates}, **extra}


@pytest.mark.parametrize("doc, fragment", [
    ([], "FeatureCollection"),
    ({"type": "Feature", "geometry": None}, "FeatureCollection"),
    ({"type": "FeatureCollection"}, "'features'"),
    ({"type": "FeatureCollection", "features": {}}, "'features'"),
    ({"type": "FeatureCollection", "features": [None]}, "features[0] must be a GeoJSON Feature"),
    ({"type": "FeatureCollection",
      "features": [feature([1, 2]),
                   {"type": "Feature", "geometry": {"type": "LineString", "coordinates": [[1, 2], [3, 4]]}}]},
     "features[1].geometry must be a Point"),
    ({"type": "FeatureCollection", "features": [feature([1])]}, "features[0].geometry.coordinates"),
    ({"type": "FeatureCollection", "features": [feature([1, 2, 3, 4])]}, "features[0].geometry.coordinates"),
    ({"type": "FeatureCollection", "features": [feature([200, 2])]}, "coordinates[0] (lng)"),
    ({"type": "FeatureCollection", "features": [feature([1, -95])]}, "coordinates[1] (lat)"),
    ({"type": "FeatureCollection", "features": [feature(["1", 2])]}, "coordinates[0] (lng)"),
    ({"type": "FeatureCollection", "features": [feature([1, 2, "high"])]}, "altitude"),
    ({"type": "FeatureCollection", "features": [feature([1, 2], properties=[1])]}, "properties"),
    ({"type": "FeatureCollection", "features": [feature([1, 2], properties={"label": 7})]}, "properties.label"),
    ({"type": "FeatureCollection", "features": [feature([1, 2])] * 4}, "ROVER_WEB_MAX_WAYPOINTS"),
])
def test_malformed_geojson_is_refused_with_the_place_named(doc, fragment):
    with pytest.raises(InvalidInput) as err:
        waypoints_from_geojson(doc, 3)
    assert fragment in str(err.value)
