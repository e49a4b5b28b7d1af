"""GPS waypoints: the RobotX GUI's map click, a persistent mission editor, and the robot's live fix.

HTTP (views stay thin; rules live in waypoint_store, mission_geojson and gps):
  POST /waypoints                      the seeds' call: append, publish [lng, lat] on /waypoints
  GET  /waypoints                      server-rendered table of the mission (no JavaScript needed)
  GET/POST/DELETE /api/waypoints       list, add (optional label), clear
  PATCH/DELETE /api/waypoints/<id>     move (lng/lat), rename (label), reorder (index), delete
  POST /api/waypoints/send             the whole ordered mission on /mission (n x 2 Float64MultiArray)
  GET/POST /api/waypoints/geojson      export / import (replace) as a GeoJSON FeatureCollection
SSE: `waypoints` (the stored mission, at most 10 Hz) and `fix` (robot position and track, 5 Hz).

Every waypoint added, by either POST, is stored (committed, fsynced) first and then published on
/waypoints, so an acknowledged waypoint is both on disk and on the wire. Moves, reorders, deletes
and imports change only the stored mission; the robot gets them with "send mission".
"""

from __future__ import annotations

import logging
import sqlite3
import threading

from flask import Blueprint, current_app, jsonify, render_template, request

from rover_web.core.state import Rover
from .gps import GpsTrack
from rover_web.storage.group_commit import CommitterStopped
from rover_web.web.http import ApiError, error_response, json_body
from .geojson import MEDIA_TYPE, mission_to_geojson, waypoints_from_geojson
from .msgs import FLOAT64_MULTI_ARRAY, NAV_SAT_FIX, fix_reading, mission_message, waypoint_message
from rover_web.basemap import basemap
from rover_web.basemap import bp as tiles_bp
from rover_web.web.validate import InvalidInput, only_keys
from .store import (
    MissionFull,
    StaleRevision,
    Waypoint,
    WaypointNotFound,
    WaypointStore,
    check_label,
    check_lat,
    check_lng,
)

log = logging.getLogger(__name__)

EXTENSION = "rover_web.waypoints"
WAYPOINTS_CHANNEL_MAX_HZ = 10.0
FIX_CHANNEL_MAX_HZ = 5.0
# Every waypoint is a command the robot must not miss: keep enough history that a subscriber a
# few hundred milliseconds behind a burst of clicks (or a script) still receives all of them.
WAYPOINT_QOS_DEPTH = 1000
SQLITE_MAX_INT = (1 << 63) - 1

bp = Blueprint("waypoints", __name__)


class MissionBroadcaster:
    """Keeps the `waypoints` channel equal to the stored mission, read back from the database.

    Writers only say "changed"; this thread reads the committed mission and publishes it at most
    max_hz times a second, so a burst of writes costs one read and one frame per interval, and the
    channel can never show an older mission after a newer one.
    """

    def __init__(self, store: WaypointStore, hub, max_hz: float = WAYPOINTS_CHANNEL_MAX_HZ):
        self._store, self._hub = store, hub
        self._interval_s = 1.0 / max_hz
        self._changed = threading.Event()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="waypoints-broadcaster", daemon=True)

    def start(self) -> None:
        self.publish_now()
        self._thread.start()

    def changed(self) -> None:
        self._changed.set()

    def publish_now(self) -> None:
        mission = self._store.mission().to_dict()
        mission["max"] = self._store.max_waypoints
        self._hub.publish("waypoints", mission)

    def _run(self) -> None:
        while not self._stop.is_set():
            if not self._changed.wait(0.5):
                continue
            self._changed.clear()
            if self._stop.is_set():
                break
            try:
                self.publish_now()
            except Exception:
                log.exception("could not publish the mission to the waypoints channel")
            self._stop.wait(self._interval_s)

    def stop(self) -> None:
        self._stop.set()
        self._changed.set()
        if self._thread.is_alive():
            self._thread.join(2.0)


