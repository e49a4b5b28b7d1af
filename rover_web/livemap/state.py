"""The campus rover's LiveMap, and the robot's live pose, goal and plan it is drawn with. Pure Python.

`LiveMap(map_name, cm_per_pixel, bot_cm_diameter=35.4)` keeps the campus rover's `map_state`:

    map_parameters:      map_name, files {path, png {file_name, cm_per_pixel, pixel_width,
                         pixel_height}, yaml {resolution, origin, ...}}, bot_radius (cm),
                         cm_per_pixel (the display scale asked for), waypoints, current_pose,
                         goal_pose (map metres and radians)
    scaled_pixel_values: bot_radius, cm_per_pixel, png_pixel_width, png_pixel_height,
                         current_pose, goal_pose, waypoints (pixels of the map drawn at cm_per_pixel)

Two corrections to the campus code: width and height are no longer swapped, and the scaled bot
radius is radius_cm / cm_per_pixel (the campus formula also multiplied by the image's own cm per
pixel, which only worked because its image had 1 cm pixels).
"""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass

from rover_web.config import ROOT
from rover_web.web.api_messages import explain

from .geometry import wrap_angle
from .map_files import MapDefinition, load_catalog

BOT_CM_DIAMETER = 35.4  # the Turtlebot 2 the campus rover was built on
MIN_CM_PER_PIXEL = 0.01
MAX_CM_PER_PIXEL = 100000.0


class UnknownMap(LookupError):
    pass


@dataclass(frozen=True)
class Pose2D:
    x: float
    y: float
    yaw: float
    frame_id: str = "map"
    stamp_s: float = 0.0

    @property
    def finite(self) -> bool:
        return all(math.isfinite(v) for v in (self.x, self.y, self.yaw, self.stamp_s))


def _catalog_default() -> Mapping[str, MapDefinition]:
    """The floorplans bundled with rover_web (ROVER_WEB_MAPS_FILE's default), read only when asked for."""
    return load_catalog(ROOT / "map_files" / "all_maps.json")


class LiveMap:
    """One floorplan at one display scale, with the robot's current and goal poses on it."""

    def __init__(self, map_name: str, cm_per_pixel: float | None = None, bot_cm_diameter: float = BOT_CM_DIAMETER,
                 *, catalog: Mapping[str, MapDefinition] | None = None):
        catalog = _catalog_default() if catalog is None else catalog
        definition = catalog.get(map_name)
        if definition is None:
            raise UnknownMap(explain("no map named %(map_name)s; known: %(catalog)s",
                                     map_name=repr(map_name), catalog=', '.join(catalog)))
        geometry = definition.geometry
        if cm_per_pixel is None:
            cm_per_pixel = geometry.cm_per_pixel
        if isinstance(cm_per_pixel, bool) or not isinstance(cm_per_pixel, (int, float)) \
                or not math.isfinite(cm_per_pixel) or not MIN_CM_PER_PIXEL <= cm_per_pixel <= MAX_CM_PER_PIXEL:
            raise ValueError(explain("cm_per_pixel must be a number from %(low)s to %(high)s",
                                     low=format(MIN_CM_PER_PIXEL, "g"), high=format(MAX_CM_PER_PIXEL, "g")))
        if not (math.isfinite(bot_cm_diameter) and bot_cm_diameter > 0):
            raise ValueError(explain("bot_cm_diameter must be a positive number of centimetres"))
        self.definition = definition
        self.geometry = geometry
        self.cm_per_pixel = float(cm_per_pixel)
        self.scale = geometry.display_scale(self.cm_per_pixel)  # display pixels per image pixel
        bot_radius_cm = bot_cm_diameter / 2.0
        files = {k: v for k, v in definition.files.items()}
        files["yaml"] = dict(definition.yaml)
        self.map_state = {
            "map_parameters": {
                "map_name": definition.name,
                "label": definition.label,
                "source": definition.source,
                "version": definition.version,
                "files": files,
                "bot_radius": bot_radius_cm,
                "cm_per_pixel": self.cm_per_pixel,
                "waypoints": [w.as_dict() for w in definition.waypoints],
                "current_pose": {},
                "goal_pose": {},
            },
            "scaled_pixel_values": {
                "bot_radius": bot_radius_cm / self.cm_per_pixel,
                "cm_per_pixel": self.cm_per_pixel,
                "scale": self.scale,
                "png_pixel_width": geometry.width_px * self.scale,
                "png_pixel_height": geometry.height_px * self.scale,
                "current_pose": {},
                "goal_pose": {},
                "waypoints": [dict(zip(("x", "y"), self.to_pixels(w.x, w.y), strict=True), name=w.name)
                              for w in definition.waypoints],
            },
        }

    @property
    def name(self) -> str:
        return self.definition.name

    def to_pixels(self, x: float, y: float) -> tuple[float, float]:
        return self.geometry.to_display(x, y, self.cm_per_pixel)

    def to_world(self, px: float, py: float) -> tuple[float, float]:
        return self.geometry.from_display(px, py, self.cm_per_pixel)

    def _scaled(self, pose: Pose2D) -> dict:
        px, py = self.to_pixels(pose.x, pose.y)
        if not (math.isfinite(px) and math.isfinite(py)):  # a finite pose can still overflow in pixels
            px = py = None
        return {"x": px, "y": py, "yaw": self.geometry.yaw_to_image(pose.yaw),
                "inside": self.geometry.contains(pose.x, pose.y)}

    def update_current_pose(self, pose: Pose2D | None, *, age_s: float | None = None, stale: bool = False) -> None:
        params, scaled = self.map_state["map_parameters"], self.map_state["scaled_pixel_values"]
        if pose is None:
            params["current_pose"], scaled["current_pose"] = {}, {}
            return
        params["current_pose"] = {"x": pose.x, "y": pose.y, "yaw": pose.yaw, "frame_id": pose.frame_id,
                                  "stamp": pose.stamp_s, "age_s": age_s, "stale": stale}
        scaled["current_pose"] = self._scaled(pose)

    def update_goal_pose(self, pose: Pose2D | None) -> None:
        params, scaled = self.map_state["map_parameters"], self.map_state["scaled_pixel_values"]
        if pose is None:
            params["goal_pose"], scaled["goal_pose"] = {}, {}
            return
        params["goal_pose"] = {"x": pose.x, "y": pose.y, "yaw": pose.yaw, "frame_id": pose.frame_id,
                               "stamp": pose.stamp_s}
        scaled["goal_pose"] = self._scaled(pose)


