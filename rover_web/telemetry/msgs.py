"""Telemetry's messages: nav_msgs/Odometry read into the `odom` channel's plain values."""

from __future__ import annotations

import math

from rover_web.ros import cdr
from rover_web.ros.convert import stamp_to_float, yaw_from_quaternion

ODOMETRY = "nav_msgs/msg/Odometry"
BATTERY_STATE = "sensor_msgs/msg/BatteryState"
# sensor_msgs/BatteryState power_supply_status
SUPPLY_STATUS = {1: "charging", 2: "discharging", 3: "not charging", 4: "full"}


def battery_summary(msg) -> dict:
    """The level a person reads; a field the driver left NaN (unknown) becomes None, never NaN."""
    def known(value: float, scale: float = 1.0, digits: int = 2):
        return round(value * scale, digits) if math.isfinite(value) else None

    return {
        "percent": known(msg.percentage, 100.0, 1),
        "voltage": known(msg.voltage),
        "status": SUPPLY_STATUS.get(msg.power_supply_status, "unknown"),
        "stamp": stamp_to_float(msg.header.stamp),
    }


def odom_summary(msg) -> dict:
    pose, twist = msg.pose.pose, msg.twist.twist
    q = pose.orientation
    return {
        "x": round(pose.position.x, 3),
        "y": round(pose.position.y, 3),
        "yaw": round(yaw_from_quaternion(q.x, q.y, q.z, q.w), 4),
        "linear": round(twist.linear.x, 3),
        "angular": round(twist.angular.z, 3),
        "frame_id": msg.header.frame_id,
        "stamp": stamp_to_float(msg.header.stamp),
    }


def odom_summary_cdr(raw: bytes) -> dict:
    """odom_summary from the serialized message, reading only the fields shown (ros/cdr.py says why)."""
    try:
        f = cdr.odometry(raw)
    except cdr.NotPlainCdr:
        return odom_summary(cdr.deserialize(raw, ODOMETRY))
    return {
        "x": round(f.x, 3),
        "y": round(f.y, 3),
        "yaw": round(yaw_from_quaternion(f.qx, f.qy, f.qz, f.qw), 4),
        "linear": round(f.linear_x, 3),
        "angular": round(f.angular_z, 3),
        "frame_id": f.frame_id,
        "stamp": f.sec + f.nanosec * 1e-9,
    }
