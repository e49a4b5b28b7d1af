"""Nav2's routes: GET /api/nav2, POST /api/nav2/goal, /api/nav2/route and /api/nav2/cancel."""

from __future__ import annotations

from flask import Blueprint, jsonify, request

from rover_web.auth import on_revoke, signed_in_name
from rover_web.core.state import current_feature
from rover_web.geofence import OutsideGeofence
from rover_web.livemap.keep_out import check_goal
from rover_web.livemap.routes import answer_map_errors
from rover_web.livemap.service import LiveMapService, OutsideMap, check_on_map
from rover_web.web.api_messages import explain, text_of
from rover_web.web.http import ApiError, error_response, json_body
from rover_web.web.validate import InvalidInput, number, only_keys, text

from .service import GoalRejected, Nav2Service, Nav2Unavailable, NoGoal, ShuttingDown

bp = Blueprint("nav2", __name__)

ROUTE_MODES = {"through_poses": "through_poses", "follow_waypoints": "follow_waypoints"}


@bp.errorhandler(Nav2Unavailable)
def unavailable(exc: Nav2Unavailable):
    return error_response(503, exc.code, text_of(exc))


@bp.errorhandler(GoalRejected)
def rejected(exc: GoalRejected):
    return error_response(409, "goal_rejected", text_of(exc))


@bp.errorhandler(NoGoal)
def no_goal(exc: NoGoal):
    return error_response(409, "no_goal", text_of(exc))


@bp.errorhandler(ShuttingDown)
def shutting_down(exc: ShuttingDown):
    return error_response(503, "shutting_down", text_of(exc))


answer_map_errors(bp)  # a goal or route point off the map or in a keep-out area, as LiveMap answers it


def _sender() -> str:
    return signed_in_name() or request.remote_addr or "unknown"


def _pose(item, where: str) -> tuple[float, float, float]:
    if not isinstance(item, dict):
        raise InvalidInput("%(where)s must be an object {\"x\": ..., \"y\": ..., \"yaw\": ...}", "bad_type",
                           where=where)
    only_keys(item, {"x", "y", "yaw"})
    try:
        return number(item, "x"), number(item, "y"), number(item, "yaw", default=0.0)
    except InvalidInput as exc:
        raise InvalidInput("%(where)s: %(why)s", exc.code, where=where, why=text_of(exc)) from None


def _checked(map_name: str | None, poses: list[tuple[float, float, float]]) -> str:
    """Every pose on the map and outside its keep-out areas, before anything is sent; the map's name."""
    livemap = current_feature(LiveMapService)
    name = map_name or livemap.default_name
    if name is None:
        raise ApiError(400, "missing_field", "'map' is required: no default map is configured")
    definition = livemap.get(name)
    for i, (x, y, _) in enumerate(poses):
        try:
            check_on_map(definition, x, y)
            check_goal(definition.keep_out, definition.name, x, y)
        except OutsideGeofence as exc:
            exc.details["index"] = i
            raise
        except OutsideMap as exc:
            if len(poses) > 1:
                raise OutsideMap(explain("pose %(i)s: %(why)s", i=i, why=text_of(exc))) from None
            raise
    return definition.name


@bp.app_context_processor
def panel_context() -> dict:
    """`nav2_panel` for LiveMap's page (templates/partials/nav2_panel.html): the state GET /api/nav2 answers."""
    if request.endpoint != "livemap.livemap_page":
        return {}
    service = current_feature(Nav2Service)
    service.client()  # an operator is looking: discovery of Nav2's servers starts now
    return {"nav2_panel": service.state()}


@bp.get("/api/nav2")
def nav2_state():
    service = current_feature(Nav2Service)
    service.client()  # discovery of Nav2's servers starts with the first look
    return jsonify(service.state())


@bp.post("/api/nav2/goal")
def post_goal():
    service = current_feature(Nav2Service)
    service.client()
    body = json_body()
    try:
        only_keys(body, {"map", "x", "y", "yaw"})
        map_name = text(body, "map", max_len=200, default=None)
        pose = _pose({k: v for k, v in body.items() if k != "map"}, "the goal")
    except InvalidInput as exc:
        raise ApiError(400, exc.code, text_of(exc)) from None
    if service.missing is not None:  # after the body check: a bad request is told what is wrong with it first
        raise Nav2Unavailable("nav2_unavailable", service.missing_text)
    name = _checked(map_name, [pose])
    goal = service.send("to_pose", [pose], map_name=name, by=_sender(), watch=on_revoke)
    return jsonify(status="sent", goal=goal)


@bp.post("/api/nav2/route")
def post_route():
    service = current_feature(Nav2Service)
    service.client()
    body = json_body()
    try:
        only_keys(body, {"map", "mode", "poses"})
        map_name = text(body, "map", max_len=200, default=None)
        mode = text(body, "mode", choices=tuple(ROUTE_MODES))
        raw = body.get("poses")
        if not isinstance(raw, list) or not 1 <= len(raw) <= service.max_poses:
            raise InvalidInput("'poses' must be an array of 1 to %(max_poses)s poses",
                               "missing_field" if raw is None else "bad_value", max_poses=service.max_poses)
        poses = [_pose(item, f"poses[{i}]") for i, item in enumerate(raw)]
    except InvalidInput as exc:
        raise ApiError(400, exc.code, text_of(exc)) from None
    if service.missing is not None:
        raise Nav2Unavailable("nav2_unavailable", service.missing_text)
    name = _checked(map_name, poses)
    goal = service.send(ROUTE_MODES[mode], poses, map_name=name, by=_sender(), watch=on_revoke)
    return jsonify(status="sent", goal=goal)


@bp.post("/api/nav2/cancel")
def post_cancel():
    service = current_feature(Nav2Service)
    body = json_body(required=False)
    try:
        only_keys(body or {}, set())
    except InvalidInput as exc:
        raise ApiError(400, exc.code, text_of(exc)) from None
    if service.missing is not None:
        raise Nav2Unavailable("nav2_unavailable", service.missing_text)
    goal = service.cancel_active("operator", f"canceled by {_sender()}")
    if goal is None:
        raise NoGoal(explain("no Nav2 goal sent from here is running"))
    return jsonify(status="canceling", goal=goal)
