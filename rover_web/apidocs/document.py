"""The OpenAPI 3.1 document: every feature's part (its package's openapi.py), merged. Pure Python.

A part is found from the URL map: a route whose view lives in rover_web/<pkg>/... is described by
rover_web/<pkg>/openapi.py (PATHS). So a new feature adds its openapi.py next to its routes.py and
nothing here changes; tests/integration/apidocs/test_openapi.py fails while a route is undescribed.
"""

from __future__ import annotations

import copy
import importlib
import re
from typing import Any

from flask import Flask

from .describe import ERROR_REF

UNDESCRIBED_ENDPOINTS = frozenset({"static"})  # files, not an API
_CONVERTER = re.compile(r"<(?:(\w+)(?:\([^)]*\))?:)?(\w+)>")
PATH_SCHEMAS = {
    "int": {"type": "integer", "minimum": 0},
    "path": {"type": "string", "minLength": 1},
    "default": {"type": "string", "minLength": 1, "pattern": "^[^/]+$"},
}


def openapi_path(rule: str) -> str:
    """/api/tokens/<int:token_id> → /api/tokens/{token_id}"""
    return _CONVERTER.sub(lambda m: "{" + m.group(2) + "}", rule)


def path_converters(rule: str) -> dict[str, str]:
    return {m.group(2): m.group(1) or "default" for m in _CONVERTER.finditer(rule)}


def part_modules(app: Flask) -> list[str]:
    """The openapi modules of the packages that own the app's views, in URL-map order."""
    names: list[str] = []
    for rule in app.url_map.iter_rules():
        if rule.endpoint in UNDESCRIBED_ENDPOINTS:
            continue
        package = app.view_functions[rule.endpoint].__module__.rsplit(".", 1)[0]
        if f"{package}.openapi" not in names:
            names.append(f"{package}.openapi")
    return names


def _fill_path_parameters(paths: dict[str, Any], app: Flask) -> None:
    converters = {openapi_path(r.rule): path_converters(r.rule) for r in app.url_map.iter_rules()}
    for key, item in paths.items():
        for method, operation in item.items():
            given = {p["name"] for p in operation.get("parameters", []) if p["in"] == "path"}
            for name, conv in converters.get(key, {}).items():
                if name not in given:
                    operation.setdefault("parameters", []).insert(0, {
                        "name": name, "in": "path", "required": True,
                        "schema": dict(PATH_SCHEMAS.get(conv, PATH_SCHEMAS["default"]))})
            if method in ("post", "put", "patch"):
                for code, what in ((413, "request_entity_too_large"), (415, "unsupported_media_type")):
                    operation["responses"].setdefault(str(code), {
                        "description": what, "content": {"application/json": {"schema": ERROR_REF}}})


def build(app: Flask, parts: list[str] | None = None) -> dict[str, Any]:
    paths: dict[str, Any] = {}
    for name in parts if parts is not None else part_modules(app):
        try:
            module = importlib.import_module(name)
        except ModuleNotFoundError as exc:
            if exc.name != name:
                raise
            continue  # the URL-map test names the routes left undescribed
        for key, item in module.PATHS.items():
            for method, operation in item.items():
                if method in paths.get(key, {}):
                    raise ValueError(f"{method.upper()} {key} is described twice (again in {name})")
                paths.setdefault(key, {})[method] = copy.deepcopy(operation)
    _fill_path_parameters(paths, app)
    rover = app.extensions.get("rover_web")
    names = rover.fleet.names if rover is not None and rover.fleet is not None else ["robot"]
    return {
        "openapi": "3.1.0",
        "info": {
            "title": "rover_web",
            "version": "1",
            "description": "The HTTP API of rover_web, a web GUI for ROS 2 robots. Every error is "
                           "`{\"error\": code, \"message\": text}`. See docs/api.md.",
        },
        # Every path is also served for each robot under /robots/<name> (docs/fleet.md).
        "servers": [{"url": "/", "description": "the first robot"},
                    {"url": "/robots/{robot}", "description": "one robot of ROVER_WEB_ROBOTS",
                     "variables": {"robot": {"default": names[0], "enum": names}}}],
        "security": [{"bearerToken": []}, {"sessionCookie": []}],
        "paths": dict(sorted(paths.items())),
        "components": {
            "securitySchemes": {
                "bearerToken": {"type": "http", "scheme": "bearer",
                                "description": "an API token (`flask tokens add`, POST /api/tokens)"},
                "sessionCookie": {"type": "apiKey", "in": "cookie", "name": "session",
                                  "description": "the cookie POST /login sets"},
            },
            "schemas": {
                "Error": {"type": "object", "required": ["error", "message"],
                          "properties": {"error": {"type": "string", "description": "short machine-readable code"},
                                         "message": {"type": "string", "description": "what to fix"}}},
            },
        },
    }