class WaypointsFeature:
    def __init__(self, rover: Rover):
        config = rover.config
        self.config = config
        self.store = WaypointStore(rover.db, config["ROVER_WEB_MAX_WAYPOINTS"])
        runtime = rover.runtime
        self.waypoint_topic = config["ROVER_WEB_WAYPOINTS_TOPIC"]
        self.mission_topic = config["ROVER_WEB_MISSION_TOPIC"]
        self.waypoint_pub = runtime.publisher(FLOAT64_MULTI_ARRAY, self.waypoint_topic, qos=WAYPOINT_QOS_DEPTH)
        self.mission_pub = runtime.publisher(FLOAT64_MULTI_ARRAY, self.mission_topic, qos=10)
        self.hub = rover.hub
        self.track = GpsTrack(config["ROVER_WEB_FIX_TRACK_POINTS"])
        self.broadcaster = MissionBroadcaster(self.store, rover.hub)
        runtime.subscribe(NAV_SAT_FIX, config["ROVER_WEB_FIX_TOPIC"], self._on_fix, qos="sensor_data")

    def _on_fix(self, msg) -> None:
        state = self.track.update(fix_reading(msg))
        self.hub.publish_throttled("fix", state, FIX_CHANNEL_MAX_HZ)

    # --- changes ---

    def add(self, lng: float, lat: float, label: str = "") -> Waypoint:
        # Published once committed, by the committer thread: /waypoints carries the waypoints in
        # the mission's order even when several browsers or scripts add at the same moment.
        waypoint, _revision = self.store.add(lng, lat, label, announce=self._announce)
        self.broadcaster.changed()
        return waypoint

    def _announce(self, waypoint: Waypoint) -> None:
        self.waypoint_pub.publish(waypoint_message(waypoint.lng, waypoint.lat))

    def changed(self) -> None:
        self.broadcaster.changed()

    def send_mission(self, expected_revision: int | None) -> dict:
        mission = self.store.mission()
        if expected_revision is not None and expected_revision != mission.revision:
            raise StaleRevision(mission.revision)
        if not mission.waypoints:
            raise ApiError(409, "empty_mission", "the mission has no waypoints; add at least one before sending it")
        self.mission_pub.publish(mission_message([(w.lng, w.lat) for w in mission.waypoints]))
        return {"sent": len(mission.waypoints), "topic": self.mission_topic, **mission.to_dict()}

    # --- views' data ---

    def map_config(self) -> dict:
        config = self.config
        return {
            "place": config["ROVER_WEB_MAP_PLACE_NAME"],
            "center": [config["ROVER_WEB_MAP_CENTER_LNG"], config["ROVER_WEB_MAP_CENTER_LAT"]],
            "zoom": config["ROVER_WEB_MAP_ZOOM"],
            "basemap": basemap(config),
            "max_waypoints": self.store.max_waypoints,
        }

    def panel_context(self) -> dict:
        return {"mission": self.store.mission(), "map": self.map_config(), "fix": self.track.state()}


def feature() -> WaypointsFeature:
    return current_app.extensions[EXTENSION]


# --- input ---

def _position(body: dict) -> tuple[float, float]:
    for key in ("lng", "lat"):
        if key not in body:
            raise InvalidInput(f"'{key}' is required: send {{\"lng\": <degrees east>, \"lat\": <degrees north>}}",
                               "missing_field")
    return check_lng(body["lng"]), check_lat(body["lat"])


def _integer(body: dict, key: str, low: int = 0) -> int | None:
    if key not in body or body[key] is None:
        return None
    value = body[key]
    if isinstance(value, bool) or not isinstance(value, int):
        raise InvalidInput(f"'{key}' must be an integer, got {type(value).__name__}", "bad_type")
    if value < low:
        raise InvalidInput(f"'{key}' must be at least {low}", "out_of_range")
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
    waypoint = feature().add(lng, lat, check_label(body.get("label")))
    return jsonify(status="success", message="Waypoint received", waypoint=waypoint.to_dict())


@bp.get("/waypoints")
def table_page():
    f = feature()
    return render_template("waypoints.html", mission=f.store.mission(), map=f.map_config(),
                           waypoint_topic=f.waypoint_topic, mission_topic=f.mission_topic)


