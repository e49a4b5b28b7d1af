"""The layouts' routes, for GET /api/openapi.json (see rover_web/apidocs/describe.py)."""

from rover_web.apidocs.describe import obj, op, query

from .schema import LAYOUT_SCHEMA

LAYOUT = {k: v for k, v in LAYOUT_SCHEMA.items() if k != "$schema"}
SUMMARY = obj({"id": {"type": "integer"}, "name": {"type": "string"}, "kind": {"type": ["string", "null"]},
               "cards": {"type": "integer"}, "updated_at": {"type": "number"}, "updated_by": {"type": "string"}})
SAVED = obj({"id": {"type": "integer"}, "layout": LAYOUT})
BAD_LAYOUT = ("missing_body, bad_json, non_finite, missing_field, unknown_field, bad_type, too_long, too_short, "
              "too_many, too_few, bad_value, bad_version, out_of_range, out_of_grid, overlap, duplicate_card "
              "(the body also names the `field`)")
STORAGE = {503: "storage_unavailable", 507: "disk_full"}

PATHS = {
    "/api/layouts": {
        "get": op("This robot's dashboard layouts, and the caller's active one", tag="layouts",
                  ok=obj({"layouts": {"type": "array", "items": SUMMARY},
                          "active": {"type": ["integer", "null"]}, "kind": {"type": "string"}})),
        "post": op("Add a layout (import: the body is what GET /api/layouts/{layout_id} returns)", tag="layouts",
                   role="operator", status=201, body=LAYOUT, ok=SAVED,
                   errors={400: BAD_LAYOUT, 409: "name_taken", **STORAGE}),
    },
    "/api/layouts/{layout_id}": {
        "get": op("One layout (export; `?download=1` for a file)", tag="layouts", ok=LAYOUT,
                  params=[query("download", {"type": "string"}, "any value: answer as an attachment")],
                  errors={404: "not_found"}),
        "put": op("Replace a layout", tag="layouts", role="operator", body=LAYOUT, ok=SAVED,
                  errors={400: BAD_LAYOUT, 404: "not_found", 409: "name_taken", **STORAGE}),
        "delete": op("Delete a layout; whoever had chosen it gets the robot's default", tag="layouts",
                     role="operator", ok=obj({"deleted": {"type": "integer"}}),
                     errors={404: "not_found", **STORAGE}),
    },
    "/api/me/layout": {
        "get": op("The layout the caller's dashboard shows", tag="layouts",
                  ok=obj({"id": {"type": ["integer", "null"]}, "layout": LAYOUT,
                          "user": {"type": ["string", "null"]}})),
        "put": op("Choose the layout the caller's dashboard shows (remembered per user; with sign-in off, "
                  "one choice for every browser)", tag="layouts",
                  body=obj({"id": {"type": "integer"}}, ("id",)),
                  ok=obj({"id": {"type": "integer"}, "user": {"type": ["string", "null"]}}),
                  errors={400: "missing_body, bad_json, unknown_field, missing_field, bad_type", 404: "not_found",
                          **STORAGE}),
    },
}
