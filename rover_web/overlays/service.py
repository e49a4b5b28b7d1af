"""The overlays of one robot: its scan, costmaps, markers and footprint turned into map-frame channels.

Each message is converted once, in the subscription callback, into the small value the page
draws, and each channel is rate-limited on the server (the page could not draw more anyway).
Costmaps are the expensive one: a new grid is only kept, and a loop off the executor encodes the
newest grid of each topic, at most ROVER_WEB_COSTMAP_MAX_HZ times a second. Messages that cannot be drawn are
skipped and counted by reason (`GET /api/overlays`), never raised.
"""

from __future__ import annotations

import dataclasses
import logging
import math
import threading
import time
from typing import Any

from rover_web.config import ConfigError
from rover_web.core.state import Rover
from rover_web.ros import cdr
from rover_web.ros.convert import yaw_from_quaternion

from . import costmap, scan
from .counts import LayerCounts
from .frames import OdomInMap, compose
from .markers import MAP_FRAMES, ROBOT_FRAMES, BadMarker, MarkerSet
from .poses import PoseHistory

log = logging.getLogger(__name__)

FOOTPRINT_MAX_HZ = 5.0
COSTMAP_CHECK_S = 0.05  # how often the encoding loop looks for a new grid: the most it adds to a grid's age
FOOTPRINT_MAX_POINTS = 200
CHANNELS = ("scan", "costmap", "markers", "footprint")


def laser_offset(config: dict[str, Any]) -> tuple[float, float, float]:
    raw = config["ROVER_WEB_SCAN_LASER_OFFSET"]
    try:
        values = tuple(float(v) for v in raw)
    except ValueError:
        values = ()
    if len(values) != 3 or not all(map(math.isfinite, values)):
        raise ConfigError(f"ROVER_WEB_SCAN_LASER_OFFSET: expected x,y,yaw (three numbers), got {raw!r}")
    return values


