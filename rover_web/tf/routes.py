"""GET /tf (the page), GET /api/tf (the tree) and GET /api/tf/lookup (one transform, or tf2's reason)."""

from __future__ import annotations

import math

from flask import Blueprint, jsonify, render_template, request

from rover_web.core.state import current_feature
from rover_web.web.api_messages import Text
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


def frame_arg(name: str) -> str:
    value = request.args.get(name, "")
    if not value:
        raise ApiError(400, "missing_frame", "%(name)s is required: a frame id such as map or base_link", name=name)
    if len(value) > MAX_FRAME_ID or not value.isprintable():
        raise ApiError(400, "bad_frame", "%(name)s must be a printable frame id of at most %(max_frame_id)s "
                                         "characters",
                       name=name, max_frame_id=MAX_FRAME_ID)
    return value


def time_arg() -> int | None:
    raw = request.args.get("time", "")
    if raw == "":
        return None
    try:
        seconds = float(raw)
    except ValueError:
        raise ApiError(400, "bad_time", "time must be seconds (a number), got %(raw)s", raw=repr(raw[:40])) from None
    if not math.isfinite(seconds) or seconds < 0 or seconds > 1e10:
        raise ApiError(400, "bad_time", "time must be 0 (the latest common time) or seconds since the epoch")
    return round(seconds * 1e9)


def transform_json(tf, target: str, source: str) -> dict:
    return {"target": target, "source": source, "translation": list(tf.translation),
            "rotation": list(tf.rotation), "yaw": tf.yaw, "stamp": tf.stamp_ns / 1e9, "stamp_ns": tf.stamp_ns}


def lookup_response(buffer, missing_text: Text | None = None):
    """The answer to ?target=&source=&time= from `buffer`: the transform, or tf2's reason as a 4xx."""
    target, source, stamp = frame_arg("target"), frame_arg("source"), time_arg()
    try:
        tf = buffer.lookup(target, source, stamp)
    except TfError as exc:
        if missing_text and exc.kind == "unknown_frame":
            raise ApiError(503, "tf_unavailable", missing_text) from None
        response = jsonify(error=exc.kind, message=exc.text.translated(), detail=exc.detail)
        response.status_code = STATUS.get(exc.kind, 400)
        return response
    return jsonify(transform_json(tf, target, source))


@bp.get("/api/tf/lookup")
def api_tf_lookup():
    service = current_feature(TfService)
    return lookup_response(service.buffer, service.missing)


@bp.get("/tf")
def tf_page():
    return render_template("tf.html", tf=current_feature(TfService).tree())
