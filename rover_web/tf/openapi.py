"""TF's routes, for GET /api/openapi.json (see rover_web/apidocs/describe.py)."""

from rover_web.apidocs.describe import obj, op, page, query

_VEC3 = {"type": "array", "items": {"type": "number"}, "minItems": 3, "maxItems": 3}
_QUAT = {"type": "array", "items": {"type": "number"}, "minItems": 4, "maxItems": 4}
_FRAME = {"type": "string", "minLength": 1, "maxLength": 256}

TREE = obj({
    "available": {"type": "boolean", "description": "false: tf2_msgs is not installed; nothing is subscribed"},
    "missing": {"type": ["string", "null"], "description": "what is missing and how to get it"},
    "frames": {"type": "object", "description": "frame id -> parent (null for a root), static, rate_hz, "
                                                "newest_stamp, oldest_stamp, age_s, authority, received, "
                                                "unnormalised, children, in_loop"},
    "roots": {"type": "array", "items": {"type": "string"}},
    "warnings": {"type": "array", "items": obj({"kind": {"enum": ["two_parents", "loop", "stale", "future",
                                                                  "unnormalised", "several_trees"]},
                                                "message": {"type": "string"}}, ("kind", "message"), closed=False)},
    "rejected": {"type": "array", "description": "transforms tf2 would ignore, counted by reason (nan, "
                                                "unnormalised, self_transform, no_frame_id, old_data, repeated, "
                                                "too_many_frames)"},
    "now": {"type": "number", "description": "the clock ages are measured against (s)"},
    "cache_s": {"type": "number"},
}, closed=False)

PATHS = {
    "/tf": {"get": page("The robot's TF tree, each frame's details and what is wrong with it", tag="pages")},
    "/api/tf": {
        "get": op("The TF tree: each frame's parent, static or dynamic, rate, age of its newest transform; "
                  "warnings (two parents, a loop, stale, stamped in the future, unnormalised quaternions, "
                  "several trees)", tag="tf", ok=TREE),
    },
    "/api/tf/lookup": {
        "get": op("The transform mapping points in `source` into `target` (tf2's lookupTransform), at `time` "
                  "or the latest common time; a refusal carries tf2's reason as its error code",
                  tag="tf",
                  params=[query("target", _FRAME, "the frame the answer is expressed in", required=True),
                          query("source", _FRAME, "the frame whose points are mapped", required=True),
                          query("time", {"type": "number", "minimum": 0},
                                "seconds (ROS time); absent or 0: the latest time every link has data")],
                  ok=obj({"target": {"type": "string"}, "source": {"type": "string"}, "translation": _VEC3,
                          "rotation": {**_QUAT, "description": "x, y, z, w"}, "yaw": {"type": "number"},
                          "stamp": {"type": "number"}, "stamp_ns": {"type": "integer"}}),
                  errors={400: "missing_frame, bad_frame, bad_time, invalid",
                          404: "unknown_frame",
                          409: "not_connected, extrapolation_past, extrapolation_future",
                          503: "tf_unavailable"}),
    },
}
