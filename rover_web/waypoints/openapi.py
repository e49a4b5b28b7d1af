"""The waypoints routes, for GET /api/openapi.json (see rover_web/apidocs/describe.py)."""

from rover_web.apidocs.describe import obj, op, page, query

LNG = {"type": "number", "minimum": -180, "maximum": 180}
LAT = {"type": "number", "minimum": -90, "maximum": 90}
LABEL = {"type": ["string", "null"], "maxLength": 80}
WAYPOINT = obj({"id": {"type": "integer"}, "lng": LNG, "lat": LAT, "label": {"type": "string"}}, closed=False)
MISSION = obj({"revision": {"type": "integer"}, "waypoints": {"type": "array", "items": WAYPOINT},
               "max": {"type": "integer"}}, closed=False)
NEW = obj({"lng": LNG, "lat": LAT, "label": LABEL}, ("lng", "lat"))
BAD = "missing_body, bad_json, non_finite, unknown_field, missing_field, bad_type, out_of_range, too_long, bad_value"
STORAGE = "storage_unavailable, shutting_down"
FULL = {507: "disk_full"}
FENCE = {422: "outside_geofence"}

PATHS = {
    "/waypoints": {
        "get": page("The waypoints table and map", tag="pages"),
        "post": op("Add a waypoint (the original seed call; answers status=success)", tag="waypoints",
                   role="operator", ok=obj({"status": {"type": "string"}, "waypoint": WAYPOINT}, closed=False),
                   body=NEW,
                   errors={400: BAD, 409: "too_many_waypoints, estop_engaged", **FENCE, 503: STORAGE, **FULL}),
    },
    "/api/waypoints": {
        "get": op("The mission: every waypoint in order, and its revision", tag="waypoints", ok=MISSION),
        "post": op("Add a waypoint at the end", tag="waypoints", role="operator", status=201,
                   ok=obj({"waypoint": WAYPOINT}), body=NEW,
                   errors={400: BAD, 409: "too_many_waypoints, estop_engaged", **FENCE, 503: STORAGE, **FULL}),
        "delete": op("Delete every waypoint", tag="waypoints", role="operator",
                     ok=obj({"deleted": {"type": "integer"}, "revision": {"type": "integer"}}),
                     errors={503: STORAGE, **FULL}),
    },
    "/api/waypoints/{waypoint_id}": {
        "patch": op("Move, relabel or reorder a waypoint", tag="waypoints", role="operator",
                    ok=obj({"waypoint": WAYPOINT, "revision": {"type": "integer"}}),
                    body=obj({"lng": LNG, "lat": LAT, "label": LABEL,
                              "index": {"type": ["integer", "null"], "minimum": 0}}, minProperties=1),
                    errors={400: BAD, 404: "no_such_waypoint", **FENCE, 503: STORAGE, **FULL}),
        "delete": op("Delete a waypoint", tag="waypoints", role="operator",
                     ok=obj({"deleted": {"type": "integer"}, "revision": {"type": "integer"}}),
                     errors={404: "no_such_waypoint", 503: STORAGE, **FULL}),
    },
    "/api/waypoints/send": {
        "post": op("Publish the mission to ROS", tag="waypoints", role="operator", ok=obj(closed=False),
                   body=obj({"revision": {"type": ["integer", "null"], "minimum": 0,
                                          "description": "refuse if the mission changed since this revision"}}),
                   body_required=False,
                   errors={400: BAD, 409: "mission_changed, empty_mission, estop_engaged", **FENCE}),
    },
    "/api/waypoints/geojson": {
        "get": op("The mission as a GeoJSON FeatureCollection of Points", tag="waypoints",
                  media="application/geo+json", ok=obj(closed=False),
                  params=[query("download", {"type": "string"}, "any value: answer as an attachment")]),
        "post": op("Replace the mission with a GeoJSON FeatureCollection of Points", tag="waypoints",
                   role="operator", ok=MISSION,
                   body=obj({"type": {"const": "FeatureCollection"}, "features": {"type": "array", "items": obj({
                       "type": {"const": "Feature"},
                       "geometry": obj({"type": {"const": "Point"},
                                        "coordinates": {"type": "array", "items": {"type": "number"},
                                                        "minItems": 2, "maxItems": 3}}, ("type", "coordinates"),
                                       closed=False),
                       "properties": {"type": ["object", "null"]}}, ("type", "geometry"), closed=False)}},
                            ("type", "features"), closed=False),
                   errors={400: BAD + ", bad_geojson", 409: "too_many_waypoints", **FENCE, 503: STORAGE, **FULL}),
    },
}
