"""Nodes, parameters, services and actions, for GET /api/openapi.json (see rover_web/apidocs/describe.py)."""

from rover_web.apidocs.describe import obj, op, page, query

BODY = "missing_body, bad_json, non_finite, unknown_field, missing_field, bad_type, out_of_range"
FIELDS = "and a field of the request or goal, named by its path"
NODE = {404: "unknown_node", 504: "no_answer"}
OFF = "ros_admin_off"
WRITE_403 = "ros_admin_off, ros_admin_read_only, denied, not_allowed (ROVER_WEB_ROS_ADMIN_*)"
TYPE_NAME = {"type": "string", "examples": ["std_srvs/srv/SetBool"]}

PATHS = {
    "/ros": {"get": page("Nodes, parameters, services and actions", tag="pages",
                         errors={403: "ros_admin_off (the page says so)"})},
    "/api/nodes": {"get": op("The nodes in the graph, with their topics, services and actions", tag="ros",
                             ok=obj(closed=False), errors={403: OFF})},
    "/api/nodes/{node}/parameters": {
        "get": op("A node's parameters: name, type, value, description, read_only, ranges", tag="ros",
                  ok=obj(closed=False), errors={400: "bad_node_name", 403: OFF, **NODE}),
    },
    "/api/nodes/{node}/parameters/{name}": {
        "put": op("Set one parameter, checked against its descriptor first", tag="ros", role="admin",
                  body=obj({"value": {}}, ("value",)), ok=obj(closed=False),
                  errors={400: f"{BODY}, bad_node_name, bad_parameter_name, wrong type, out of range",
                          403: WRITE_403, 404: "unknown_node, unknown_parameter",
                          409: "read_only, refused_by_node, estop_engaged (a safety node)",
                          504: "no_answer"}),
    },
    "/api/services": {"get": op("Every service with its types", tag="ros", ok=obj(closed=False), errors={403: OFF})},
    "/api/types/{package}/{kind}/{name}": {
        "get": op("The fields of a message, service or action type (for generated forms)", tag="ros",
                  ok=obj(closed=False),
                  errors={400: "bad_type_name", 403: OFF, 404: "unknown_kind", 422: "unknown_type"}),
    },
    "/api/services/call": {
        "post": op("Call a service; the request is checked field by field against its type", tag="ros",
                   role="admin", ok=obj(closed=False),
                   body=obj({"service": {"type": "string"}, "type": TYPE_NAME, "request": obj(closed=False),
                             "timeout_s": {"type": "number", "minimum": 0.1}}, ("service", "type")),
                   errors={400: f"{BODY}, bad_topic, bad_type_name, type_mismatch, {FIELDS}",
                           403: WRITE_403, 404: "unknown_service", 409: "estop_engaged", 422: "unknown_type",
                           504: "no_answer"}),
    },
    "/api/actions/goals": {"get": op("Goals sent from here, running and recent", tag="ros", ok=obj(closed=False),
                                     errors={403: OFF})},
    "/api/actions/goal": {
        "post": op("Send an action goal", tag="ros", role="admin", ok=obj(closed=False),
                   body=obj({"action": {"type": "string"}, "type": {"type": "string"}, "goal": obj(closed=False)},
                            ("action", "type")),
                   errors={400: f"{BODY}, bad_topic, bad_type_name, {FIELDS}",
                           403: f"{WRITE_403}, navigation_goal (use the LiveMap or waypoints)",
                           409: "estop_engaged, goal_rejected",
                           422: "unknown_type", 504: "no_answer"},
                   fuzz="last", fuzz_why="a goal the simulator accepts keeps running; sent after the rest"),
    },
    "/api/actions/{goal_id}/cancel": {
        "post": op("Cancel a goal sent from here", tag="ros", role="operator", ok=obj(closed=False),
                   body=obj(closed=False), body_required=False,
                   errors={400: "bad_json, bad_goal_id", 403: OFF, 404: "unknown_goal", 504: "no_answer"}),
    },
    "/api/actions/{goal_id}/events": {
        "get": op("Server-Sent Events: a goal's status, feedback and result", tag="ros",
                  media="text/event-stream", ok={"type": "string"},
                  errors={400: "bad_goal_id", 403: OFF, 404: "unknown_goal", 503: "too_many_streams"},
                  extra={"x-stream": "sse"}),
    },
    "/api/ros/log": {
        "get": op("The operator log of parameter sets, service calls and goals", tag="ros", ok=obj(closed=False),
                  params=[query("limit", {"type": "integer", "minimum": 1, "maximum": 500}, "most entries")],
                  errors={400: "bad_limit", 403: OFF}),
    },
}
