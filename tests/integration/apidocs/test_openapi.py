"""GET /api/openapi.json describes exactly the app's routes, and is a valid OpenAPI 3.1 document."""

import re
from pathlib import Path

import requests
from openapi_spec_validator import validate

import rover_web
from rover_web.apidocs.document import UNDESCRIBED_ENDPOINTS, openapi_path

IGNORED_METHODS = {"HEAD", "OPTIONS"}  # Werkzeug answers these for every GET route by itself


def routes(app) -> set[tuple[str, str]]:
    return {(method.lower(), openapi_path(rule.rule)) for rule in app.url_map.iter_rules()
            if rule.endpoint not in UNDESCRIBED_ENDPOINTS for method in rule.methods - IGNORED_METHODS}


def described(document) -> set[tuple[str, str]]:
    return {(method, path) for path, item in document["paths"].items() for method in item}


def test_every_route_is_described_and_nothing_else(app, client):
    document = client.get("/api/openapi.json").get_json()
    assert routes(app) - described(document) == set(), "routes without a description in their package's openapi.py"
    assert described(document) - routes(app) == set(), "described operations the app does not have"


def test_a_route_added_without_a_description_fails_the_check(app, client):
    app.add_url_rule("/api/undescribed", "undescribed", lambda: "")
    document = client.get("/api/openapi.json").get_json()
    assert ("get", "/api/undescribed") in routes(app) - described(document)


def test_the_document_is_valid_openapi_3_1(client):
    document = client.get("/api/openapi.json").get_json()
    assert document["openapi"].startswith("3.1")
    validate(document)


def test_every_operation_describes_the_error_object_and_its_path_parameters(client):
    document = client.get("/api/openapi.json").get_json()
    for path, item in document["paths"].items():
        for method, operation in item.items():
            where = f"{method.upper()} {path}"
            errors = [r for status, r in operation["responses"].items() if status.startswith(("4", "5"))]
            assert errors, where
            for response in errors:
                assert response["content"]["application/json"]["schema"] == {"$ref": "#/components/schemas/Error"}
            names = {p["name"] for p in operation.get("parameters", []) if p["in"] == "path"}
            assert names == {part[1:-1] for part in path.split("/") if part.startswith("{")}, where
            if method in ("post", "put", "patch"):
                assert {"413", "415"} <= set(operation["responses"]), where


def test_sign_in_and_public_routes_are_stated(client):
    document = client.get("/api/openapi.json").get_json()
    schemes = document["components"]["securitySchemes"]
    assert schemes["bearerToken"]["scheme"] == "bearer" and schemes["sessionCookie"]["in"] == "cookie"
    assert document["paths"]["/login"]["post"]["security"] == []
    assert "security" not in document["paths"]["/api/estop"]["post"]  # the document's default: signed in


def error_codes(description: str) -> set[str]:
    """The error codes an error response's description names: the leading word of each
    comma-separated part outside parentheses ("forbidden (the role is too low), foreign_origin")."""
    parts, depth, current = [], 0, ""
    for char in description:
        depth += {"(": 1, ")": -1}.get(char, 0)
        if char == "," and depth == 0:
            parts.append(current)
            current = ""
        else:
            current += char
    parts.append(current)
    return {m.group(0) for part in parts if (m := re.match(r"[a-z][a-z0-9]*(?:_[a-z0-9]+)*\b(?![ -][a-z])",
                                                              part.strip()))}


def returned_codes() -> str:
    """Every quoted string in the app's code, outside the documents that describe it."""
    root = Path(rover_web.__file__).parent
    return "\n".join(p.read_text() for p in root.rglob("*.py") if p.name != "openapi.py" and p.parent.name != "apidocs")


# Codes the code builds rather than spells: logs/routes.py's f"bad_{key}", and the name of
# Werkzeug's 404 that web/http.py answers in the API's shape.
BUILT_CODES = {"bad_node", "bad_contains", "not_found"}


def test_every_error_code_the_document_names_is_one_the_code_returns(client):
    """A code listed but never returned (weak_password for bad_password, a last_admin rule that
    does not exist) sends a client's error handling after something that never comes."""
    document = client.get("/api/openapi.json").get_json()
    source = returned_codes()
    missing = set()
    for path, item in document["paths"].items():
        for method, operation in item.items():
            for status, response in operation["responses"].items():
                if status.startswith(("4", "5")):
                    missing |= {(f"{method.upper()} {path}", code) for code in error_codes(response["description"])
                                if code not in BUILT_CODES and f'"{code}"' not in source and f"'{code}'" not in source}
    assert missing == set(), sorted(missing)


# Each route that opens a stream or a subscription, with what it needs to get that far.
OPENS = {
    "/api/events": "/api/events?channels=status",
    "/api/topics/echo": "/api/topics/echo?topic=/doc_echo&type=std_msgs/msg/String",
    "/stream": "/stream?topic=/doc_camera&type=sensor_msgs/msg/Image",
    "/snapshot": "/snapshot?topic=/doc_camera&type=sensor_msgs/msg/Image",
    "/api/plot": "/api/plot?topic=/doc_plot&type=std_msgs/msg/Float64&field=data",
    "/api/actions/{goal_id}/events": "/api/actions/0123456789abcdef0123456789abcdef/events",
    "/ws/teleop": "/ws/teleop",
}
CROSS_SITE = {"Sec-Fetch-Site": "cross-site", "Sec-Fetch-Mode": "no-cors"}
UPGRADE = {"Connection": "Upgrade", "Upgrade": "websocket", "Sec-WebSocket-Version": "13",
           "Sec-WebSocket-Key": "dGhlIHNhbXBsZSBub25jZQ=="}


def test_the_cross_site_refusal_of_every_route_that_opens_a_stream_is_described(live_server):
    document = requests.get(live_server.url + "/api/openapi.json", timeout=10).json()
    for path, url in OPENS.items():
        headers = {**CROSS_SITE, **(UPGRADE if path.startswith("/ws/") else {})}
        answer = requests.get(live_server.url + url, headers=headers, stream=True, timeout=10)
        assert (answer.status_code, answer.json()["error"]) == (403, "cross_site"), path
        assert "cross_site" in error_codes(document["paths"][path]["get"]["responses"]["403"]["description"]), path


def test_sign_in_needed_is_described_wherever_sign_in_is_checked(live_server):
    document = requests.get(live_server.url + "/api/openapi.json", timeout=10).json()
    # Under auto on loopback with no user, a proxied request is told to turn sign-in on.
    refused = requests.get(live_server.url + "/api/status", headers={"X-Forwarded-For": "10.0.0.1"}, timeout=10)
    assert (refused.status_code, refused.json()["error"]) == (403, "sign_in_needed")
    for path, item in document["paths"].items():
        for method, operation in item.items():
            if operation.get("security") != []:  # every route but the public ones
                assert "sign_in_needed" in error_codes(operation["responses"]["403"]["description"]), \
                    f"{method.upper()} {path}"
