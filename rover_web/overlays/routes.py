"""GET /api/overlays: each LiveMap overlay's topics and message counts, and the robot's recent path."""

from __future__ import annotations

from flask import Blueprint, jsonify

from rover_web.core.state import current_feature

from .service import OverlayService

bp = Blueprint("overlays", __name__)


@bp.get("/api/overlays")
def overlays():
    return jsonify(current_feature(OverlayService).summary())


@bp.app_context_processor
def layers_context() -> dict:
    """`overlay_layers()` for the map page's layer list (each layer's name, label and topics); a
    function, so other pages pay nothing for it."""
    return {"overlay_layers": lambda: current_feature(OverlayService).layers()}
