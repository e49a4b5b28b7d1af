"""The overlays' messages read into plain values: LaserScan, OccupancyGrid, MarkerArray, PolygonStamped."""

from __future__ import annotations

import numpy as np

from rover_web.livemap.msgs import occupancy_grid
from rover_web.ros.convert import stamp_to_float, yaw_from_quaternion
from rover_web.ros.graph import deserializer  # noqa: F401  (the feature's subscriptions take it from here)

from .bounds import FRAME_ID_MAX, MARKERS_MAX_COUNT, NS_MAX, TEXT_MAX
from .costmap import Grid
from .scan import Scan

LASER_SCAN = "sensor_msgs/msg/LaserScan"
OCCUPANCY_GRID = "nav_msgs/msg/OccupancyGrid"
MARKER_ARRAY = "visualization_msgs/msg/MarkerArray"
POLYGON_STAMPED = "geometry_msgs/msg/PolygonStamped"
AMCL_POSE = "geometry_msgs/msg/PoseWithCovarianceStamped"
ODOMETRY = "nav_msgs/msg/Odometry"


def _yaw(q) -> float:
    return yaw_from_quaternion(q.x, q.y, q.z, q.w)


def scan(msg) -> Scan:
    return Scan(msg.header.frame_id, stamp_to_float(msg.header.stamp), float(msg.angle_min),
                float(msg.angle_increment), float(msg.range_min), float(msg.range_max),
                np.asarray(msg.ranges, dtype=np.float32))


def grid(msg) -> Grid:
    info, cells = occupancy_grid(msg)  # LiveMap's reading of an OccupancyGrid, the same for a costmap
    return Grid(info["frame_id"], stamp_to_float(msg.header.stamp), info["width"], info["height"],
                info["resolution"], tuple(info["origin"]), cells)


def markers(msg, most: int = MARKERS_MAX_COUNT) -> list[dict]:
    """The first `most` markers of the array as plain values (the rest are counted by the caller,
    never converted), ns and text truncated."""
    out = []
    for m in msg.markers[:most]:
        p = m.pose
        c = m.color
        out.append({"ns": m.ns[:NS_MAX], "id": int(m.id), "type": int(m.type), "action": int(m.action),
                    "frame_id": m.header.frame_id[:FRAME_ID_MAX], "stamp": stamp_to_float(m.header.stamp),
                    "pose": (p.position.x, p.position.y, _yaw(p.orientation)),
                    "scale": (m.scale.x, m.scale.y, m.scale.z), "color": (c.r, c.g, c.b, c.a),
                    "points": [(q.x, q.y) for q in m.points],
                    "colors": [(k.r, k.g, k.b, k.a) for k in m.colors],
                    "text": m.text[:TEXT_MAX], "lifetime_s": m.lifetime.sec + m.lifetime.nanosec * 1e-9})
    return out


def polygon(msg) -> tuple[str, float, list[tuple[float, float]]]:
    return msg.header.frame_id, stamp_to_float(msg.header.stamp), [(p.x, p.y) for p in msg.polygon.points]


def amcl_pose(msg) -> tuple[float, float, float, float]:
    """(stamp, x, y, yaw) of a PoseWithCovarianceStamped."""
    p = msg.pose.pose
    return stamp_to_float(msg.header.stamp), p.position.x, p.position.y, _yaw(p.orientation)
