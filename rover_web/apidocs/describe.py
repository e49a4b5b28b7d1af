"""Helpers each feature's openapi.py uses to describe its routes in a few lines. Pure Python.

A feature's part is a dict PATHS: {"/api/x/{name}": {"get": op(...), "post": op(...)}}, with
OpenAPI's {name} for Flask's <name>. Path parameters that a part does not describe are filled in
from the URL rule's converter (document.py), so most parts never mention them.
"""

from __future__ import annotations

from typing import Any

ERROR_REF = {"$ref": "#/components/schemas/Error"}
JSON = "application/json"
# What the guard and the sign-in check may answer on any route (rover_web/web/http.py, auth/routes.py).
GUARD_ERRORS = {400: "untrusted_host"}
# sign_in_needed: under ROVER_WEB_AUTH=auto, a request through a proxy or by another host name while no
# user exists (auth/routes.py); it may answer any route that needs sign-in.
SIGNED_IN_ERRORS = {401: "unauthenticated",
                    403: "forbidden (the role is too low), foreign_origin, sign_in_needed (under ROVER_WEB_AUTH=auto "
                         "a request through a proxy or by another host name, and no user exists)"}
# Routes that open a stream or a subscription (web/streams.py refuse_cross_site).
CROSS_SITE_ERRORS = {403: "cross_site (another site's page, Sec-Fetch-Site: cross-site, while sign-in is off: "
                          "nothing is opened)"}
BODY_ERRORS = {413: "request_entity_too_large", 415: "unsupported_media_type"}


def obj(properties: dict[str, Any] | None = None, required: tuple[str, ...] = (), *,
        closed: bool = True, **extra: Any) -> dict:
    """A JSON object schema; closed (no other keys) because the routes refuse unknown keys."""
    schema: dict[str, Any] = {"type": "object", "properties": properties or {}}
    if required:
        schema["required"] = list(required)
    if closed:
        schema["additionalProperties"] = False
    schema.update(extra)
    return schema


def query(name: str, schema: dict, description: str = "", *, required: bool = False) -> dict:
    return {"name": name, "in": "query", "required": required, "schema": schema, "description": description}


def path(name: str, schema: dict, description: str = "") -> dict:
    return {"name": name, "in": "path", "required": True, "schema": schema, "description": description}


def header(name: str, schema: dict, description: str = "") -> dict:
    return {"name": name, "in": "header", "required": False, "schema": schema, "description": description}


def op(summary: str, *, tag: str, ok: dict | None = None, status: int = 200, media: str = JSON,
       body: dict | None = None, body_required: bool = True, form: dict | None = None,
       params: list[dict] | tuple = (), errors: dict[int, str] | None = None, public: bool = False,
       role: str = "viewer", description: str = "", fuzz: str = "yes", fuzz_why: str = "",
       extra: dict[str, Any] | None = None, cross_site: bool | None = None) -> dict:
    """One operation. `errors` maps each 4xx/5xx status the view itself may answer to its error codes.

    `role` is the least role the route needs when sign-in is on (rover_web/auth/policy.py decides;
    this only documents it); `public` routes need no sign-in at all. `fuzz` tells the fuzz test
    (tests/integration/apidocs/test_fuzz.py) what to do: "yes", "last" (a second phase, for calls
    that would stop the rest from being tested) or "skip", each but "yes" with `fuzz_why`.
    `cross_site`: the route opens a stream or subscription and so refuses another site's page
    (403 cross_site); every stream (`x-stream`) does.
    """
    if (extra or {}).get("x-stream") and fuzz == "yes":
        fuzz, fuzz_why = "skip", "an endless response; its query checks have their own tests"
    if fuzz != "yes" and not fuzz_why:
        raise ValueError(f"{summary!r}: say why it is fuzzed {fuzz!r} (fuzz_why)")
    responses: dict[str, Any] = {str(status): {"description": "success",
                                               "content": {media: {"schema": ok if ok is not None else {}}}}}
    if cross_site is None:
        cross_site = bool((extra or {}).get("x-stream"))
    all_errors = dict(GUARD_ERRORS)
    for part in ({} if public else SIGNED_IN_ERRORS, errors or {}, CROSS_SITE_ERRORS if cross_site else {}):
        for code, codes in part.items():
            all_errors[code] = f"{all_errors[code]}, {codes}" if code in all_errors else codes
    for code, codes in sorted(all_errors.items()):
        responses[str(code)] = {"description": codes, "content": {JSON: {"schema": ERROR_REF}}}
    operation: dict[str, Any] = {"summary": summary, "tags": [tag], "responses": responses,
                                 "x-role": None if public else role, "x-fuzz": fuzz}
    if fuzz_why:
        operation["x-fuzz-why"] = fuzz_why
    if description:
        operation["description"] = description
    if params:
        operation["parameters"] = list(params)
    if body is not None or form is not None:
        content = {}
        if body is not None:
            content[JSON] = {"schema": body}
        if form is not None:
            content["application/x-www-form-urlencoded"] = {"schema": form}
        operation["requestBody"] = {"required": body_required, "content": content}
    if public:
        operation["security"] = []
    operation.update(extra or {})
    return operation


def page(summary: str, *, tag: str, params: list[dict] | tuple = (), errors: dict[int, str] | None = None,
         public: bool = False) -> dict:
    """An HTML page: described so the URL map check sees it, not for clients to call."""
    return op(summary, tag=tag, ok={"type": "string"}, media="text/html", params=params, errors=errors,
              public=public, extra={"x-page": True})