class OverlayService:
    def __init__(self, rover: Rover):
        config = rover.config
        self.rover = rover
        self.hub = rover.hub
        self.scan_topic = config["ROVER_WEB_SCAN_TOPIC"]
        self.costmap_topics = list(config["ROVER_WEB_COSTMAP_TOPICS"])
        self.markers_topic = config["ROVER_WEB_MARKERS_TOPIC"]
        self.footprint_topic = config["ROVER_WEB_FOOTPRINT_TOPIC"]
        self.scan_bins = config["ROVER_WEB_SCAN_MAX_POINTS"]
        self.scan_max_hz = config["ROVER_WEB_SCAN_MAX_HZ"]
        self.laser = laser_offset(config)
        self.costmap_max_hz = config["ROVER_WEB_COSTMAP_MAX_HZ"]
        self.costmap_max_side = config["ROVER_WEB_COSTMAP_MAX_SIDE"]
        self.costmap_max_cells = config["ROVER_WEB_COSTMAP_MAX_CELLS"]
        self.markers_max_hz = config["ROVER_WEB_MARKERS_MAX_HZ"]
        self.map_frames = {*MAP_FRAMES, config["ROVER_WEB_GOAL_FRAME_ID"]}
        self.poses = PoseHistory(keep_s=config["ROVER_WEB_LIVEMAP_TRAIL_S"])
        self.odom_frame = OdomInMap()
        self.counts = {
            "scan": LayerCounts("scan", [self.scan_topic] if self.scan_topic else []),
            "costmap": LayerCounts("costmap", self.costmap_topics),
            "markers": LayerCounts("markers", [self.markers_topic] if self.markers_topic else []),
            "footprint": LayerCounts("footprint", [self.footprint_topic] if self.footprint_topic else []),
        }
        self._grids_lock = threading.Lock()
        self._pending: dict[str, costmap.Grid] = {}  # newest grid per topic, not yet encoded
        self._encoded: dict[str, dict] = {}  # topic -> its part of the costmap channel
        self._grid_seq = 0
        self._next_encode = 0.0  # monotonic time the next encoding may start
        self._markers = MarkerSet(max_points=config["ROVER_WEB_MARKERS_MAX_POINTS"])
        self._markers_lock = threading.Lock()

    # --- the robot's pose ---

    def on_pose(self, stamp: float, x: float, y: float, yaw: float) -> None:
        if all(map(math.isfinite, (stamp, x, y, yaw))):
            self.poses.add(stamp, x, y, yaw)
            self.odom_frame.on_map_pose(stamp, (x, y, yaw))

    def on_odom(self, raw: bytes) -> None:
        """The odometry's pose, for placing grids and footprints given in its frame (frames.py)."""
        try:
            f = cdr.odometry(raw)
        except cdr.NotPlainCdr:
            return
        self.odom_frame.on_odom(f.frame_id, f.stamp,
                                (f.x, f.y, yaw_from_quaternion(f.qx, f.qy, f.qz, f.qw)))

    # --- scan ---

    def on_scan(self, value: scan.Scan) -> None:
        counts = self.counts["scan"]
        counts.receive()
        try:
            scan.check(value)
        except scan.BadScan as exc:
            counts.skip(str(exc))
            return
        frame = value.frame_id.lstrip("/")
        if frame in self.map_frames:
            robot, laser = (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)  # a scan already in the map frame (a simulator's)
        else:
            robot, laser = self.poses.at(value.stamp), self.laser
            if robot is None:
                counts.skip("no_pose")
                return
        angles, ranges, invalid = scan.thin(value, self.scan_bins)
        # NaN, inf and out-of-range beams are no return, as RViz shows them: counted, not drawn. A
        # scan with none left is still sent, empty: the robot sees nothing in range (an open field,
        # a laser inside a wall), and the page must not keep showing the last scan's points.
        counts.drop(invalid)
        points = scan.to_map(angles, ranges, robot, laser)
        counts.send()
        self.hub.publish_throttled("scan", scan.payload(self.scan_topic, value, robot, points), self.scan_max_hz)

    # --- costmaps ---

    def on_costmap(self, topic: str, grid: costmap.Grid) -> None:
        counts = self.counts["costmap"]
        counts.receive()
        try:
            costmap.check(grid, self.costmap_max_cells)
        except costmap.BadGrid as exc:
            counts.skip(str(exc))
            return
        if grid.frame_id.lstrip("/") not in self.map_frames:
            map_t_odom = self.odom_frame.transform(grid.frame_id)
            if map_t_odom is None:
                counts.skip("unknown_frame")
                return
            grid = dataclasses.replace(grid, frame_id="map", origin=compose(map_t_odom, grid.origin))
        with self._grids_lock:
            self._pending[topic] = grid  # the encoding loop takes the newest

    def encode_costmaps(self) -> None:
        """Encode the newest grid of each topic that changed, then publish every costmap once; at
        most costmap_max_hz times a second. Runs on a loop of its own (COSTMAP_CHECK_S), off the executor."""
        now = time.monotonic()
        with self._grids_lock:
            if not self._pending or now < self._next_encode:
                return
            pending, self._pending = self._pending, {}
        self._next_encode = now + 1.0 / self.costmap_max_hz
        for topic, grid in pending.items():
            self._grid_seq += 1
            encoded = costmap.encode(grid, topic, self._grid_seq, self.costmap_max_side)
            self.counts["costmap"].send()
            with self._grids_lock:
                self._encoded[topic] = encoded
        # Only the grids that changed carry their cells: a global costmap that changes once a minute
        # is not sent again with every local one. A page missing a grid's cells (one opened since)
        # reads them from GET /api/overlays?costmaps=1.
        with self._grids_lock:
            layers = [self._encoded[t] if t in pending else {**self._encoded[t], "data": None}
                      for t in self.costmap_topics if t in self._encoded]
        self.hub.publish("costmap", {"costmaps": layers})

    def costmaps(self) -> list[dict]:
        """Every costmap's newest encoding, cells included."""
        with self._grids_lock:
            return [self._encoded[t] for t in self.costmap_topics if t in self._encoded]

    # --- markers ---

    def on_markers(self, markers: list[dict], over: int = 0) -> None:
        """`over`: markers of the array past the count cap, never converted (bounds.py)."""
        counts = self.counts["markers"]
        counts.receive()
        if over > 0:
            counts.skip("too_many_markers", over)
        if not markers:
            counts.skip("empty")
            return
        robot = self.poses.latest()
        now = time.monotonic()
        with self._markers_lock:
            for marker in markers:
                try:
                    self._markers.apply(marker, robot, now)
                except BadMarker as exc:
                    counts.skip(str(exc))
            payload = self._markers.payload(self.markers_topic)
        counts.send()
        self.hub.publish_throttled("markers", payload, self.markers_max_hz)

    def expire_markers(self) -> None:
        with self._markers_lock:
            if not self._markers.expire(time.monotonic()):
                return
            payload = self._markers.payload(self.markers_topic)
        self.hub.publish_throttled("markers", payload, self.markers_max_hz)

    # --- footprint ---

    def on_footprint(self, frame_id: str, stamp: float, points: list[tuple[float, float]]) -> None:
        counts = self.counts["footprint"]
        counts.receive()
        if len(points) < 2 or len(points) > FOOTPRINT_MAX_POINTS:
            counts.skip("empty" if len(points) < 2 else "too_large")
            return
        if not all(math.isfinite(v) for p in points for v in p):
            counts.skip("not_finite")
            return
        frame = frame_id.lstrip("/")
        if frame in self.map_frames:
            polygon = points
        elif frame in ROBOT_FRAMES:
            robot = self.poses.at(stamp)
            if robot is None:
                counts.skip("no_pose")
                return
            x0, y0, yaw = robot
            c, s = math.cos(yaw), math.sin(yaw)
            polygon = [(x0 + c * x - s * y, y0 + s * x + c * y) for x, y in points]
        elif (map_t_odom := self.odom_frame.transform(frame)) is not None:
            polygon = [compose(map_t_odom, (x, y, 0.0))[:2] for x, y in points]
        else:
            counts.skip("unknown_frame")
            return
        counts.send()
        self.hub.publish_throttled("footprint", {
            "topic": self.footprint_topic, "frame_id": frame_id, "stamp": stamp,
            "polygon": [[round(x, 3), round(y, 3)] for x, y in polygon]}, FOOTPRINT_MAX_HZ)

    # --- what the page and the API read ---

    def layers(self) -> list[dict]:
        """The map page's layer list, in drawing order from the bottom."""
        return [{"name": "costmap", "label": "Costmaps", "topics": self.costmap_topics},
                {"name": "path", "label": "Recent path", "topics": []},
                {"name": "footprint", "label": "Footprint", "topics": self.counts["footprint"].topics},
                {"name": "markers", "label": "Markers", "topics": self.counts["markers"].topics},
                {"name": "scan", "label": "Laser scan", "topics": self.counts["scan"].topics}]

    def summary(self) -> dict:
        return {"layers": {name: c.snapshot() for name, c in self.counts.items()},
                "trail": self.poses.path(), "laser_offset": list(self.laser)}
