"""The preferences' routes, for GET /api/openapi.json (see rover_web/apidocs/describe.py)."""

from rover_web.apidocs.describe import obj, op

from .service import LANGUAGES, THEMES

CHOICES = {"theme": {"type": "string", "enum": list(THEMES)}, "language": {"type": "string", "enum": list(LANGUAGES)}}
STORAGE = {503: "storage_unavailable", 507: "disk_full"}

PATHS = {
    "/api/me/preferences": {
        "get": op("The caller's theme and language: in effect (saved over the browser's cookies over the "
                  "defaults), saved for the user, and where they are kept", tag="preferences",
                  ok=obj({"effective": obj(CHOICES), "saved": obj(CHOICES, required=()), "defaults": obj(CHOICES),
                          "user": {"type": ["string", "null"]},
                          "kept": {"type": "string", "enum": ["user", "browser"]}})),
        "put": op("Save some of the caller's choices on the robot (signed in only; a browser keeps its own)",
                  tag="preferences", body=obj(CHOICES, required=()),
                  ok=obj({"saved": obj(CHOICES, required=()), "user": {"type": "string"}}),
                  errors={400: "missing_body, bad_json, unknown_field, bad_type, bad_value", 409: "no_user",
                          **STORAGE}),
    },
}
