"""LiveMap: floorplans from map_files, the live robot pose, its goal and plan, click-to-goal.

ROS: subscribes /amcl_pose (transient local), /goal_pose, /plan and optionally an OccupancyGrid
(/map, transient local) drawn into a map named "live map"; publishes goals on /goal_pose.
SSE: `pose` (at most LIVEMAP_POSE_MAX_HZ), `goal`, `plan` (at most 5 Hz), `live_map` (new grid).
HTTP: /livemap pages and /api/maps... (see the routes below and README.md).
"""

from __future__ import annotations

import hashlib
import logging
import math
import threading
from urllib.parse import quote

from flask import Blueprint, Response, abort, current_app, jsonify, redirect, render_template, request, url_for

from rover_web.config import ConfigError
from rover_web.core.state import Rover
from rover_web.web.http import ApiError, json_body
from .state import LiveMap, Pose2D, RobotTrack, UnknownMap, goal_payload, plan_payload, pose_payload
from .map_files import MAX_IMAGE_SIDE_PX, MapDefinition, load_catalog, maps_file_path
from .geometry import MapGeometry, wrap_angle
from .occupancy import grid_to_image, image_to_png
from rover_web.web.validate import InvalidInput, number, only_keys

log = logging.getLogger(__name__)

LIVE_MAP_NAME = "live map"
PLAN_MAX_HZ = 5.0
LIVE_MAP_MAX_HZ = 1.0
STALE_CHECK_S = 0.2

bp = Blueprint("livemap", __name__)


