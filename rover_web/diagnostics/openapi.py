"""The diagnostics' routes, for GET /api/openapi.json (see rover_web/apidocs/describe.py)."""

from rover_web.apidocs.describe import obj, op, page

PATHS = {
    "/diagnostics": {"get": page("Every diagnostic status with its values", tag="pages")},
    "/api/diagnostics": {
        "get": op("The latest status per name: name, hardware_id, level, message, values, age_s, stale",
                  tag="diagnostics", ok=obj(closed=False)),
    },
}
