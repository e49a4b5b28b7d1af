"""The topic browser's routes, for GET /api/openapi.json (see rover_web/apidocs/describe.py)."""

from rover_web.apidocs.describe import obj, op, page, query

PATHS = {
    "/topics": {"get": page("The topic browser", tag="pages",
                            params=[query("topic", {"type": "string"}, "the topic to open")])},
    "/api/topics": {"get": op("Every topic in the ROS graph, with types, publishers and rates", tag="topics",
                              ok=obj(closed=False))},
    "/api/topics/echo": {
        "get": op("Server-Sent Events: a topic's messages as JSON, and its rate", tag="topics",
                  media="text/event-stream", ok={"type": "string"},
                  params=[query("topic", {"type": "string", "minLength": 1}, "the topic name", required=True),
                          query("type", {"type": "string", "examples": ["std_msgs/msg/String"]},
                                "pkg/msg/Name; needed when the topic is not up yet or carries several")],
                  errors={400: "missing_field, bad_topic, bad_type, type_mismatch, ambiguous_type, unknown_type",
                          404: "unknown_topic", 503: "too_many_streams, too_many_subscriptions, shutting_down"},
                  extra={"x-stream": "sse"}),
    },
}
