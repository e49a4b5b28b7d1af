"""Nav2's routes, for GET /api/openapi.json (see rover_web/apidocs/describe.py)."""

from rover_web.apidocs.describe import obj, op

NUMBER = {"type": "number"}
POSE = obj({"x": NUMBER, "y": NUMBER, "yaw": NUMBER}, ("x", "y"))
MAP = {"type": "string", "maxLength": 200, "description": "the LiveMap map the poses are on (default: the default map)"}
GOAL = obj(closed=False, description="the goal: id, kind, action, map, frame_id, poses, sent_by, sent_at, status, "
                                     "cancel")
SENT = obj({"status": {"type": "string"}, "goal": GOAL})
STATE = obj({
    "available": {"type": "boolean"},
    "missing": {"type": ["object", "null"], "description": "what is missing (nav2_msgs) and how to get it"},
    "goal_mode": {"enum": ["auto", "action", "topic"]},
    "goal_via": {"enum": ["action", "topic"], "description": "how LiveMap sends a goal now"},
    "servers": {"type": "object"},
    "lifecycle": {"type": "array", "items": obj(closed=False),
                  "description": "each Nav2 server's lifecycle state: active, inactive, unconfigured, finalized, "
                                 "missing (no get_state service), no_answer, checking, unknown"},
    "goal": {"type": ["object", "null"]},
    "feedback": {"type": ["object", "null"]},
    "result": {"type": ["object", "null"]},
}, closed=False)
BAD = "missing_body, bad_json, non_finite, unknown_field, missing_field, bad_type, too_long, bad_value, outside_map"
SENDING = {404: "unknown_map", 409: "estop_engaged, goal_rejected",
           422: "outside_geofence (reason inside_keep_out; index: the refused pose)",
           503: "nav2_unavailable (nav2_msgs missing: the message says how to get it), no_nav2_server, shutting_down"}

PATHS = {
    "/api/nav2": {"get": op("Nav2: the goal, its feedback and result, the servers and their lifecycle states",
                            tag="nav2", ok=STATE)},
    "/api/nav2/goal": {
        "post": op("Send a NavigateToPose goal in the map's frame", tag="nav2", role="operator", ok=SENT,
                   body=obj({"map": MAP, "x": NUMBER, "y": NUMBER, "yaw": NUMBER}, ("x", "y")),
                   errors={400: BAD, **SENDING}),
    },
    "/api/nav2/route": {
        "post": op("Send a route: NavigateThroughPoses or FollowWaypoints", tag="nav2", role="operator", ok=SENT,
                   body=obj({"map": MAP, "mode": {"enum": ["through_poses", "follow_waypoints"]},
                             "poses": {"type": "array", "items": POSE, "minItems": 1}}, ("mode", "poses")),
                   errors={400: BAD, **SENDING}),
    },
    "/api/nav2/cancel": {
        "post": op("Cancel the Nav2 goal sent from here", tag="nav2", role="operator", ok=SENT, body=obj(),
                   body_required=False,
                   errors={400: "bad_json, unknown_field", 409: "no_goal", 503: "nav2_unavailable"}),
    },
}
