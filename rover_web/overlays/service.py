"""The overlays of one robot: its scan, costmaps, markers and footprint turned into map-frame channels.

Each message is converted once, in the subscription callback, into the small value the page
draws, and each channel is rate-limited on the server (the page could not draw more anyway).
Costmaps are the expensive one: a new grid is only kept, and a loop off the executor encodes the
newest grid of each topic, at most ROVER_WEB_COSTMAP_MAX_HZ times a second. Messages that cannot be drawn are
skipped and counted by reason (`GET /api/overlays`), never raised.

Each message is placed in the map frame through TF (map <- its header's frame at its stamp, one
lookup per message: rover_web/placement.py) when TF knows its frame; otherwise with the fallback
it had before TF: the configured laser offset and AMCL's pose, map -> odom rebuilt from two poses
(frames.py). Every layer says which placed its latest message (`placed_by`).
"""

from __future__ import annotations

import dataclasses
import logging
import math
import threading
import time
from typing import Any

import numpy as np

from rover_web.config import ConfigError
from rover_web.core.state import Rover
from rover_web.i18n import N_
from rover_web.placement import CONFIGURED, IDENTITY, MAP, TF, MapPlacer, Planar, Unplaceable, heading, tf_buffer
from rover_web.ros import cdr
from rover_web.ros.convert import yaw_from_quaternion

from . import costmap, scan
from .counts import LayerCounts
from .frames import OdomInMap, compose
from .markers import MAP_FRAMES, ROBOT_FRAMES, BadMarker, MarkerSet, robot_frames
from .poses import PoseHistory

log = logging.getLogger(__name__)

