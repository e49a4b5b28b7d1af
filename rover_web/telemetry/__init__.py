"""The robot's odometry on the dashboard (`odom` channel): the foundation's own live topic."""

from __future__ import annotations

import math

from rover_web.core.state import Rover
from rover_web.ros.convert import stamp_to_float, yaw_from_quaternion

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


def init_app(app, rover: Rover) -> None:
    rover.hub.register("odom")
    # Odometry often arrives at 50-100 Hz; a person reads a speed at a few Hz.
    max_hz = rover.config["ROVER_WEB_ODOM_MAX_HZ"]

    def on_odom(msg) -> None:
        summary = odom_summary(msg)
        if all(isinstance(v, str) or math.isfinite(v) for v in summary.values()):  # a NaN pose is not shown
            rover.hub.publish_throttled("odom", summary, max_hz)

    rover.runtime.subscribe("nav_msgs/msg/Odometry", rover.config["ROVER_WEB_ODOM_TOPIC"], on_odom, qos=10)
    rover.add_panel(10, "panels/odom.html", "Robot", channels=("odom",))
