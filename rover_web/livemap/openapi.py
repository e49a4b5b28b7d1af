"""LiveMap's routes, for GET /api/openapi.json (see rover_web/apidocs/describe.py)."""

from rover_web.apidocs.describe import obj, op, page, query

PNG = {"type": "string", "contentMediaType": "image/png"}
UNKNOWN = {404: "unknown_map"}

PATHS = {
    "/livemap": {"get": page("The default map, or the list of maps", tag="pages")},
    "/livemap/{name}": {"get": page("One map with the robot on it", tag="pages", errors=UNKNOWN)},
    "/api/maps": {"get": op("Every map, and the default one", tag="livemap", ok=obj(closed=False))},
    "/api/maps/{name}": {
        "get": op("A map's state: its frame, size and scale", tag="livemap", ok=obj(closed=False),
                  params=[query("cm_per_pixel", {"type": "number", "exclusiveMinimum": 0},
                                "the floorplan's scale, if it differs from the map file's")],
                  errors={400: "bad_type, out_of_range", **UNKNOWN}),
    },
    "/api/maps/{name}/image": {"get": op("The map as PNG", tag="livemap", media="image/png", ok=PNG,
                                         errors={**UNKNOWN, 503: "no map received yet, or shutting_down"})},
    "/api/maps/{name}/thumbnail": {"get": op("A small PNG of the map", tag="livemap", media="image/png", ok=PNG,
                                             errors={**UNKNOWN, 503: "no map received yet, or shutting_down"})},
    "/api/maps/{name}/goal": {
        "post": op("Send a navigation goal in the map's frame", tag="livemap", role="operator",
                   ok=obj(closed=False),
                   body=obj({"x": {"type": "number"}, "y": {"type": "number"}, "yaw": {"type": "number"}},
                            ("x", "y")),
                   errors={400: "missing_body, bad_json, non_finite, unknown_field, missing_field, bad_type, "
                                "outside_map", **UNKNOWN, 409: "estop_engaged",
                           422: "outside_geofence (reason inside_keep_out)", 503: "shutting_down"}),
    },
    "/api/maps/{name}/initial_pose": {
        "post": op("Set the robot's initial pose (AMCL's /initialpose) in the map's frame", tag="livemap",
                   role="operator", ok=obj(closed=False),
                   body=obj({"x": {"type": "number"}, "y": {"type": "number"}, "yaw": {"type": "number"},
                             "covariance": {"type": "array", "items": {"type": "number"},
                                            "minItems": 36, "maxItems": 36}},
                            ("x", "y")),
                   errors={400: "missing_body, bad_json, non_finite, unknown_field, missing_field, bad_type, "
                                "out_of_range, bad_value, outside_map", **UNKNOWN, 409: "estop_engaged",
                           503: "shutting_down"}),
    },
}
