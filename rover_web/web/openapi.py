"""The dashboard, /api/status and /api/events, for GET /api/openapi.json (see apidocs/describe.py)."""

from rover_web.apidocs.describe import header, obj, op, page, query

PATHS = {
    "/": {"get": page("The dashboard", tag="pages")},
    "/status": {"get": page("The node, its topics and the link plot", tag="pages")},
    "/api/ping": {"get": op("The server's clock, for timing a round trip", tag="status",
                            ok=obj({"t": {"type": "number"}}))},
    "/api/status": {"get": op("The node, its topics and the process, as the status channel", tag="status",
                              ok=obj(closed=False))},
    "/api/events": {
        "get": op(
            "Server-Sent Events: the latest value of each channel asked for, then every change", tag="events",
            media="text/event-stream", ok={"type": "string"},
            params=[query("channels", {"type": "string", "minLength": 1},
                          "comma-separated channel names (docs/events.md)", required=True),
                    query("lastEventId", {"type": "string"}, "replay must-deliver events after this id"),
                    header("Last-Event-ID", {"type": "string"}, "as lastEventId")],
            errors={400: "missing_channels, unknown_channel", 503: "too_many_streams"},
            extra={"x-stream": "sse"}),
    },
}
