"""The plots' routes, for GET /api/openapi.json (see rover_web/apidocs/describe.py)."""

from rover_web.apidocs.describe import obj, op, page, query

TOPIC = query("topic", {"type": "string", "minLength": 1}, "the topic", required=True)
TYPE = query("type", {"type": "string"}, "pkg/msg/Name, when the topic is not up yet or carries several")
REFUSED = {400: "missing_field, bad_topic, bad_type, type_mismatch, ambiguous_type, unknown_type",
           404: "unknown_topic", 422: "not_plottable (images, point clouds, maps)",
           503: "too_many_subscriptions, too_many_series, shutting_down"}

PATHS = {
    "/plot": {"get": page("Live plots of numeric fields", tag="pages")},
    "/api/plot": {
        "get": op("A field's recent samples, decimated to at most 2,000 points (min and max kept)", tag="plot",
                  ok=obj({"t": {"type": "array", "items": {"type": "number"}},
                          "v": {"type": "array", "items": {"type": "number"}}}, closed=False),
                  params=[TOPIC, query("field", {"type": "string", "minLength": 1},
                                       "a numeric field: twist.twist.linear.x, position[2]", required=True),
                          query("seconds", {"type": "number", "exclusiveMinimum": 0, "maximum": 86400},
                                "how far back (default 60)"), TYPE],
                  errors={**REFUSED, 400: REFUSED[400] + ", bad_field, no_such_field, not_numeric, not_array, "
                                                         "bad_seconds"},
                  cross_site=True),
    },
    "/api/plot/fields": {
        "get": op("The numeric fields of a topic's type, as paths", tag="plot", ok=obj(closed=False),
                  params=[TOPIC, TYPE], errors=REFUSED),
    },
}
