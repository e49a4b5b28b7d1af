"""The fleet's routes, for GET /api/openapi.json (see rover_web/apidocs/describe.py).

Every route is also served under /robots/{robot}/ for each robot of ROVER_WEB_ROBOTS
(rover_web/fleet/prefix.py); the paths here are the first robot's.
"""

from rover_web.apidocs.describe import obj, op, page

ROBOT = obj({
    "name": {"type": "string"}, "namespace": {"type": "string"}, "kind": {"type": "string"},
    "title": {"type": "string"}, "url": {"type": "string"},
    "link": {"type": "string", "enum": ["ok", "degraded", "stale", "no_data"]},
    "mode": {"type": "string", "enum": ["estop", "driving", "operator", "idle"]},
    "operator": {"type": ["string", "null"]},
    "speed": {"type": ["object", "null"]}, "battery": {"type": ["object", "null"]},
    "estop": {"type": "object"}, "position": {"type": ["object", "null"]},
}, closed=False)

PATHS = {
    "/api/robots": {
        "get": op("Every robot: link, mode, speed, battery, e-stop and position", tag="fleet",
                  ok=obj({"current": {"type": "string"}, "robots": {"type": "array", "items": ROBOT}})),
    },
    "/robots": {"get": page("The fleet: every robot's state, and all of them on one map", tag="pages")},
}
