"""GET /tiles/<z>/<x>/<y>: a tile of the installed store, 404 for any tile it does not hold.
GET /basemap/<name>: a drawn basemap of ROVER_WEB_MAP_GEOJSON_DIR, checked, 404 otherwise."""

from __future__ import annotations

from flask import Blueprint, Response, current_app, jsonify

from rover_web.web.http import error_response

from .features import feature_folder
from .source import installed_store
from .tile_store import MEDIA_TYPES, TileStoreError, valid_tile

bp = Blueprint("tiles", __name__)


@bp.get("/tiles/<int:z>/<int:x>/<int:y>")
def tile(z: int, x: int, y: int):
    store = installed_store(current_app.config) if valid_tile(z, x, y) else None
    if store is None:
        return Response(status=404)
    try:
        found = store.get(z, x, y)
    except TileStoreError as exc:
        current_app.logger.warning("tile %s/%s/%s: %s", z, x, y, exc)
        found = None
    finally:
        store.close()
    if found is None:
        return Response(status=404)
    data, fmt = found
    response = Response(data, mimetype=MEDIA_TYPES.get(fmt, "application/octet-stream"))
    response.headers["Cache-Control"] = "public, max-age=3600"
    return response


@bp.get("/basemap/<name>")
def features(name: str):
    found = feature_folder(current_app.config)
    collection = found.get(name) if found is not None else None
    if collection is None:
        return error_response(404, "unknown_basemap", "no drawn basemap named %(name)s", name=repr(name[:64]))
    response = jsonify(collection)
    response.mimetype = "application/geo+json"
    response.headers["Cache-Control"] = "no-cache"
    return response
