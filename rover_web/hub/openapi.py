"""The hub's routes (ROVER_WEB_HUB=true), for its GET /api/openapi.json (see rover_web/apidocs/describe.py)."""

from rover_web.apidocs.describe import obj, op, page
from rover_web.fleet.openapi import ROBOT

HEARD_ROBOT = {**ROBOT, "properties": {
    **ROBOT["properties"],
    "url": {"type": ["string", "null"], "description": "the robot's own rover_web (its ROVER_WEB_PUBLIC_URL)"},
    "alerts": {"type": "array", "items": {"type": "string"}},
    "heard": {"type": "string", "enum": ["live", "lost"],
              "description": "live: its liveliness token is there and a summary came within "
                             "ROVER_WEB_FLEET_LOST_AFTER_S"},
    "alive": {"type": "boolean", "description": "its Zenoh liveliness token is declared"},
    "summary_age_s": {"type": ["number", "null"], "description": "since its last authentic summary"},
}}

ANSWER = obj({"result": {"type": "string", "enum": ["engaged", "not_engaged", "refused", "no_answer",
                                                    "bad_answer", "error"]},
              "reason": {"type": "string", "description": "why a robot refused (bad_signature, stale, replayed, ...)"},
              "message": {"type": "string"}, "estop": {"type": "object"}}, closed=False)
STOP_ALL = obj({"at": {"type": "number"}, "by": {"type": "string"}, "took_s": {"type": "number"},
                "engaged": {"type": "boolean", "description": "every robot answered engaged"},
                "robots": {"type": "object", "additionalProperties": ANSWER,
                           "description": "each robot's answer, by name"}})

PATHS = {
    "/api/robots": {
        "get": op("Every robot heard over Zenoh: its summary, and whether it is live or lost", tag="hub",
                  ok=obj({"hub": {"const": True}, "fleet": {"type": "string"},
                          "robots": {"type": "array", "items": HEARD_ROBOT},
                          "last_stop": {"type": ["object", "null"], "description": "the last stop-all's answers"}})),
    },
    "/": {"get": op("The hub's home: a redirect to /robots", tag="pages", status=302, ok={"type": "string"},
                    media="text/html", extra={"x-page": True})},
    "/robots": {"get": page("The hub's page: every robot heard, and the last stop-all's answers", tag="pages")},
    "/api/status": {
        "get": op("The hub itself: its fleet, robots heard and live, forged summaries dropped", tag="hub",
                  ok=obj({"hub": {"const": True}, "fleet": {"type": "string"}, "robots": {"type": "integer"},
                          "live": {"type": "integer"}, "forged_summaries": {"type": "integer"}})),
    },
    "/api/estop/all": {
        "post": op(
            "Send every robot heard a signed stop; each robot's answer", tag="hub", ok=STOP_ALL,
            body=obj({"engaged": {"const": True, "description": "optional; false is refused: release is per robot"},
                      "by": {"type": ["string", "null"], "maxLength": 40, "description": "who, when sign-in is off"}}),
            body_required=False,
            errors={400: "bad_json, non_finite, unknown_field, bad_type, too_long, release_per_robot"},
            description="Any signed-in user, as on a robot. Waits at most ROVER_WEB_FLEET_STOP_TIMEOUT_S for "
                        "the robots' answers (asked at once); a robot silent until then is `no_answer`.",
            fuzz="last", fuzz_why="it stops every robot of the fleet"),
    },
    "/api/openapi.json": {"get": op("This description of the hub's API", tag="docs", ok=obj(closed=False))},
}
