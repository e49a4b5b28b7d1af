"""GET /api/overlays: each LiveMap overlay's topics and message counts, the robot's recent path and,
with ?costmaps=1, every costmap's cells."""

from __future__ import annotations

from flask import Blueprint, jsonify, request

from rover_web.core.state import current_feature
from rover_web.web.http import ApiError

from .service import OverlayService

bp = Blueprint("overlays", __name__)


@bp.get("/api/overlays")
def overlays():
    feature = current_feature(OverlayService)
    summary = feature.summary()
    raw = request.args.get("costmaps", "0")
    if raw not in ("0", "1"):
        raise ApiError(400, "bad_costmaps", "costmaps must be 0 or 1, got %(raw)s", raw=repr(raw[:20]))
    if raw == "1":
        summary["costmaps"] = feature.costmaps()
    return jsonify(summary)


@bp.app_context_processor
def layers_context() -> dict:
    """`overlay_layers()` for the map page's layer list (each layer's name, label and topics); a
    function, so other pages pay nothing for it."""
    return {"overlay_layers": lambda: current_feature(OverlayService).layers()}
