"""Messages of the waypoints feature: Float64MultiArray out (/waypoints, /mission), NavSatFix in."""

from __future__ import annotations

import math
from collections.abc import Sequence

from rover_web.ros import cdr
from rover_web.ros.typesupport import message_class

from .gps import FixReading
from .heading import yaw_of_quaternion

FLOAT64_MULTI_ARRAY = "std_msgs/msg/Float64MultiArray"
NAV_SAT_FIX = "sensor_msgs/msg/NavSatFix"
# ROVER_WEB_GPS_HEADING_TYPE -> the message type its topic carries
HEADING_TYPES = {"odometry": "nav_msgs/msg/Odometry", "imu": "sensor_msgs/msg/Imu",
                 "pose": "geometry_msgs/msg/PoseStamped"}


def waypoint_message(lng: float, lat: float):
    """data [lng, lat] with an empty layout, exactly as the RobotX GUI published it."""
    msg = message_class(FLOAT64_MULTI_ARRAY)()
    msg.data = [float(lng), float(lat)]
    return msg


def mission_message(points: Sequence[tuple[float, float]]):
    """The ordered mission as one n x 2 row-major array: [lng0, lat0, lng1, lat1, ...].

    dim[0] "waypoints" (size n, stride 2n) and dim[1] "lng_lat" (size 2, stride 2), following the
    MultiArrayLayout convention that a dimension's stride is the number of elements it spans.
    """
    cls = message_class(FLOAT64_MULTI_ARRAY)
    dim_cls = message_class("std_msgs/msg/MultiArrayDimension")
    msg = cls()
    n = len(points)
    msg.layout.dim = [dim_cls(label="waypoints", size=n, stride=2 * n),
                      dim_cls(label="lng_lat", size=2, stride=2)]
    msg.layout.data_offset = 0
    msg.data = [float(v) for lng, lat in points for v in (lng, lat)]
    return msg


def fix_reading(msg) -> FixReading:
    """The numbers the map needs from a NavSatFix; judging them is gps.py's job."""
    sigma = None
    if msg.position_covariance_type != 0:  # COVARIANCE_TYPE_UNKNOWN
        cov = msg.position_covariance
        east, north = float(cov[0]), float(cov[4])
        if math.isfinite(east) and math.isfinite(north) and east >= 0 and north >= 0:
            sigma = math.sqrt((east + north) / 2)
    return FixReading(status=int(msg.status.status), lat=float(msg.latitude), lng=float(msg.longitude),
                      alt=float(msg.altitude), horizontal_sigma_m=sigma, frame_id=msg.header.frame_id)


def heading_yaw(msg, kind: str) -> float | None:
    """Yaw (radians, ENU) of an Odometry, Imu or PoseStamped; None when it carries no orientation."""
    if kind == "imu":
        if msg.orientation_covariance[0] == -1.0:  # REP 145: this IMU gives no orientation
            return None
        q = msg.orientation
    elif kind == "odometry":
        q = msg.pose.pose.orientation
    else:
        q = msg.pose.orientation
    return yaw_of_quaternion(float(q.x), float(q.y), float(q.z), float(q.w))


def heading_orientation(msg, kind: str) -> tuple[tuple[float, float, float, float] | None, str]:
    """(orientation x, y, z, w or None, the frame it is the orientation of) of an Imu or PoseStamped:
    an IMU's is its own frame's (header.frame_id, REP 145), a pose's its header's frame's child,
    taken as the base (no sensor to correct for)."""
    if kind == "imu":
        if msg.orientation_covariance[0] == -1.0:
            return None, ""
        q = msg.orientation
        return (float(q.x), float(q.y), float(q.z), float(q.w)), msg.header.frame_id
    q = msg.pose.orientation
    return (float(q.x), float(q.y), float(q.z), float(q.w)), ""


def odometry_yaw(raw: bytes) -> float | None:
    """heading_yaw of a serialized nav_msgs/Odometry, reading only its orientation (ros/cdr.py)."""
    try:
        f = cdr.odometry(raw)
    except cdr.NotPlainCdr:
        return heading_yaw(cdr.deserialize(raw, HEADING_TYPES["odometry"]), "odometry")
    return yaw_of_quaternion(f.qx, f.qy, f.qz, f.qw)
