"""GET /api/openapi.json describes exactly the app's routes, and is a valid OpenAPI 3.1 document."""

from openapi_spec_validator import validate

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
