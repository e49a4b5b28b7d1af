"""This package's own routes, described like every other feature's (see describe.py)."""

from rover_web.apidocs.describe import obj, op, page

PATHS = {
    "/api/openapi.json": {"get": op("This description (OpenAPI 3.1)", tag="api", ok=obj(closed=False))},
    "/api/docs": {"get": page("The description rendered for people (Swagger UI, vendored)", tag="api")},
}
