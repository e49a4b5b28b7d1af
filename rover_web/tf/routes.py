"""GET /tf (the page), GET /api/tf (the tree) and GET /api/tf/lookup (one transform, or tf2's reason)."""

from __future__ import annotations

import math

from flask import Blueprint, jsonify, render_template, request

from rover_web.core.state import current_feature
from rover_web.web.http import ApiError

from .buffer import TfError
from .service import TfService

bp = Blueprint("tf", __name__)

MAX_FRAME_ID = 256
# tf2's reasons as HTTP: a malformed question is 400, a frame never heard 404, a tree that cannot
# answer it now (apart, or no data at that time) 409.
STATUS = {"invalid": 400, "unknown_frame": 404, "not_connected": 409, "extrapolation_past": 409,
          "extrapolation_future": 409}


@bp.get("/api/tf")
def api_tf():
    return jsonify(current_feature(TfService).tree())


def _frame_arg(name: str) -> str:
    value = request.args.get(name, "")
    if not value:
        raise ApiError(400, "missing_frame", f"{name} is required: a frame id such as map or base_link")
    if len(value) > MAX_FRAME_ID or not value.isprintable():
        raise ApiError(400, "bad_frame", f"{name} must be a printable frame id of at most {MAX_FRAME_ID} characters")
    return value


def _time_arg() -> int | None:
    raw = request.args.get("time", "")
    if raw == "":
        return None
    try:
        seconds = float(raw)
    except ValueError:
        raise ApiError(400, "bad_time", f"time must be seconds (a number), got {raw[:40]!r}") from None
    if not math.isfinite(seconds) or seconds < 0 or seconds > 1e10:
        raise ApiError(400, "bad_time", "time must be 0 (the latest common time) or seconds since the epoch")
    return round(seconds * 1e9)


def transform_json(tf, target: str, source: str) -> dict:
    return {"target": target, "source": source, "translation": list(tf.translation),
            "rotation": list(tf.rotation), "yaw": tf.yaw, "stamp": tf.stamp_ns / 1e9, "stamp_ns": tf.stamp_ns}


@bp.get("/api/tf/lookup")
def api_tf_lookup():
    target, source, stamp = _frame_arg("target"), _frame_arg("source"), _time_arg()
    service = current_feature(TfService)
    try:
        tf = service.buffer.lookup(target, source, stamp)
    except TfError as exc:
        if not service.available and exc.kind == "unknown_frame":
            raise ApiError(503, "tf_unavailable", service.missing) from None
        response = jsonify(error=exc.kind, message=exc.message, detail=exc.detail)
        response.status_code = STATUS.get(exc.kind, 400)
        return response
    return jsonify(transform_json(tf, target, source))


@bp.get("/tf")
def tf_page():
    return render_template("tf.html", tf=current_feature(TfService).tree())
