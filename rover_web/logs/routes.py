"""GET /logs (the page) and GET /api/rosout (the ring, filtered)."""

from __future__ import annotations

from flask import Blueprint, jsonify, render_template, request

from rover_web.core.state import current_feature
from rover_web.web.api_messages import text_of
from rover_web.web.http import ApiError

from .ring import LEVELS, parse_level
from .service import RosoutLog

bp = Blueprint("logs", __name__)

DEFAULT_LIMIT = 200
MAX_TEXT = 200


def _query(args) -> dict:
    unknown = sorted(set(args) - {"level", "node", "contains", "limit"})
    if unknown:
        raise ApiError(
            400,
            "unknown_parameter",
            "unknown parameter %(unknown)s; use level, node, contains, limit",
            unknown=repr(unknown[0][:40]),
        )
    query = {"min_level": 0, "node": "", "contains": "", "limit": DEFAULT_LIMIT}
    if args.get("level"):
        try:
            query["min_level"] = parse_level(args["level"])
        except ValueError as exc:
            raise ApiError(400, "bad_level", text_of(exc)) from None
    for key in ("node", "contains"):
        value = args.get(key, "")
        if len(value) > MAX_TEXT:
            raise ApiError(400, "bad_" + key, "%(key)s is at most %(max_text)s characters", key=key, max_text=MAX_TEXT)
        query[key] = value
    if "limit" in args:
        keep = current_feature(RosoutLog).ring.keep
        raw = args["limit"]
        if not raw.isdigit() or not 1 <= int(raw) <= keep:
            raise ApiError(400, "bad_limit", "limit must be a whole number from 1 to %(keep)s, not %(raw)s",
                           keep=keep, raw=repr(raw[:20]))
        query["limit"] = int(raw)
    return query


@bp.get("/api/rosout")
def api_rosout():
    log = current_feature(RosoutLog)
    query = _query(request.args)
    lines, last_seq = log.ring.query_at(**query)
    return jsonify({"lines": lines, "last_seq": last_seq, "keep": log.ring.keep, "received": log.received,
                    **log.health()})


@bp.get("/logs")
def logs_page():
    log = current_feature(RosoutLog)
    return render_template("logs.html", lines=log.ring.query(limit=DEFAULT_LIMIT), levels=list(LEVELS),
                           keep=log.ring.keep)
