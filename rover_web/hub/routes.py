"""The hub's routes: the fleet page and API fed from Zenoh, and the signed stop-all."""

from __future__ import annotations

from flask import Blueprint, current_app, jsonify, redirect, render_template, request

from rover_web.auth import signed_in_name
from rover_web.basemap.source import map_view
from rover_web.core.state import current_feature
from rover_web.web.api_messages import text_of
from rover_web.web.http import ApiError, json_body
from rover_web.web.validate import InvalidInput, only_keys, text
from rover_web.zenoh_link.session import NAME

from .history import PAGE_MAX

bp = Blueprint("hub", __name__)

NAME_MAX_LEN = 40


def _hub():
    from . import FleetHub

    return current_feature(FleetHub)


def _state() -> dict:
    hub = _hub()
    directory = hub.directory
    return {"hub": True, "fleet": hub.fleet, "robots": directory.robots(), "last_stop": hub.stop_all.last,
            "forgotten": directory.recently_forgotten(), "forget_after_s": directory.forget_after_s}


@bp.get("/api/robots")
def robots():
    return jsonify(_state())


@bp.get("/")
def home():
    return redirect(request.script_root + "/robots")


@bp.get("/robots")
def robots_page():
    return render_template("hub.html", state=_state(), map_config=map_view(current_app.config))


@bp.get("/api/status")
def status():
    hub = _hub()
    directory = hub.directory
    counts = directory.counts()
    return jsonify({"hub": True, "fleet": hub.fleet, "robots": sum(counts.values()), **counts,
                    "forgotten": directory.forgotten_total, "forged_summaries": directory.forged,
                    "stale_summaries": directory.stale})


@bp.get("/api/robots/<name>/history")
def robot_history(name: str):
    """A robot's history, newest first; `before` (an id from `next_before`) pages back, `limit` ≤ 200."""
    hub = _hub()
    try:
        before = _int_arg("before", 1, 2**62)
        limit = _int_arg("limit", 1, PAGE_MAX)
    except InvalidInput as exc:
        raise ApiError(400, exc.code, text_of(exc)) from None
    if not NAME.match(name) or (name not in hub.directory.names() and not hub.history.known(name)):
        raise ApiError(404, "unknown_robot", "the hub has no robot %(name)s heard or in its history",
                       name=repr(name[:40]))
    return jsonify(hub.history.page(name, before=before, limit=limit or 50))


def _int_arg(key: str, low: int, high: int) -> int | None:
    raw = request.args.get(key)
    if raw is None:
        return None
    if not raw.isdigit() or len(raw) > 19 or not low <= int(raw) <= high:
        raise InvalidInput("%(key)s must be a whole number from %(low)s to %(high)s", "bad_value",
                           key=key, low=low, high=high)
    return int(raw)


@bp.post("/api/estop/all")
def estop_all():
    """Every robot heard, live or lost (a lost one may still hear us), is sent its own signed stop.

    Takes the bodies a robot's POST /api/estop/all takes; releasing is refused here too: a robot
    is released on its own rover_web, by someone who can see it."""
    body = json_body(required=False)
    try:
        only_keys(body, {"engaged", "by"})
        if body.get("engaged", True) is not True:
            raise ApiError(400, "release_per_robot", "the hub only stops: release each robot on its own rover_web "
                           "(POST {\"engaged\": false} to its /api/estop)")
        by = text(body, "by", max_len=NAME_MAX_LEN, default=None)
    except InvalidInput as exc:
        raise ApiError(400, exc.code, text_of(exc)) from None
    who = signed_in_name() or by or request.remote_addr or "unknown"
    return jsonify(_hub().stop_robots(who[:NAME_MAX_LEN]))


@bp.get("/api/openapi.json")
def openapi_json():
    from rover_web.apidocs.document import build

    return jsonify(build(current_app))
