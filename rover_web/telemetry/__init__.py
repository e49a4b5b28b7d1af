"""Telemetry: the robot's odometry on the dashboard, the foundation's own live topic.

ROS: subscribes nav_msgs/Odometry on ROVER_WEB_ODOM_TOPIC and sensor_msgs/BatteryState on
ROVER_WEB_BATTERY_TOPIC, each robot on its own.
SSE: `odom` (at most ROVER_WEB_ODOM_MAX_HZ), `battery` (at most 1 Hz). No routes; a dashboard card
(panels/odom.html); /api/robots reads the channels' latest values.
Modules: msgs (odom_summary, odom_summary_cdr read from the raw bytes, battery_summary).
"""

from __future__ import annotations

import math

from rover_web.core.fleet import Fleet
from rover_web.core.state import Rover
from rover_web.i18n import N_

from . import msgs

BATTERY_MAX_HZ = 1.0  # a level that changes over minutes


def init_app(app, fleet: Fleet) -> None:
    for rover in fleet:
        _init_robot(rover)


def _init_robot(rover: Rover) -> None:
    rover.hub.register("odom", "battery")
    # Odometry often arrives at 50-100 Hz; a person reads a speed at a few Hz.
    max_hz = rover.config["ROVER_WEB_ODOM_MAX_HZ"]

    def on_odom(raw: bytes) -> None:
        summary = msgs.odom_summary_cdr(raw)
        if all(isinstance(v, str) or math.isfinite(v) for v in summary.values()):  # a NaN pose is not shown
            rover.hub.publish_throttled("odom", summary, max_hz)

    rover.runtime.subscribe(msgs.ODOMETRY, rover.config["ROVER_WEB_ODOM_TOPIC"], on_odom, qos=10, raw=True,
                            share=True)  # with the GPS heading (waypoints), when it reads /odom too
    rover.runtime.subscribe(msgs.BATTERY_STATE, rover.config["ROVER_WEB_BATTERY_TOPIC"],
                            lambda msg: rover.hub.publish_throttled("battery", msgs.battery_summary(msg),
                                                                    BATTERY_MAX_HZ), qos="sensor_data")
    rover.add_panel(10, "panels/odom.html", N_("Robot"), channels=("odom", "battery"))