class LiveMapFeature:
    """The maps, the robot track and the goal publisher of one app (app.extensions["livemap"])."""

    def __init__(self, rover: Rover, files: dict[str, MapDefinition]):
        self.rover = rover
        config = rover.config
        self.files = files
        self.live: MapDefinition | None = None  # replaced whole on each new grid, never mutated
        self._live_version = 0
        self.track = RobotTrack(config["ROVER_WEB_LIVEMAP_POSE_STALE_S"])
        self.bot_cm_diameter = config["ROVER_WEB_LIVEMAP_BOT_DIAMETER_CM"]
        self.goal_frame_id = config["ROVER_WEB_GOAL_FRAME_ID"]
        self.goal_topic = config["ROVER_WEB_GOAL_TOPIC"]
        self.pose_max_hz = config["ROVER_WEB_LIVEMAP_POSE_MAX_HZ"]
        self.plan_max_points = config["ROVER_WEB_LIVEMAP_PLAN_MAX_POINTS"]
        self.map_topic = config["ROVER_WEB_LIVEMAP_MAP_TOPIC"]
        self.default_name = config["ROVER_WEB_LIVEMAP_DEFAULT_MAP"] or next(iter(files), None) \
            or (LIVE_MAP_NAME if self.map_topic else None)
        self._goal_publisher = None
        self._goal_lock = threading.Lock()

    # --- maps ---

    def maps(self) -> list[MapDefinition]:
        live = self.live
        return list(self.files.values()) + ([live] if live is not None else [])

    def catalog(self) -> dict[str, MapDefinition]:
        return {d.name: d for d in self.maps()}

    def get(self, name: str) -> MapDefinition:
        definition = self.files.get(name)
        if definition is None and name == LIVE_MAP_NAME:
            definition = self.live
        if definition is None:
            raise ApiError(404, "unknown_map", f"no map named {name[:80]!r}; GET /api/maps lists them")
        return definition

    def live_map(self, name: str, cm_per_pixel: float | None) -> LiveMap:
        """The campus rover's LiveMap for `name`, with the robot's pose and goal filled in."""
        definition = self.get(name)
        live = LiveMap(name, cm_per_pixel, self.bot_cm_diameter, catalog={name: definition})
        pose, age, stale = self.track.pose()
        if pose is not None:
            live.update_current_pose(pose, age_s=round(age, 3), stale=stale)
        live.update_goal_pose(self.track.goal())
        return live

    # --- ROS input ---

    def on_pose(self, values) -> None:
        x, y, yaw, frame_id, stamp = values
        pose = Pose2D(x, y, wrap_angle(yaw) if math.isfinite(yaw) else yaw, frame_id, stamp)
        if not pose.finite:
            return  # a NaN pose is not a place on the map
        self.track.set_pose(pose)
        self.rover.hub.publish_throttled("pose", pose_payload(pose, self.maps()), self.pose_max_hz)

    def on_goal(self, values) -> None:
        x, y, yaw, frame_id, stamp = values
        goal = Pose2D(x, y, wrap_angle(yaw) if math.isfinite(yaw) else yaw, frame_id, stamp)
        if goal.finite and self.track.set_goal(goal):
            self.rover.hub.publish("goal", goal_payload(goal, self.maps()))

    def on_plan(self, frame_id: str, points: list[tuple[float, float]]) -> None:
        points = [(x, y) for x, y in points if math.isfinite(x) and math.isfinite(y)]
        payload = plan_payload(frame_id, points, self.plan_max_points)
        self.track.set_plan(payload)
        self.rover.hub.publish_throttled("plan", payload, PLAN_MAX_HZ)

    def on_grid(self, info: dict, cells) -> None:
        width, height, resolution = info["width"], info["height"], info["resolution"]
        problem = None
        if width <= 0 or height <= 0 or width > MAX_IMAGE_SIDE_PX or height > MAX_IMAGE_SIDE_PX:
            problem = f"size {width}x{height} (1 to {MAX_IMAGE_SIDE_PX} cells a side)"
        elif len(cells) != width * height:
            problem = f"{len(cells)} cells for {width}x{height}"
        elif not (math.isfinite(resolution) and resolution > 0) or not all(map(math.isfinite, info["origin"])):
            problem = "a resolution or origin that is not a finite number"
        if problem:
            log.warning("ignoring an OccupancyGrid on %s with %s", self.map_topic, problem)
            return
        geometry = MapGeometry(width, height, resolution, *info["origin"])
        self._live_version += 1
        cells = cells.copy()
        params = {"resolution": resolution, "origin": list(info["origin"]), "negate": 0,
                  "occupied_thresh": 0.65, "free_thresh": 0.25, "mode": "trinary"}
        files = {"path": "", "topic": self.map_topic, "frame_id": info["frame_id"],
                 "png": {"file_name": "", "cm_per_pixel": geometry.cm_per_pixel,
                         "pixel_width": width, "pixel_height": height}}
        self.live = MapDefinition(LIVE_MAP_NAME, geometry, files, params, (), label=f"live {self.map_topic}",
                                  source="live", version=self._live_version,
                                  renderer=lambda: image_to_png(grid_to_image(cells, width, height)))
        self.rover.hub.publish_throttled("live_map", {
            "name": LIVE_MAP_NAME, "label": self.live.label, "version": self._live_version,
            "width_px": width, "height_px": height, "resolution_m": resolution,
            "origin": [round(v, 6) for v in info["origin"]]}, LIVE_MAP_MAX_HZ)

    # --- goals ---

    def send_goal(self, definition: MapDefinition, x: float, y: float, yaw: float) -> Pose2D:
        from .msgs import goal_message

        if not definition.geometry.contains(x, y):
            g = definition.geometry
            corners = [g.pixel_to_world(*c) for c in ((0, g.height_px), (g.width_px, 0))]
            raise ApiError(400, "outside_map",
                           f"({x:g}, {y:g}) is outside {definition.name!r}, which spans "
                           f"x {min(corners[0][0], corners[1][0]):g}..{max(corners[0][0], corners[1][0]):g} m, "
                           f"y {min(corners[0][1], corners[1][1]):g}..{max(corners[0][1], corners[1][1]):g} m")
        if self.rover.stopping.is_set():
            raise ApiError(503, "stopping", "the server is shutting down; no goal was sent")
        yaw = wrap_angle(yaw)
        with self._goal_lock:
            stamp = self.rover.runtime.now_msg()
            goal = Pose2D(x, y, yaw, self.goal_frame_id, stamp.sec + stamp.nanosec * 1e-9)
            self._goal_publisher.publish(goal_message(x, y, yaw, self.goal_frame_id, stamp))
            # Our own subscription hears it back too; set_goal makes that echo a no-op.
            if self.track.set_goal(goal):
                self.rover.hub.publish("goal", goal_payload(goal, self.maps()))
        return goal

    # --- staleness ---

    def watch_staleness(self) -> None:
        """Tell pages once when the pose goes stale: silence alone cannot say 'no pose'."""
        was_stale = True
        while not self.rover.stopping.wait(STALE_CHECK_S):
            pose, age, stale = self.track.pose()
            if pose is not None and stale and not was_stale:
                self.rover.hub.publish("pose", pose_payload(pose, self.maps(), stale=True, age_s=age))
            was_stale = stale


