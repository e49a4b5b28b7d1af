"""LiveMap's pages (/livemap, /livemap/<name>) and API (/api/maps...), and the dashboard card's context."""

from __future__ import annotations

import hashlib
from urllib.parse import quote

from flask import Blueprint, Response, abort, jsonify, redirect, render_template, request, url_for
from flask_babel import gettext

from rover_web.core.state import current_feature
from rover_web.geofence import OutsideGeofence, outside_geofence_response
from rover_web.web.api_messages import text_of
from rover_web.web.http import ApiError, error_response, json_body
from rover_web.web.validate import InvalidInput, number, only_keys

from . import initial_pose
from .map_files import MapDefinition
from .service import LIVE_MAP_NAME, LiveMapService, OutsideMap, ShuttingDown
from .state import UnknownMap, goal_payload

bp = Blueprint("livemap", __name__)


def answer_map_errors(blueprint: Blueprint) -> None:
    """A pose refused by a floorplan, answered the same by every blueprint that checks one (nav2's too)."""
    blueprint.register_error_handler(UnknownMap, lambda exc: error_response(404, "unknown_map", text_of(exc)))
    blueprint.register_error_handler(OutsideMap, lambda exc: error_response(400, "outside_map", text_of(exc)))
    blueprint.register_error_handler(OutsideGeofence, outside_geofence_response)


answer_map_errors(bp)


@bp.errorhandler(ShuttingDown)
def shutting_down(exc: ShuttingDown):
    return error_response(503, "stopping", text_of(exc))


def map_summary(definition: MapDefinition) -> dict:
    g = definition.geometry
    quoted = quote(definition.name, safe="")
    version = f"?v={definition.version}" if definition.source == "live" else ""
    root = request.script_root
    return {
        "name": definition.name, "label": definition.label, "source": definition.source,
        "version": definition.version,
        "width_px": g.width_px, "height_px": g.height_px, "resolution_m": g.resolution_m,
        "cm_per_pixel": g.cm_per_pixel, "width_m": round(g.width_m, 6), "height_m": round(g.height_m, 6),
        "origin": [g.origin_x, g.origin_y, g.origin_yaw], "waypoint_count": len(definition.waypoints),
        "keep_out": [a.as_dict() for a in definition.keep_out],
        # Under the robot's prefix (/robots/<name>): a live map is that robot's own.
        "urls": {"state": f"{root}/api/maps/{quoted}", "image": f"{root}/api/maps/{quoted}/image{version}",
                 "thumbnail": f"{root}/api/maps/{quoted}/thumbnail{version}", "page": f"{root}/livemap/{quoted}",
                 "goal": f"{root}/api/maps/{quoted}/goal",
                 "initial_pose": f"{root}/api/maps/{quoted}/initial_pose"},
    }


def png_response(data: bytes) -> Response:
    response = Response(data, mimetype="image/png")
    response.set_etag(hashlib.sha1(data).hexdigest())
    response.headers["Cache-Control"] = "no-cache"  # revalidate: a live map changes under the same URL
    return response.make_conditional(request)


@bp.app_context_processor
def panel_context() -> dict:
    """`livemap_panel` for the dashboard card: the default map and the last pose."""
    feature = current_feature(LiveMapService)
    if feature.default_name is None:
        return {"livemap_panel": None}
    try:
        definition = feature.get(feature.default_name)
    except UnknownMap:
        return {"livemap_panel": {"map": None, "pose": None}}
    return {"livemap_panel": {"map": map_summary(definition), "pose": feature.rover.hub.latest("pose")}}


# --- pages ---


@bp.get("/livemap")
def livemap_index():
    feature = current_feature(LiveMapService)
    if feature.default_name is None or (feature.default_name == LIVE_MAP_NAME and feature.live is None):
        return render_template("livemap.html", page=None, maps=[map_summary(d) for d in feature.maps()])
    return redirect(url_for("livemap.livemap_page", name=feature.default_name))


@bp.get("/livemap/<name>")
def livemap_page(name: str):
    feature = current_feature(LiveMapService)
    try:
        live = feature.live_map(name, None)
    except UnknownMap:
        abort(404, description=gettext("There is no map named %(name)s.", name=repr(name[:80])))
    page = {
        "map": map_summary(live.definition),
        "map_state": live.map_state,
        "maps": [map_summary(d) for d in feature.maps()],
        "pose": feature.rover.hub.latest("pose"),
        "goal": feature.rover.hub.latest("goal"),
        "plan": feature.track.plan(),
        "pose_stale_s": feature.track.stale_after_s,
        "goal_topic": feature.goal_topic,
        "initial_pose_topic": feature.initial_pose_topic,
    }
    return render_template("livemap.html", page=page, maps=page["maps"])


# --- API ---


@bp.get("/api/maps")
def list_maps():
    feature = current_feature(LiveMapService)
    return jsonify(maps=[map_summary(d) for d in feature.maps()], default=feature.default_name)


@bp.get("/api/maps/<name>")
def map_state(name: str):
    feature = current_feature(LiveMapService)
    feature.get(name)  # 404 before looking at the query
    raw = request.args.get("cm_per_pixel")
    cm_per_pixel = None
    if raw is not None:
        try:
            cm_per_pixel = float(raw)
        except ValueError:
            raise ApiError(400, "bad_type", "cm_per_pixel must be a number, got %(raw)s", raw=repr(raw[:40])) from None
    try:
        live = feature.live_map(name, cm_per_pixel)
    except ValueError as exc:
        raise ApiError(400, "out_of_range", text_of(exc)) from None
    return jsonify(live.map_state)


@bp.get("/api/maps/<name>/image")
def map_image(name: str):
    return png_response(current_feature(LiveMapService).get(name).png())


@bp.get("/api/maps/<name>/thumbnail")
def map_thumbnail(name: str):
    return png_response(current_feature(LiveMapService).get(name).thumbnail())


@bp.post("/api/maps/<name>/goal")
def post_goal(name: str):
    feature = current_feature(LiveMapService)
    definition = feature.get(name)
    body = json_body()
    try:
        only_keys(body, {"x", "y", "yaw"})
        x = number(body, "x")
        y = number(body, "y")
        yaw = number(body, "yaw", default=0.0)
    except InvalidInput as exc:
        raise ApiError(400, exc.code, text_of(exc)) from None
    goal = feature.send_goal(definition, x, y, yaw)
    payload = goal_payload(goal, [definition])
    return jsonify(status="sent", topic=feature.goal_topic, goal=payload)


@bp.post("/api/maps/<name>/initial_pose")
def post_initial_pose(name: str):
    feature = current_feature(LiveMapService)
    definition = feature.get(name)
    body = json_body()
    try:
        x, y, yaw, covariance = initial_pose.parse(body)
    except InvalidInput as exc:
        raise ApiError(400, exc.code, text_of(exc)) from None
    sent = feature.send_initial_pose(definition, x, y, yaw, covariance)
    return jsonify(status="sent", topic=feature.initial_pose_topic, initial_pose=sent)
