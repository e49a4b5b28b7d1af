"""Mission-control panels' routes, for GET /api/openapi.json (see rover_web/apidocs/describe.py)."""

from rover_web.apidocs.describe import obj, op, page, query

UNKNOWN = {404: "unknown_panel"}
VIEW = obj(closed=False)

PATHS = {
    "/panels": {"get": page("Every panel", tag="pages")},
    "/panels/{panel_id}": {"get": page("One panel", tag="pages", errors=UNKNOWN)},
    "/api/panels": {"get": op("Every panel with its state", tag="panels", ok=obj({"panels": {"type": "array"}}))},
    "/api/panels/{panel_id}": {"get": op("One panel with its state", tag="panels", ok=VIEW, errors=UNKNOWN)},
    "/api/panels/{panel_id}/log": {
        "get": op("The panel's operator log, newest first", tag="panels", ok=obj(closed=False),
                  params=[query("limit", {"type": "integer", "minimum": 1, "maximum": 500}, "at most this many")],
                  errors={400: "bad_limit", **UNKNOWN}),
    },
    "/api/panels/{panel_id}/unlock": {
        "post": op("Unlock the panel for commands", tag="panels", role="operator", ok=VIEW,
                   body=obj(closed=False), body_required=False,
                   errors={400: "bad_json", **UNKNOWN, 429: "rate_limited (PANEL_UNLOCKS_PER_MIN; Retry-After)"}),
    },
    "/api/panels/{panel_id}/lock": {
        "post": op("Lock the panel", tag="panels", role="operator", ok=VIEW,
                   body=obj(closed=False), body_required=False, errors={400: "bad_json", **UNKNOWN}),
    },
    "/api/panels/{panel_id}/{control_id}": {
        "post": op("Run one of the panel's controls (its arguments in the body)", tag="panels", role="operator",
                   ok=obj(closed=False), body=obj(closed=False), body_required=False,
                   errors={400: "bad_json and the control's own argument errors", 404: "unknown_panel, unknown_control",
                           409: "locked, estop_engaged and other refusals (docs/panels.md)",
                           429: "rate_limited (PANEL_REFUSALS_PER_MIN; Retry-After)"}),
    },
}
