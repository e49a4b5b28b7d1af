"""The e-stop's routes, for GET /api/openapi.json (see rover_web/apidocs/describe.py)."""

from rover_web.apidocs.describe import obj, op

STATE = obj({"engaged": {"type": "boolean"}, "cancellable_actions": {"type": "array"}}, closed=False)

PATHS = {
    "/api/estop": {
        "get": op("The e-stop latch and who set it", tag="estop", ok=STATE),
        "post": op(
            "Engage (anyone signed in) or release (an operator) the e-stop", tag="estop", ok=STATE,
            body=obj({"engaged": {"type": "boolean"},
                      "by": {"type": ["string", "null"], "maxLength": 40,
                             "description": "who, when sign-in is off"}}, ("engaged",)),
            errors={400: "missing_body, bad_json, non_finite, unknown_field, missing_field, bad_type",
                    403: "forbidden (releasing needs an operator)",
                    409: "release refused (see docs/estop.md)"},
            description="`{\"engaged\": true}` always engages, whatever else the body holds.",
            fuzz="last", fuzz_why="engaged, it turns every motion route into a 409 for the rest of the run"),
    },
    "/api/estop/all": {
        "post": op(
            "Engage every robot's e-stop (the \"Stop all\" button)", tag="estop",
            ok=obj({"engaged": {"type": "boolean"},
                    "robots": {"type": "object", "additionalProperties": STATE,
                               "description": "each robot's latch, by robot name"}}),
            body=obj({"engaged": {"const": True, "description": "optional; false is refused: release is per robot"},
                      "by": {"type": ["string", "null"], "maxLength": 40, "description": "who, when sign-in is off"}}),
            body_required=False,
            errors={400: "bad_json, non_finite, unknown_field, bad_type, too_long, release_per_robot"},
            description="Any signed-in user may stop every robot; each is released on its own "
                        "(`POST /robots/<name>/api/estop`): `{\"engaged\": false}` here is a 400.",
            fuzz="last", fuzz_why="engaged, it turns every motion route into a 409 for the rest of the run"),
    },
    "/estop": {
        "post": op(
            "The header's E-STOP as a plain HTML form: engages, before or without the page's scripts",
            tag="estop", ok={"type": "string"}, media="text/html",
            form=obj({"back": {"type": "string", "maxLength": 2000,
                               "description": "the page the form was on (a path of this app), linked back to"}},
                     closed=False),
            body=obj(closed=False), body_required=False,
            description="Engages only, as `POST /api/estop {\"engaged\": true}` (same Origin check, any "
                        "signed-in user); the answer is a page saying the e-stop is engaged.",
            fuzz="last", fuzz_why="engaged, it turns every motion route into a 409 for the rest of the run"),
    },
    "/login/estop": {
        "post": op(
            "The sign-in page's e-stop: engage every robot, without signing in", tag="estop", public=True,
            ok=obj({"engaged": {"type": "boolean"},
                    "robots": {"type": "object", "additionalProperties": STATE}}),
            body=obj(closed=False), body_required=False, form=obj(closed=False),
            errors={403: "foreign_origin", 404: "not_found (ROVER_WEB_LOGIN_ESTOP off)",
                    429: "rate_limited (6 a minute per address, with Retry-After)"},
            description="Engages only, never releases. A form post gets the sign-in page back with a notice; "
                        "JSON gets the robots' latches. Who engaged is recorded as the client's address.",
            fuzz="last", fuzz_why="engaged, it turns every motion route into a 409 for the rest of the run"),
    },
}
