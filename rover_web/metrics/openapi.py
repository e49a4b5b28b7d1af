"""GET /metrics, for GET /api/openapi.json (see rover_web/apidocs/describe.py)."""

from rover_web.apidocs.describe import op

PATHS = {
    "/metrics": {
        "get": op("Prometheus metrics: each robot's state and the process's own, in the text exposition format",
                  tag="metrics", ok={"type": "string"}, media="text/plain",
                  description="docs/observability.md lists the families; docs/alerts.yml the alerting rules. "
                              "Open on loopback as the API is; when exposed, a viewer's token "
                              "(`Authorization: Bearer`, Prometheus' `authorization` credentials). "
                              "`ROVER_WEB_METRICS=off`: 404."),
    },
}
