"""Telemetry's messages: nav_msgs/Odometry read into the `odom` channel's plain values."""

from __future__ import annotations

import math

from rover_web.i18n import N_
from rover_web.ros import cdr
from rover_web.ros.convert import stamp_to_float, yaw_from_quaternion

ODOMETRY = "nav_msgs/msg/Odometry"
BATTERY_STATE = "sensor_msgs/msg/BatteryState"
# sensor_msgs/BatteryState power_supply_status
# Message ids: the page translates them where it shows them (templates/panels/odom.html).
SUPPLY_STATUS = {1: N_("charging"), 2: N_("discharging"), 3: N_("not charging"), 4: N_("full")}


def battery_summary(msg) -> dict:
    """The level a person reads; a field the driver left NaN (unknown) becomes None, never NaN."""
    def known(value: float, scale: float = 1.0, digits: int = 2):
        return round(value * scale, digits) if math.isfinite(value) else None

    return {
        "percent": known(msg.percentage, 100.0, 1),
        "voltage": known(msg.voltage),
        "status": SUPPLY_STATUS.get(msg.power_supply_status, N_("unknown")),
        "stamp": stamp_to_float(msg.header.stamp),
    }


def _summary(x, y, qx, qy, qz, qw, linear, angular, frame_id, stamp) -> dict:
    return {
        "x": round(x, 3),
        "y": round(y, 3),
        "yaw": round(yaw_from_quaternion(qx, qy, qz, qw), 4),
        "linear": round(linear, 3),
        "angular": round(angular, 3),
        "frame_id": frame_id,
        "stamp": stamp,
    }


def odom_summary(msg) -> dict:
    pose, twist = msg.pose.pose, msg.twist.twist
    q = pose.orientation
    return _summary(pose.position.x, pose.position.y, q.x, q.y, q.z, q.w, twist.linear.x, twist.angular.z,
                    msg.header.frame_id, stamp_to_float(msg.header.stamp))


def odom_summary_cdr(raw: bytes) -> dict:
    """odom_summary from the serialized message, reading only the fields shown (ros/cdr.py says why)."""
    try:
        f = cdr.odometry(raw)
    except cdr.NotPlainCdr:
        return odom_summary(cdr.deserialize(raw, ODOMETRY))
    return _summary(f.x, f.y, f.qx, f.qy, f.qz, f.qw, f.linear_x, f.angular_z, f.frame_id, f.stamp)
