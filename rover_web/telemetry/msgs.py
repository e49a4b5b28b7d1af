"""Telemetry's messages: nav_msgs/Odometry read into the `odom` channel's plain values."""

from __future__ import annotations

import math

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
