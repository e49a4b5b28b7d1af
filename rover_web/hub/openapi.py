"""The hub's routes (ROVER_WEB_HUB=true), for its GET /api/openapi.json (see rover_web/apidocs/describe.py)."""

from rover_web.apidocs.describe import obj, op, page
from rover_web.fleet.openapi import ROBOT

from .history import EVENTS

HEARD_ROBOT = {**ROBOT, "properties": {
    **ROBOT["properties"],
    "url": {"type": ["string", "null"], "description": "the robot's own rover_web (its ROVER_WEB_PUBLIC_URL)"},
    "alerts": {"type": "array", "items": {"type": "string"}, "description": "in English"},
    "alerts_i18n": {"type": "array", "items": {"type": "object"},
                    "description": "each alert's message id and values, for a page in another language "
                                   "(docs/api.md)"},
    "heard": {"type": "string", "enum": ["waiting", "live", "lost"],
              "description": "live: its liveliness token is there and a summary came within "
                             "ROVER_WEB_FLEET_LOST_AFTER_S; waiting: its token came and no summary since (for "
                             "at most that long); lost: otherwise"},
    "forget_in_s": {"type": ["number", "null"], "description": "a lost robot: until it is dropped from the list"},
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
                          "last_stop": {"type": ["object", "null"], "description": "the last stop-all's answers"},
                          "forgotten": {"type": "array", "items": obj({"name": {"type": "string"},
                                                                       "at": {"type": "number"}}),
                                        "description": "robots recently dropped after being lost too long"},
                          "forget_after_s": {"type": "number"}})),
    },
    "/": {"get": op("The hub's home: a redirect to /robots", tag="pages", status=302, ok={"type": "string"},
                    media="text/html", extra={"x-page": True})},
    "/robots": {"get": page("The hub's page: every robot heard, and the last stop-all's answers", tag="pages")},
    "/api/status": {
        "get": op("The hub itself: its fleet, robots heard and live, forged summaries dropped", tag="hub",
                  ok=obj({"hub": {"const": True}, "fleet": {"type": "string"}, "robots": {"type": "integer"},
                          "waiting": {"type": "integer"}, "live": {"type": "integer"}, "lost": {"type": "integer"},
                          "forgotten": {"type": "integer", "description": "robots dropped since the hub started"},
                          "forged_summaries": {"type": "integer"},
                          "stale_summaries": {"type": "integer",
                                              "description": "refused: sent outside the clock window"}})),
    },
    "/api/robots/{name}/history": {
        "get": op("A robot's history on the hub, newest first: found, waiting, live, lost, forgotten, e-stop "
                  "engaged or released (with who), stop-all answers", tag="hub",
                  params=[{"name": "before", "in": "query", "required": False,
                           "schema": {"type": "integer", "minimum": 1},
                           "description": "only rows older than this id (the previous page's next_before)"},
                          {"name": "limit", "in": "query", "required": False,
                           "schema": {"type": "integer", "minimum": 1, "maximum": 200, "default": 50}}],
                  ok=obj({"robot": {"type": "string"},
                          "events": {"type": "array", "items": obj({
                              "id": {"type": "integer"}, "at": {"type": "number"},
                              "event": {"type": "string", "enum": list(EVENTS)},
                              "detail": {"type": "object", "description": "by (e-stop, stop_all), result and "
                                                                          "reason (stop_all), lost_for_s"}})},
                          "next_before": {"type": ["integer", "null"], "description": "the next page's before"}}),
                  errors={400: "bad_value", 404: "unknown_robot"},
                  description="Kept ROVER_WEB_HUB_HISTORY_DAYS, at most ROVER_WEB_HUB_HISTORY_MAX_ROWS per robot."),
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
