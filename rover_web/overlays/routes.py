"""GET /api/overlays: each LiveMap overlay's topics and message counts, and the robot's recent path."""

from __future__ import annotations

from flask import Blueprint, jsonify

from rover_web.core.state import current_feature

from .service import OverlayService

bp = Blueprint("overlays", __name__)


@bp.get("/api/overlays")
def overlays():
    return jsonify(current_feature(OverlayService).summary())