def current_feature() -> LiveMapFeature:
    return current_app.extensions["livemap"]


def map_summary(definition: MapDefinition) -> dict:
    g = definition.geometry
    quoted = quote(definition.name, safe="")
    version = f"?v={definition.version}" if definition.source == "live" else ""
    return {
        "name": definition.name, "label": definition.label, "source": definition.source,
        "version": definition.version,
        "width_px": g.width_px, "height_px": g.height_px, "resolution_m": g.resolution_m,
        "cm_per_pixel": g.cm_per_pixel, "width_m": round(g.width_m, 6), "height_m": round(g.height_m, 6),
        "origin": [g.origin_x, g.origin_y, g.origin_yaw], "waypoint_count": len(definition.waypoints),
        "urls": {"state": f"/api/maps/{quoted}", "image": f"/api/maps/{quoted}/image{version}",
                 "thumbnail": f"/api/maps/{quoted}/thumbnail{version}", "page": f"/livemap/{quoted}",
                 "goal": f"/api/maps/{quoted}/goal"},
    }


def _png_response(data: bytes) -> Response:
    response = Response(data, mimetype="image/png")
    response.set_etag(hashlib.sha1(data).hexdigest())
    response.headers["Cache-Control"] = "no-cache"  # revalidate: a live map changes under the same URL
    return response.make_conditional(request)


# --- HTTP: pages ---


@bp.get("/livemap")
def livemap_index():
    feature = current_feature()
    if feature.default_name is None or (feature.default_name == LIVE_MAP_NAME and feature.live is None):
        return render_template("livemap.html", page=None, maps=[map_summary(d) for d in feature.maps()])
    return redirect(url_for("livemap.livemap_page", name=feature.default_name))


@bp.get("/livemap/<name>")
def livemap_page(name: str):
    feature = current_feature()
    try:
        live = feature.live_map(name, None)
    except ApiError:
        abort(404, description=f"There is no map named {name[:80]!r}.")
    page = {
        "map": map_summary(live.definition),
        "map_state": live.map_state,
        "maps": [map_summary(d) for d in feature.maps()],
        "pose": feature.rover.hub.latest("pose"),
        "goal": feature.rover.hub.latest("goal"),
        "plan": feature.track.plan(),
        "pose_stale_s": feature.track.stale_after_s,
        "goal_topic": feature.goal_topic,
    }
    return render_template("livemap.html", page=page, maps=page["maps"])


# --- HTTP: API ---


@bp.get("/api/maps")
def list_maps():
    feature = current_feature()
    return jsonify(maps=[map_summary(d) for d in feature.maps()], default=feature.default_name)


@bp.get("/api/maps/<name>")
def map_state(name: str):
    feature = current_feature()
    feature.get(name)  # 404 before looking at the query
    raw = request.args.get("cm_per_pixel")
    cm_per_pixel = None
    if raw is not None:
        try:
            cm_per_pixel = float(raw)
        except ValueError:
            raise ApiError(400, "bad_type", f"cm_per_pixel must be a number, got {raw[:40]!r}") from None
    try:
        live = feature.live_map(name, cm_per_pixel)
    except ValueError as exc:
        raise ApiError(400, "out_of_range", str(exc)) from None
    except UnknownMap as exc:  # pragma: no cover - get() above already answered 404
        raise ApiError(404, "unknown_map", str(exc)) from None
    return jsonify(live.map_state)