FOOTPRINT_MAX_HZ = 5.0
COSTMAP_CHECK_S = 0.05  # how often the encoding loop looks for a new grid: the most it adds to a grid's age
FOOTPRINT_MAX_POINTS = 200
CHANNELS = ("scan", "scan3d", "costmap", "markers", "footprint")
AMCL_QUIET_S = 2.0  # no AMCL pose this long: the robot's pose history is fed from TF's map -> base_link
TF_POSE_S = 0.2  # how often then (the path keeps a point per 5 cm: 5 a second is plenty)


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
        self.placer = MapPlacer(tf_buffer(rover) if hasattr(rover, "feature") else None,
                                config.get("ROVER_WEB_MAP_FRAME", "map"))
        self.map_frames.add(self.placer.map_frame)
        self.base_frame = config.get("ROVER_WEB_BASE_FRAME", "base_link")
        self._amcl_at = -math.inf
        self._tf_stamp: int | None = None
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
        self._placed_lock = threading.Lock()
        self._placed_by: dict[str, str] = {}  # costmap topic -> how its newest grid was placed
        self._next_encode = 0.0  # monotonic time the next encoding may start
        self._markers = MarkerSet(max_points=config["ROVER_WEB_MARKERS_MAX_POINTS"])
        self._markers_lock = threading.Lock()

    # --- the robot's pose ---

    def on_pose(self, stamp: float, x: float, y: float, yaw: float) -> None:
        if all(map(math.isfinite, (stamp, x, y, yaw))):
            self._amcl_at = time.monotonic()
            self.poses.add(stamp, x, y, yaw)
            self.odom_frame.on_map_pose(stamp, (x, y, yaw))

    def pose_from_tf(self) -> None:
        """One tick: with AMCL quiet, the recent path (and the fallback's robot) from TF's map -> base_link."""
        buffer = self.placer.buffer
        if buffer is None or time.monotonic() - self._amcl_at < AMCL_QUIET_S:
            return
        from rover_web.tf.buffer import TfError

        try:
            t = buffer.lookup(self.placer.map_frame, self.base_frame, None)
        except TfError:
            return
        if t.stamp_ns != self._tf_stamp:
            self._tf_stamp = t.stamp_ns
            self.poses.add(t.stamp_ns / 1e9, t.translation[0], t.translation[1], t.yaw)

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
        placement = None
        if frame in self.map_frames:
            placed_by = MAP  # a scan already in the map frame
        else:
            try:
                placement = self.placer.lookup(frame, value.stamp)
            except Unplaceable as exc:
                counts.skip(str(exc))
                return
            placed_by = TF if placement is not None else CONFIGURED
            if placement is None:
                robot = self.poses.at(value.stamp)
                if robot is None:
                    counts.skip("no_pose")
                    return
                placement = Planar(*robot).compose_2d(self.laser)
        thinned = scan.thin_both(value, self.scan_bins)
        # NaN, inf and out-of-range beams are no return, as RViz shows them: counted, not drawn. A
        # scan with none left is still sent, empty: the robot sees nothing in range (an open field,
        # a laser inside a wall), and the page must not keep showing the last scan's points.
        counts.drop(thinned.invalid)
        placement = placement or IDENTITY
        points = self._place_returns(placement, thinned.angles, thinned.ranges)
        far = self._place_returns(placement, thinned.far_angles, thinned.far_ranges)
        counts.send(placed_by)
        self.hub.publish_throttled("scan", scan.payload(self.scan_topic, value, heading(placement, 0.0, 0.0, 0.0),
                                                        points[:, :2], far[:, :2], placed_by), self.scan_max_hz)
        if self.hub.watchers("scan3d") > 0:
            # The 3D view's: the same returns with their height, where TF put the laser at the scan's stamp
            # (a tilted laser's returns slope); placed by the configured offsets, they are at z = 0.
            self.hub.publish_throttled("scan3d", scan.payload_3d(self.scan_topic, value, np.vstack((points, far)),
                                                                 placed_by), self.scan_max_hz)

    @staticmethod
    def _place_returns(placement, angles, ranges):
        """Returns in the laser's frame, placed in 3D (a tilted laser too), as (N, 3) map points."""
        xs, ys = scan.in_sensor_frame(angles, ranges)
        mx, my, mz = placement.apply_many(xs, ys, None)
        return np.column_stack((mx, my, mz))

    # --- costmaps ---

    def on_costmap(self, topic: str, grid: costmap.Grid) -> None:
        counts = self.counts["costmap"]
        counts.receive()
        try:
            costmap.check(grid, self.costmap_max_cells)
        except costmap.BadGrid as exc:
            counts.skip(str(exc))
            return
        placed_by = MAP
        if grid.frame_id.lstrip("/") not in self.map_frames:
            try:
                placement = self.placer.lookup(grid.frame_id, grid.stamp)
            except Unplaceable as exc:
                counts.skip(str(exc))
                return
            if placement is not None:
                placed_by, origin = TF, heading(placement, *grid.origin)
            else:
                map_t_odom = self.odom_frame.transform(grid.frame_id)
                if map_t_odom is None:
                    counts.skip("unknown_frame")
                    return
                placed_by, origin = CONFIGURED, compose(map_t_odom, grid.origin)
            grid = dataclasses.replace(grid, frame_id="map", origin=origin)
        with self._placed_lock:
            self._placed_by[topic] = placed_by
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
            with self._placed_lock:
                encoded["placed_by"] = self._placed_by.get(topic, MAP)
            self.counts["costmap"].send(encoded["placed_by"])
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
        placed: list[str] = []
        lookups: dict[tuple[str, float], tuple] = {}  # one lookup per frame and stamp of the array

        def place(frame: str, stamp: float):
            key = (frame, stamp)
            if key not in lookups:
                lookups[key] = self._place_marker(frame, stamp, robot)
            placement, how = lookups[key]
            placed.append(how)
            return placement, how

        with self._markers_lock:
            for marker in markers:
                try:
                    self._markers.apply(marker, place, now)
                except BadMarker as exc:
                    counts.skip(str(exc))
            payload = self._markers.payload(self.markers_topic)
        counts.send(TF if TF in placed else (placed[-1] if placed else None))
        self.hub.publish_throttled("markers", payload, self.markers_max_hz)

    def _place_marker(self, frame: str, stamp: float, robot):
        if frame in self.map_frames:
            return IDENTITY, MAP
        try:
            placement = self.placer.lookup(frame, stamp)
        except Unplaceable as exc:
            raise BadMarker(str(exc)) from None
        if placement is not None:
            return placement, TF
        return robot_frames(robot)(frame, stamp)

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
        try:
            placement = None if frame in self.map_frames else self.placer.lookup(frame, stamp)
        except Unplaceable as exc:
            counts.skip(str(exc))
            return
        placed_by = CONFIGURED
        if frame in self.map_frames:
            polygon, placed_by = points, MAP
        elif placement is not None:
            xs, ys, _ = placement.apply_many([p[0] for p in points], [p[1] for p in points], None)
            polygon, placed_by = list(zip(xs.tolist(), ys.tolist(), strict=True)), TF
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
        counts.send(placed_by)
        self.hub.publish_throttled("footprint", {
            "topic": self.footprint_topic, "frame_id": frame_id, "stamp": stamp, "placed_by": placed_by,
            "polygon": [[round(x, 3), round(y, 3)] for x, y in polygon]}, FOOTPRINT_MAX_HZ)

    # --- what the page and the API read ---

    def layers(self) -> list[dict]:
        """The map page's layer list, in drawing order from the bottom."""
        return [{"name": "costmap", "label": N_("Costmaps"), "topics": self.costmap_topics},
                {"name": "path", "label": N_("Recent path"), "topics": []},
                {"name": "footprint", "label": N_("Footprint"), "topics": self.counts["footprint"].topics},
                {"name": "markers", "label": N_("Markers"), "topics": self.counts["markers"].topics},
                {"name": "scan", "label": N_("Laser scan"), "topics": self.counts["scan"].topics}]

    def summary(self) -> dict:
        with self._placed_lock:
            costmaps = dict(self._placed_by)
        return {"layers": {name: c.snapshot() for name, c in self.counts.items()},
                "trail": self.poses.path(), "laser_offset": list(self.laser),
                "tf": self.placer.buffer is not None, "costmaps_placed_by": costmaps}
