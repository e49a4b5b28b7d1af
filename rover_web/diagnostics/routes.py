"""GET /diagnostics (the page) and GET /api/diagnostics."""

from __future__ import annotations

from flask import Blueprint, jsonify, render_template

from rover_web.core.state import current_feature

from .service import Diagnostics

bp = Blueprint("diagnostics", __name__)


@bp.get("/api/diagnostics")
def api_diagnostics():
    return jsonify(current_feature(Diagnostics).snapshot())


@bp.get("/diagnostics")
def diagnostics_page():
    return render_template("diagnostics.html", diagnostics=current_feature(Diagnostics).snapshot())
