"""The waypoints pages and API; every refusal is a 4xx JSON body naming the problem."""

from __future__ import annotations

from flask import Blueprint, jsonify, render_template, request

from rover_web.auth import signed_in_name
from rover_web.core.state import current_feature, current_rover
from rover_web.geofence import OutsideGeofence, outside_geofence_response
from rover_web.storage.group_commit import CommitterStopped
from rover_web.web.api_messages import text_of
from rover_web.web.http import error_response, json_body
from rover_web.web.validate import InvalidInput, only_keys

from .geojson import MEDIA_TYPE, mission_to_geojson, waypoints_from_geojson
from .service import WaypointsService
from .store import EmptyMission, MissionFull, StaleRevision, WaypointNotFound, check_label, check_lat, check_lng

SQLITE_MAX_INT = (1 << 63) - 1

bp = Blueprint("waypoints", __name__)


@bp.after_request
def _audit_edit(response):
    # Every accepted change to the mission (add, move, delete, send, import) in one place, for
    # recordings (events/audit.py): the route and its answer say what was done.
    if request.method not in ("GET", "HEAD", "OPTIONS") and response.status_code < 400:
        by = signed_in_name() or request.remote_addr or "unknown"
        current_rover().audit.record(f"waypoints.{request.endpoint.rsplit('.', 1)[-1]}", by=by,
                                     detail=f"{request.method} {request.path}", status=response.status_code)
    return response


# --- input ---

def _position(body: dict) -> tuple[float, float]:
    for key in ("lng", "lat"):
        if key not in body:
            raise InvalidInput("'%(key)s' is required: send {\"lng\": <degrees east>, \"lat\": <degrees north>}",
                               "missing_field", key=key)
    return check_lng(body["lng"]), check_lat(body["lat"])


def _integer(body: dict, key: str, low: int = 0) -> int | None:
    if key not in body or body[key] is None:
        return None
    value = body[key]
    if isinstance(value, bool) or not isinstance(value, int):
        raise InvalidInput("'%(key)s' must be an integer, got %(type)s", "bad_type",
                           key=key, type=type(value).__name__)
    if value < low:
        raise InvalidInput("'%(key)s' must be at least %(low)s", "out_of_range", key=key, low=low)
    return value


def _waypoint_id(waypoint_id: int) -> int:
    if waypoint_id > SQLITE_MAX_INT:
        raise WaypointNotFound(waypoint_id)
    return waypoint_id


# --- routes ---

@bp.post("/waypoints")
def seed_add():
    """The seeds' call, unchanged: {"lng": x, "lat": y} -> 200 {"status": "success", ...}."""
    body = json_body()
    only_keys(body, {"lng", "lat", "label"})
    lng, lat = _position(body)
    waypoint = current_feature(WaypointsService).add(lng, lat, check_label(body.get("label")))
    return jsonify(status="success", message="Waypoint received", waypoint=waypoint.to_dict())


@bp.get("/waypoints")
def table_page():
    service = current_feature(WaypointsService)
    return render_template("waypoints.html", mission=service.store.mission(), map=service.map_config(),
                           waypoint_topic=service.waypoint_topic, mission_topic=service.mission_topic)


@bp.get("/api/waypoints")
def list_waypoints():
    service = current_feature(WaypointsService)
    return jsonify({**service.store.mission().to_dict(), "max": service.store.max_waypoints})


@bp.post("/api/waypoints")
def add_waypoint():
    body = json_body()
    only_keys(body, {"lng", "lat", "label"})
    lng, lat = _position(body)
    waypoint = current_feature(WaypointsService).add(lng, lat, check_label(body.get("label")))
    return jsonify(waypoint=waypoint.to_dict()), 201


@bp.delete("/api/waypoints")
def clear_waypoints():
    service = current_feature(WaypointsService)
    deleted, revision = service.store.clear()
    service.changed()
    return jsonify(deleted=deleted, revision=revision)


@bp.patch("/api/waypoints/<int:waypoint_id>")
def update_waypoint(waypoint_id: int):
    body = json_body()
    only_keys(body, {"lng", "lat", "label", "index"})
    if not body:
        raise InvalidInput("send at least one of lng, lat, label, index", "missing_field")
    lng = check_lng(body["lng"]) if "lng" in body else None
    lat = check_lat(body["lat"]) if "lat" in body else None
    label = check_label(body["label"]) if "label" in body else None
    index = _integer(body, "index")
    waypoint, revision = current_feature(WaypointsService).move(_waypoint_id(waypoint_id), lng=lng, lat=lat,
                                                                label=label, index=index)
    return jsonify(waypoint=waypoint.to_dict(), revision=revision)


@bp.delete("/api/waypoints/<int:waypoint_id>")
def delete_waypoint(waypoint_id: int):
    service = current_feature(WaypointsService)
    revision = service.store.delete(_waypoint_id(waypoint_id))
    service.changed()
    return jsonify(deleted=waypoint_id, revision=revision)


@bp.post("/api/waypoints/send")
def send_mission():
    body = json_body(required=False)
    only_keys(body, {"revision"})
    return jsonify(current_feature(WaypointsService).send_mission(_integer(body, "revision")))


@bp.get("/api/waypoints/geojson")
def export_geojson():
    response = jsonify(mission_to_geojson(current_feature(WaypointsService).store.mission()))
    response.mimetype = MEDIA_TYPE
    if request.args.get("download"):
        response.headers["Content-Disposition"] = 'attachment; filename="mission.geojson"'
    return response


@bp.post("/api/waypoints/geojson")
def import_geojson():
    service = current_feature(WaypointsService)
    points = waypoints_from_geojson(json_body(), service.store.max_waypoints)
    mission = service.replace(points)
    return jsonify({**mission.to_dict(), "max": service.store.max_waypoints})


# --- errors ---

@bp.errorhandler(InvalidInput)
def _invalid(exc: InvalidInput):
    status = 409 if exc.code == "too_many_waypoints" else 400
    return error_response(status, exc.code, text_of(exc))


@bp.errorhandler(MissionFull)
def _full(exc: MissionFull):
    return error_response(409, "too_many_waypoints",
                          "the mission may hold at most %(count)s waypoints (ROVER_WEB_MAX_WAYPOINTS); delete some "
                          "first", count=exc.args[0])


@bp.errorhandler(OutsideGeofence)
def _outside_geofence(exc: OutsideGeofence):
    return outside_geofence_response(exc)


@bp.errorhandler(WaypointNotFound)
def _not_found(exc: WaypointNotFound):
    return error_response(404, "no_such_waypoint", "there is no waypoint with id %(id)s",
                          id=str(exc.args[0])[:30])


@bp.errorhandler(StaleRevision)
def _stale(exc: StaleRevision):
    return error_response(409, "mission_changed",
                          "the mission changed since you loaded it (now revision %(revision)s); reload and check it",
                          revision=exc.args[0])


@bp.errorhandler(EmptyMission)
def _empty(exc: EmptyMission):
    return error_response(409, "empty_mission", "the mission has no waypoints; add at least one before sending it")


@bp.errorhandler(CommitterStopped)
def _stopping(exc: CommitterStopped):
    return error_response(503, "shutting_down", "the server is shutting down; nothing was stored")
