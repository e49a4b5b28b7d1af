"""The API's own description: GET /api/openapi.json (OpenAPI 3.1) and the /api/docs page.

Each feature describes its routes in its package's openapi.py; document.py merges them
(docs/api.md says how to describe a new route).
"""

from __future__ import annotations

from flask import Flask

from rover_web.core.state import Rover


def init_app(app: Flask, rover: Rover) -> None:
    from . import routes

    app.register_blueprint(routes.bp)