@bp.get("/api/waypoints")
def list_waypoints():
    f = feature()
    return jsonify({**f.store.mission().to_dict(), "max": f.store.max_waypoints})


@bp.post("/api/waypoints")
def add_waypoint():
    body = json_body()
    only_keys(body, {"lng", "lat", "label"})
    lng, lat = _position(body)
    waypoint = feature().add(lng, lat, check_label(body.get("label")))
    return jsonify(waypoint=waypoint.to_dict()), 201


@bp.delete("/api/waypoints")
def clear_waypoints():
    f = feature()
    deleted, revision = f.store.clear()
    f.changed()
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
    f = feature()
    waypoint, revision = f.store.update(_waypoint_id(waypoint_id), lng=lng, lat=lat, label=label, index=index)
    f.changed()
    return jsonify(waypoint=waypoint.to_dict(), revision=revision)


@bp.delete("/api/waypoints/<int:waypoint_id>")
def delete_waypoint(waypoint_id: int):
    f = feature()
    revision = f.store.delete(_waypoint_id(waypoint_id))
    f.changed()
    return jsonify(deleted=waypoint_id, revision=revision)


@bp.post("/api/waypoints/send")
def send_mission():
    body = json_body(required=False)
    only_keys(body, {"revision"})
    return jsonify(feature().send_mission(_integer(body, "revision")))


@bp.get("/api/waypoints/geojson")
def export_geojson():
    response = jsonify(mission_to_geojson(feature().store.mission()))
    response.mimetype = MEDIA_TYPE
    if request.args.get("download"):
        response.headers["Content-Disposition"] = 'attachment; filename="mission.geojson"'
    return response


@bp.post("/api/waypoints/geojson")
def import_geojson():
    f = feature()
    points = waypoints_from_geojson(json_body(), f.store.max_waypoints)
    mission = f.store.replace(points)
    f.changed()
    return jsonify({**mission.to_dict(), "max": f.store.max_waypoints})


# --- errors: every refusal is a 4xx JSON body naming the problem ---

@bp.errorhandler(InvalidInput)
def _invalid(exc: InvalidInput):
    status = 409 if exc.code == "too_many_waypoints" else 400
    return error_response(status, exc.code, str(exc))


@bp.errorhandler(MissionFull)
def _full(exc: MissionFull):
    return error_response(409, "too_many_waypoints",
                          f"the mission may hold at most {exc.args[0]} waypoints (ROVER_WEB_MAX_WAYPOINTS); "
                          "delete some first")


@bp.errorhandler(WaypointNotFound)
def _not_found(exc: WaypointNotFound):
    return error_response(404, "no_such_waypoint", f"there is no waypoint with id {str(exc.args[0])[:30]}")


@bp.errorhandler(StaleRevision)
def _stale(exc: StaleRevision):
    return error_response(409, "mission_changed",
                          f"the mission changed since you loaded it (now revision {exc.args[0]}); reload and check it")


@bp.errorhandler(sqlite3.OperationalError)
def _storage(exc: sqlite3.OperationalError):
    current_app.logger.error("waypoint storage: %s", exc)
    return error_response(503, "storage_unavailable", f"the waypoint database could not be written: {exc}")


@bp.errorhandler(CommitterStopped)
def _stopping(exc: CommitterStopped):
    return error_response(503, "shutting_down", "the server is shutting down; nothing was stored")


def init_app(app, rover: Rover) -> None:
    waypoints = WaypointsFeature(rover)
    app.extensions[EXTENSION] = waypoints
    app.register_blueprint(bp)
    app.register_blueprint(tiles_bp)
    rover.hub.register("waypoints", "fix")
    waypoints.broadcaster.start()
    rover.on_shutdown(waypoints.broadcaster.stop)
    rover.on_shutdown(waypoints.store.close)  # runs first: queued changes commit before the db closes
    app.context_processor(lambda: {"waypoints_panel": waypoints.panel_context})
    rover.add_panel(20, "panels/waypoints.html", "GPS waypoints", channels=("waypoints", "fix"))
    rover.add_nav("Waypoints", "/waypoints")
