"""Telemetry's messages: nav_msgs/Odometry read into the `odom` channel's plain values."""

from __future__ import annotations

from rover_web.ros.convert import stamp_to_float, yaw_from_quaternion

ODOMETRY = "nav_msgs/msg/Odometry"


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
