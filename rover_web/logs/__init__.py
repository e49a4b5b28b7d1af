"""The /rosout log: GET /logs, GET /api/rosout, the `rosout` and `rosout_health` channels.

ROS: subscribes rcl_interfaces/msg/Log on /rosout with the QoS rcl publishes it with (reliable,
transient local, depth 1000). The last ROVER_WEB_ROSOUT_KEEP lines are kept in a ring; new lines
go to browsers in batches every 0.25 s on `rosout`; `rosout_health` carries the count of errors in
the last minute for the health bar of every page.
Modules: ring (the bounded ring, filters, grouping of repeats), msgs.
"""

from __future__ import annotations

from rover_web.core.state import Rover
from rover_web.i18n import N_

from . import routes
from .service import BATCH_PERIOD_S, HEALTH_PERIOD_S, RosoutLog


def init_app(app, rover: Rover) -> None:
    log = RosoutLog(rover)
    rover.add_feature(log)
    rover.hub.register("rosout", "rosout_health")
    log.subscribe()
    app.register_blueprint(routes.bp)
    rover.add_nav(N_("Logs"), "/logs")
    rover.every(BATCH_PERIOD_S, log.flush, name="rosout-batches")
    rover.every(HEALTH_PERIOD_S, log.publish_health, name="rosout-health", immediately=True)