class RobotTrack:
    """The robot's latest pose, goal and plan, shared by ROS callbacks and request threads."""

    def __init__(self, stale_after_s: float, clock: Callable[[], float] = time.monotonic):
        self.stale_after_s = stale_after_s  # 0: a pose never goes stale
        self._clock = clock
        self._lock = threading.Lock()
        self._pose: Pose2D | None = None
        self._pose_at = -math.inf
        self._goal: Pose2D | None = None
        self._plan: dict | None = None

    def set_pose(self, pose: Pose2D) -> None:
        with self._lock:
            self._pose, self._pose_at = pose, self._clock()

    def pose(self) -> tuple[Pose2D | None, float | None, bool]:
        """(pose, its age in seconds, stale?) — stale also when there is no pose at all."""
        with self._lock:
            pose, at = self._pose, self._pose_at
        if pose is None:
            return None, None, True
        age = max(0.0, self._clock() - at)
        return pose, age, self.is_stale_age(age)

    def is_stale_age(self, age_s: float) -> bool:
        return self.stale_after_s > 0 and age_s > self.stale_after_s

    def set_goal(self, goal: Pose2D) -> bool:
        """Record a goal; False if it is the one already recorded (our own publication, heard back)."""
        with self._lock:
            old = self._goal
            if old is not None and (goal.frame_id, goal.stamp_s) == (old.frame_id, old.stamp_s) and all(
                    math.isclose(a, b, abs_tol=1e-9) for a, b in ((goal.x, old.x), (goal.y, old.y),
                                                                  (goal.yaw, old.yaw))):
                return False  # yaw -> quaternion -> yaw may differ in the last bit
            self._goal = goal
            return True

    def goal(self) -> Pose2D | None:
        with self._lock:
            return self._goal

    def set_plan(self, plan: dict) -> None:
        with self._lock:
            self._plan = plan

    def plan(self) -> dict | None:
        with self._lock:
            return self._plan


def downsample(points: Sequence, max_points: int) -> list:
    """At most max_points of a path, evenly spread, always keeping the first and the last."""
    n = len(points)
    if n <= max_points:
        return list(points)
    if max_points < 2:
        return [points[-1]] if max_points == 1 else []
    step = (n - 1) / (max_points - 1)
    return [points[round(i * step)] for i in range(max_points)]


def _r(value: float, digits: int) -> float:
    return round(value, digits) + 0.0  # + 0.0 turns -0.0 into 0.0


def pose_payload(pose: Pose2D, maps: Iterable[MapDefinition], *, stale: bool = False,
                 age_s: float | None = 0.0) -> dict:
    """The `pose` channel: map metres, plus the pose in image pixels of every map (native scale)."""
    pixels = {}
    for definition in maps:
        g = definition.geometry
        px, py = g.world_to_pixel(pose.x, pose.y)
        finite = math.isfinite(px) and math.isfinite(py)  # 1e308 m is finite, its pixel column is not
        pixels[definition.name] = {"x": _r(px, 2) if finite else None, "y": _r(py, 2) if finite else None,
                                   "yaw": _r(g.yaw_to_image(pose.yaw), 4), "inside": g.contains(pose.x, pose.y)}
    return {"x": _r(pose.x, 4), "y": _r(pose.y, 4), "yaw": _r(wrap_angle(pose.yaw), 4), "frame_id": pose.frame_id,
            "stamp": _r(pose.stamp_s, 6), "stale": stale, "age_s": None if age_s is None else _r(age_s, 2),
            "pixels": pixels}


def goal_payload(goal: Pose2D, maps: Iterable[MapDefinition]) -> dict:
    payload = pose_payload(goal, maps)
    del payload["stale"], payload["age_s"]
    return payload


def plan_payload(frame_id: str, points: Sequence[tuple[float, float]], max_points: int) -> dict:
    kept = downsample(points, max_points)
    return {"frame_id": frame_id, "length": len(points),
            "points": [[_r(x, 3), _r(y, 3)] for x, y in kept]}
