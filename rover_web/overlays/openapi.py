"""The overlays' route, for GET /api/openapi.json (see rover_web/apidocs/describe.py)."""

from rover_web.apidocs.describe import obj, op

PATHS = {
    "/api/overlays": {
        "get": op("LiveMap overlays: each layer's topics, messages received, converted and skipped (by reason), "
                  "and the robot's recent path", tag="livemap", ok=obj(closed=False)),
    },
}