@bp.get("/api/maps/<name>/image")
def map_image(name: str):
    return _png_response(current_feature().get(name).png())


@bp.get("/api/maps/<name>/thumbnail")
def map_thumbnail(name: str):
    return _png_response(current_feature().get(name).thumbnail())


@bp.post("/api/maps/<name>/goal")
def post_goal(name: str):
    feature = current_feature()
    definition = feature.get(name)
    body = json_body()
    try:
        only_keys(body, {"x", "y", "yaw"})
        x = number(body, "x")
        y = number(body, "y")
        yaw = number(body, "yaw", default=0.0)
    except InvalidInput as exc:
        raise ApiError(400, exc.code, str(exc)) from None
    goal = feature.send_goal(definition, x, y, yaw)
    payload = goal_payload(goal, [definition])
    return jsonify(status="sent", topic=feature.goal_topic, goal=payload)


# --- wiring ---


def _panel_context() -> dict:
    feature = current_app.extensions.get("livemap")
    if feature is None or feature.default_name is None:
        return {"livemap_panel": None}
    try:
        definition = feature.get(feature.default_name)
    except ApiError:
        return {"livemap_panel": {"map": None, "pose": None}}
    return {"livemap_panel": {"map": map_summary(definition), "pose": feature.rover.hub.latest("pose")}}


def init_app(app, rover: Rover) -> None:
    from . import msgs

    config = rover.config
    path = maps_file_path(config["ROVER_WEB_MAPS_FILE"])
    files = load_catalog(path) if path is not None else {}
    if LIVE_MAP_NAME in files:
        raise ConfigError(f"{path}: {LIVE_MAP_NAME!r}: that name is kept for the live OccupancyGrid map; rename it")
    feature = LiveMapFeature(rover, files)
    default = config["ROVER_WEB_LIVEMAP_DEFAULT_MAP"]
    if default is not None and default not in files and not (default == LIVE_MAP_NAME and feature.map_topic):
        raise ConfigError(f"ROVER_WEB_LIVEMAP_DEFAULT_MAP: no map named {default!r} in "
                          f"{path or 'ROVER_WEB_MAPS_FILE (empty)'}; known: {', '.join(files) or 'none'}")
    app.extensions["livemap"] = feature

    rover.hub.register("pose", "goal", "plan", "live_map")
    runtime = rover.runtime
    feature._goal_publisher = runtime.publisher(msgs.POSE_STAMPED, feature.goal_topic, "default")
    runtime.subscribe(msgs.AMCL_POSE, config["ROVER_WEB_AMCL_POSE_TOPIC"],
                      lambda m: feature.on_pose(msgs.pose_from_amcl(m)), "latched")
    runtime.subscribe(msgs.POSE_STAMPED, feature.goal_topic, lambda m: feature.on_goal(msgs.pose_from_stamped(m)),
                      "default")
    runtime.subscribe(msgs.PATH, config["ROVER_WEB_PLAN_TOPIC"], lambda m: feature.on_plan(*msgs.path_points(m)), 1)
    if feature.map_topic:
        runtime.subscribe(msgs.OCCUPANCY_GRID, feature.map_topic, lambda m: feature.on_grid(*msgs.occupancy_grid(m)),
                          "latched")

    app.register_blueprint(bp)
    app.context_processor(_panel_context)
    rover.add_panel(30, "panels/livemap.html", "Live map", channels=("pose",))
    rover.add_nav("Live map", "/livemap")
    watcher = threading.Thread(target=feature.watch_staleness, name="livemap-stale", daemon=True)
    watcher.start()
    rover.on_shutdown(lambda: watcher.join(1.0))
