"""The hub's routes: the fleet page and API fed from Zenoh, and the signed stop-all."""

from __future__ import annotations

from flask import Blueprint, current_app, jsonify, redirect, render_template, request

from rover_web.auth import signed_in_name
from rover_web.basemap.source import map_view
from rover_web.core.state import current_feature
from rover_web.web.http import ApiError, json_body
from rover_web.web.validate import InvalidInput, only_keys, text

bp = Blueprint("hub", __name__)

NAME_MAX_LEN = 40


def _hub():
    from . import FleetHub

    return current_feature(FleetHub)


def _state() -> dict:
    hub = _hub()
    return {"hub": True, "fleet": hub.fleet, "robots": hub.directory.robots(), "last_stop": hub.stop_all.last}


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
    lines = hub.directory.robots()
    return jsonify({"hub": True, "fleet": hub.fleet, "robots": len(lines),
                    "live": sum(1 for line in lines if line["heard"] == "live"),
                    "forged_summaries": hub.directory.forged})


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
        raise ApiError(400, exc.code, str(exc)) from None
    who = signed_in_name() or by or request.remote_addr or "unknown"
    hub = _hub()
    return jsonify(hub.stop_all.stop(hub.directory.names(), who[:NAME_MAX_LEN]))


@bp.get("/api/openapi.json")
def openapi_json():
    from rover_web.apidocs.document import build

    return jsonify(build(current_app))
