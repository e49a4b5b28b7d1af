"""Teleop's routes, for GET /api/openapi.json (see rover_web/apidocs/describe.py)."""

from rover_web.apidocs.describe import obj, op, query

PATHS = {
    "/api/teleop": {
        "get": op("Who drives, the deadman and the last command", tag="teleop", ok=obj(closed=False)),
        "post": op(
            "Drive for a bounded time, or stop", tag="teleop", role="operator",
            ok=obj({"command": {"type": "string"}, "linear_mps": {"type": "number"},
                    "angular_rps": {"type": "number"}, "duration_s": {"type": "number"}}, closed=False),
            body=obj({"command": {"type": "string", "maxLength": 20,
                                  "examples": ["forward", "backward", "left", "right", "stop"]},
                      "speed": {"type": "number", "minimum": 0, "maximum": 1},
                      "duration_s": {"type": "number", "exclusiveMinimum": 0}}, ("command",)),
            errors={400: "missing_body, bad_json, non_finite, unknown_field, missing_field, bad_type, "
                         "unknown_command, out_of_range",
                    409: "estop_engaged, another operator drives (see docs/teleop.md)"}),
    },
    "/ws/teleop": {
        "get": op(
            "The teleop WebSocket (RFC 6455; frames in docs/teleop.md)", tag="teleop", role="operator",
            status=101, media="application/json", ok=obj(closed=False),
            params=[query("name", {"type": "string"}, "the operator's name when sign-in is off")],
            errors={400: "not a WebSocket handshake", 503: "too_many_streams"},
            extra={"x-stream": "websocket"}),
    },
}
