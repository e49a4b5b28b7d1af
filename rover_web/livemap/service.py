"""LiveMap's per-app object: the maps, the robot's track and the goal publisher of one app.

The robot's pose is AMCL's (`/amcl_pose`) while AMCL speaks; with no AMCL pose for AMCL_QUIET_S it
is TF's map -> base_link (ROVER_WEB_MAP_FRAME, ROVER_WEB_BASE_FRAME), looked up once per tick, so
a robot localised by SLAM Toolbox, Cartographer or robot_localization appears too. The plan is
placed through TF when it is in another frame than the map. Each says which it used (`placed_by`).
"""

from __future__ import annotations

import logging
import math
import threading
import time
from typing import Any

from rover_web.config import ConfigError
from rover_web.core.state import Rover
from rover_web.estop import EStopService
from rover_web.placement import MAP, TF, MapPlacer, Unplaceable, tf_buffer
from rover_web.web.api_messages import explain

from . import msgs
from .geometry import MapGeometry, wrap_angle
from .keep_out import check_goal
from .map_files import MapDefinition, load_catalog_checked_apart, maps_file_path
from .map_images import MAX_IMAGE_SIDE_PX
from .occupancy import grid_to_image, image_to_png
from .state import LiveMap, Pose2D, RobotTrack, UnknownMap, goal_payload, plan_payload, pose_payload

log = logging.getLogger(__name__)

LIVE_MAP_NAME = "live map"
PLAN_MAX_HZ = 5.0
LIVE_MAP_MAX_HZ = 1.0
STALE_CHECK_S = 0.2
AMCL_QUIET_S = 2.0  # AMCL's pose this old (or none): the robot is placed by TF's map -> base_link
TF_POSE_MIN_PERIOD_S = 0.1  # the robot from TF at most 10 times a second: a loop's wake-ups cost even idle
UNPLACED = "unplaced"  # a plan in a frame TF does not know: drawn as given (there is no fallback for it)


class OutsideMap(ValueError):
    """A goal that does not lie on the map it was sent for."""


class ShuttingDown(RuntimeError):
    """The app is stopping: nothing more goes out to the robot."""


def load_files(config: dict[str, Any]) -> dict[str, MapDefinition]:
    """The floorplans of ROVER_WEB_MAPS_FILE; ConfigError for them or for the default map setting."""
    path = maps_file_path(config["ROVER_WEB_MAPS_FILE"])
    files = load_catalog_checked_apart(path) if path is not None else {}
    if LIVE_MAP_NAME in files:
        raise ConfigError(f"{path}: {LIVE_MAP_NAME!r}: that name is kept for the live OccupancyGrid map; rename it")
    default = config["ROVER_WEB_LIVEMAP_DEFAULT_MAP"]
    if default is not None and default not in files and not (
            default == LIVE_MAP_NAME and config["ROVER_WEB_LIVEMAP_MAP_TOPIC"]):
        raise ConfigError(f"ROVER_WEB_LIVEMAP_DEFAULT_MAP: no map named {default!r} in "
                          f"{path or 'ROVER_WEB_MAPS_FILE (empty)'}; known: {', '.join(files) or 'none'}")
    return files


def check_on_map(definition: MapDefinition, x: float, y: float) -> None:
    if not definition.geometry.contains(x, y):
        g = definition.geometry
        corners = [g.pixel_to_world(*c) for c in ((0, g.height_px), (g.width_px, 0))]
        raise OutsideMap(
            explain(
                "(%(x)s, %(y)s) is outside %(name)s, which spans x %(corners)s..%(corners2)s m, y "
                "%(corners3)s..%(corners4)s m",
                x=format(x, "g"),
                y=format(y, "g"),
                name=repr(definition.name),
                corners=format(min(corners[0][0], corners[1][0]), "g"),
                corners2=format(max(corners[0][0], corners[1][0]), "g"),
                corners3=format(min(corners[0][1], corners[1][1]), "g"),
                corners4=format(max(corners[0][1], corners[1][1]), "g"),
            )
        )


