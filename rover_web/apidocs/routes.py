"""GET /api/openapi.json and the /api/docs page that renders it."""

from __future__ import annotations

from flask import Blueprint, current_app, jsonify, render_template

from .document import build

bp = Blueprint("apidocs", __name__)
_CACHE_KEY = "rover_web.openapi"  # the URL map is fixed once the app serves, so build once per app


@bp.get("/api/openapi.json")
def openapi_json():
    document = current_app.extensions.get(_CACHE_KEY)
    if document is None:
        document = current_app.extensions[_CACHE_KEY] = build(current_app)
    return jsonify(document)


@bp.get("/api/docs")
def docs_page():
    return render_template("api_docs.html")
