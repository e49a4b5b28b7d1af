"""GET /api/light_sequence, and the panel's `stc_clock` template filter."""

from __future__ import annotations

import time

from flask import Blueprint, jsonify

from rover_web.core.state import current_feature

from .service import ScanTheCodeService

bp = Blueprint("scan_the_code", __name__)


@bp.get("/api/light_sequence")
def light_sequence():
    return jsonify(current_feature(ScanTheCodeService).snapshot())


@bp.app_template_filter("stc_clock")
def clock_time(epoch_s: float | None) -> str:
    """Wall-clock time of day for the panel, as the server renders it before any event arrives."""
    return "—" if epoch_s is None else time.strftime("%H:%M:%S", time.localtime(epoch_s))