class LiveMapService:
    """The maps, the robot track and the goal publisher of one app."""

    def __init__(self, rover: Rover, files: dict[str, MapDefinition], goal_publisher, estop: EStopService,
                 initial_pose_publisher):
        self.rover = rover
        self.estop = estop
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
        self._goal_publisher = goal_publisher
        self._initial_pose_publisher = initial_pose_publisher
        self.initial_pose_topic = config["ROVER_WEB_INITIAL_POSE_TOPIC"]
        self._goal_lock = threading.Lock()
        self._was_stale = True  # no pose yet counts as stale: nothing to announce
        self.placer = MapPlacer(tf_buffer(rover) if hasattr(rover, "feature") else None,
                                config.get("ROVER_WEB_MAP_FRAME", "map"))
        self.base_frame = config.get("ROVER_WEB_BASE_FRAME", "base_link")
        self.tf_pose_period_s = max(TF_POSE_MIN_PERIOD_S, 1.0 / self.pose_max_hz)
        self._amcl_at = -math.inf  # monotonic time of AMCL's latest pose
        self._tf_stamp: int | None = None  # of the latest map -> base_link taken as the pose
        self.pose_placed_by: str | None = None  # "amcl" or "tf"
        self.plan_placed_by: str | None = None

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
            raise UnknownMap(explain("no map named %(name)s; GET /api/maps lists them", name=repr(name[:80])))
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

    def on_pose(self, values, placed_by: str = "amcl") -> None:
        x, y, yaw, frame_id, stamp = values
        pose = Pose2D(x, y, wrap_angle(yaw) if math.isfinite(yaw) else yaw, frame_id, stamp)
        if not pose.finite:
            return  # a NaN pose is not a place on the map
        if placed_by == "amcl":
            self._amcl_at = time.monotonic()
        self.pose_placed_by = placed_by
        self.track.set_pose(pose)
        self.rover.hub.publish_throttled("pose", {**pose_payload(pose, self.maps()), "placed_by": placed_by},
                                         self.pose_max_hz)

    def pose_from_tf(self) -> None:
        """One tick: with AMCL quiet, the robot's pose is map -> base_link from TF (one lookup)."""
        buffer = self.placer.buffer
        if buffer is None or time.monotonic() - self._amcl_at < AMCL_QUIET_S:
            return
        from rover_web.tf.buffer import TfError

        try:
            t = buffer.lookup(self.placer.map_frame, self.base_frame, None)
        except TfError:
            return  # no tree from map to the base (yet): no pose, and the old one goes stale
        if t.stamp_ns == self._tf_stamp and t.stamp_ns != 0:
            return  # nothing new: a silent TF must go stale, not look fresh
        self._tf_stamp = t.stamp_ns
        self.on_pose((t.translation[0], t.translation[1], t.yaw, self.placer.map_frame, t.stamp_ns / 1e9), "tf")

    def on_goal(self, values) -> None:
        x, y, yaw, frame_id, stamp = values
        goal = Pose2D(x, y, wrap_angle(yaw) if math.isfinite(yaw) else yaw, frame_id, stamp)
        if goal.finite and self.track.set_goal(goal):
            self.rover.hub.publish("goal", goal_payload(goal, self.maps()))

    def on_plan(self, frame_id: str, points: list[tuple[float, float]], stamp: float = 0.0) -> None:
        points = [(x, y) for x, y in points if math.isfinite(x) and math.isfinite(y)]
        placed_by = MAP
        if points and frame_id.lstrip("/") not in (self.placer.map_frame, "", self.goal_frame_id):
            try:
                placement = self.placer.lookup(frame_id, stamp)
            except Unplaceable:
                placement = None  # a plan out of TF's reach is drawn as given, and says so
            if placement is not None:
                xs, ys, _ = placement.apply_many([p[0] for p in points], [p[1] for p in points], None)
                points, placed_by = list(zip(xs.tolist(), ys.tolist(), strict=True)), TF
            else:
                placed_by = UNPLACED
        self.plan_placed_by = placed_by
        payload = {**plan_payload(frame_id, points, self.plan_max_points), "placed_by": placed_by}
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
        """Publish a goal on the map; OutsideMap or ShuttingDown when nothing was sent."""
        check_on_map(definition, x, y)
        check_goal(definition.keep_out, definition.name, x, y)  # OutsideGeofence: 422, nothing sent
        if self.rover.stopping.is_set():
            raise ShuttingDown(explain("the server is shutting down; no goal was sent"))
        self.estop.check_motion()
        yaw = wrap_angle(yaw)
        with self._goal_lock:
            stamp = self.rover.runtime.now_msg()
            goal = Pose2D(x, y, yaw, self.goal_frame_id, msgs.stamp_seconds(stamp))
            self._goal_publisher.publish(msgs.goal_message(x, y, yaw, self.goal_frame_id, stamp))
            # Our own subscription hears it back too; set_goal makes that echo a no-op.
            if self.track.set_goal(goal):
                self.rover.hub.publish("goal", goal_payload(goal, self.maps()))
        return goal

    def send_initial_pose(self, definition: MapDefinition, x: float, y: float, yaw: float,
                          covariance) -> dict:
        """Tell the localiser where the robot is; OutsideMap, EStopEngaged or ShuttingDown when nothing was sent.

        Refused during an e-stop as goals are: a new pose makes AMCL jump, and Nav2 replans from it.
        Keep-out areas are not checked: the robot may well stand in one (it was carried there).
        """
        check_on_map(definition, x, y)
        if self.rover.stopping.is_set():
            raise ShuttingDown(explain("the server is shutting down; no initial pose was sent"))
        self.estop.check_motion()
        yaw = wrap_angle(yaw)
        stamp = self.rover.runtime.now_msg()
        self._initial_pose_publisher.publish(
            msgs.initial_pose_message(x, y, yaw, covariance, self.goal_frame_id, stamp))
        return {"x": x, "y": y, "yaw": round(yaw, 6), "frame_id": self.goal_frame_id,
                "stamp": msgs.stamp_seconds(stamp), "covariance": list(covariance)}

    # --- staleness ---

    def check_staleness(self) -> None:
        """Tell pages once when the pose goes stale: silence alone cannot say 'no pose'."""
        pose, age, stale = self.track.pose()
        if pose is not None and stale and not self._was_stale:
            self.rover.hub.publish("pose", pose_payload(pose, self.maps(), stale=True, age_s=age))
        self._was_stale = stale
