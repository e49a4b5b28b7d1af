"""Telemetry: the robot's odometry on the dashboard, the foundation's own live topic.

ROS: subscribes nav_msgs/Odometry on ROVER_WEB_ODOM_TOPIC.
SSE: `odom` (at most ROVER_WEB_ODOM_MAX_HZ). No routes; a dashboard card (panels/odom.html).
Modules: msgs (odom_summary).
"""

from __future__ import annotations

import math

from rover_web.core.state import Rover

from . import msgs


def init_app(app, rover: Rover) -> None:
    rover.hub.register("odom")
    # Odometry often arrives at 50-100 Hz; a person reads a speed at a few Hz.
    max_hz = rover.config["ROVER_WEB_ODOM_MAX_HZ"]

    def on_odom(msg) -> None:
        summary = msgs.odom_summary(msg)
        if all(isinstance(v, str) or math.isfinite(v) for v in summary.values()):  # a NaN pose is not shown
            rover.hub.publish_throttled("odom", summary, max_hz)

    rover.runtime.subscribe(msgs.ODOMETRY, rover.config["ROVER_WEB_ODOM_TOPIC"], on_odom, qos=10)
    rover.add_panel(10, "panels/odom.html", "Robot", channels=("odom",))
