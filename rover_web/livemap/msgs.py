"""LiveMap's messages: poses, goals, paths and occupancy grids read into plain values, goals built."""

from __future__ import annotations

import numpy as np

from rover_web.ros.convert import quaternion_from_yaw, stamp_to_float, yaw_from_quaternion
from rover_web.ros.typesupport import message_class

AMCL_POSE = "geometry_msgs/msg/PoseWithCovarianceStamped"
POSE_STAMPED = "geometry_msgs/msg/PoseStamped"
PATH = "nav_msgs/msg/Path"
OCCUPANCY_GRID = "nav_msgs/msg/OccupancyGrid"


def _pose_values(pose) -> tuple[float, float, float]:
    q = pose.orientation
    return pose.position.x, pose.position.y, yaw_from_quaternion(q.x, q.y, q.z, q.w)


def pose_from_amcl(msg) -> tuple[float, float, float, str, float]:
    """(x, y, yaw, frame_id, stamp seconds) of a PoseWithCovarianceStamped."""
    return (*_pose_values(msg.pose.pose), msg.header.frame_id, stamp_to_float(msg.header.stamp))


def pose_from_stamped(msg) -> tuple[float, float, float, str, float]:
    return (*_pose_values(msg.pose), msg.header.frame_id, stamp_to_float(msg.header.stamp))


def stamp_seconds(stamp) -> float:
    """A builtin_interfaces/Time (e.g. from RosRuntime.now_msg) in seconds."""
    return stamp_to_float(stamp)


def goal_message(x: float, y: float, yaw: float, frame_id: str, stamp):
    """A fresh PoseStamped for /goal_pose."""
    msg = message_class(POSE_STAMPED)()
    msg.header.stamp = stamp
    msg.header.frame_id = frame_id
    msg.pose.position.x, msg.pose.position.y = float(x), float(y)
    o = msg.pose.orientation
    o.x, o.y, o.z, o.w = quaternion_from_yaw(yaw)
    return msg


def initial_pose_message(x: float, y: float, yaw: float, covariance, frame_id: str, stamp):
    """A fresh PoseWithCovarianceStamped for /initialpose (what RViz's 2D Pose Estimate sends)."""
    msg = message_class(AMCL_POSE)()
    msg.header.stamp = stamp
    msg.header.frame_id = frame_id
    msg.pose.pose.position.x, msg.pose.pose.position.y = float(x), float(y)
    o = msg.pose.pose.orientation
    o.x, o.y, o.z, o.w = quaternion_from_yaw(yaw)
    msg.pose.covariance = [float(v) for v in covariance]
    return msg


def path_points(msg) -> tuple[str, list[tuple[float, float]], float]:
    """(frame_id, [(x, y), ...], stamp seconds) of a nav_msgs/Path."""
    return (msg.header.frame_id, [(p.pose.position.x, p.pose.position.y) for p in msg.poses],
            stamp_to_float(msg.header.stamp))


def occupancy_grid(msg) -> tuple[dict, np.ndarray]:
    """(info, cells) of an OccupancyGrid: width, height, resolution, origin [x, y, yaw], frame_id."""
    info = msg.info
    origin = info.origin
    cells = np.frombuffer(bytes(memoryview(msg.data)), dtype=np.int8) if len(msg.data) else np.zeros(0, np.int8)
    return ({"width": int(info.width), "height": int(info.height), "resolution": float(info.resolution),
             "origin": list(_pose_values(origin)), "frame_id": msg.header.frame_id}, cells)
