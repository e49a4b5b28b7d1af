"""The overlays' route, for GET /api/openapi.json (see rover_web/apidocs/describe.py)."""

from rover_web.apidocs.describe import obj, op, query

PATHS = {
    "/api/overlays": {
        "get": op("LiveMap overlays: each layer's topics, messages received, converted and skipped (by reason), "
                  "what placed its latest message (placed_by: tf, configured offsets, or map when already in the "
                  "map frame), and the robot's recent path", tag="livemap", ok=obj(closed=False),
                  params=[query("costmaps", {"type": "string", "enum": ["0", "1"]},
                                "1: also every costmap's newest encoding, cells included")],
                  errors={400: "bad_costmaps"}),
    },
}
