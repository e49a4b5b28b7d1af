"""The /rosout log's routes, for GET /api/openapi.json (see rover_web/apidocs/describe.py)."""

from rover_web.apidocs.describe import obj, op, page, query

LEVELS = ["DEBUG", "INFO", "WARN", "ERROR", "FATAL"]

PATHS = {
    "/logs": {"get": page("The /rosout log", tag="pages",
                          params=[query("level", {"enum": LEVELS}, "the least level shown")])},
    "/api/rosout": {
        "get": op("The newest /rosout lines, filtered; repeated identical lines grouped with a count",
                  tag="logs", ok=obj(closed=False),
                  params=[query("level", {"enum": LEVELS}, "the least level"),
                          query("node", {"type": "string", "maxLength": 200}, "part of the node's name"),
                          query("contains", {"type": "string", "maxLength": 200}, "text in the line"),
                          query("limit", {"type": "integer", "minimum": 1}, "most lines (at most ROSOUT_KEEP)")],
                  errors={400: "bad_level, bad_node, bad_contains, bad_limit, unknown_parameter"}),
    },
}
