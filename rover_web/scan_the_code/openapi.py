"""Scan the Code's route, for GET /api/openapi.json (see rover_web/apidocs/describe.py)."""

from rover_web.apidocs.describe import obj, op

PATHS = {
    "/api/light_sequence": {"get": op("The light buoy's colour sequence as last decoded", tag="scan_the_code",
                                      ok=obj(closed=False))},
}
