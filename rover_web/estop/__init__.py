"""The e-stop: one latch that stops everything the GUI can start, reachable from every page.

  GET  /api/estop    the latch: engaged, since, by, via, persisted, and the goal cancels' outcome
  POST /api/estop    {"engaged": true} engages (any signed-in user), {"engaged": false} releases (operator)
  POST /api/estop/all engages every robot's e-stop (any signed-in user)
  SSE  estop         the latch whenever it changes
  ROS  ROVER_WEB_ESTOP_TOPIC (std_msgs/Bool, reliable, transient local), republished every
       ROVER_WEB_ESTOP_REPEAT_S; CancelGoal to every action in ROVER_WEB_ESTOP_CANCEL_ACTIONS on engage.
Each robot has its own latch (and topic, under its namespace).
Other features gate motion with `rover.feature(EStopService).check_motion()` and react with
`on_engage` / `on_release`.
"""

from __future__ import annotations

from flask import Flask

from rover_web.config import TOPIC_PATTERN, ConfigError
from rover_web.core.fleet import Fleet
from rover_web.core.state import Rover, current_feature
from rover_web.ros.actions import GoalCanceller

from . import msgs, routes
from .fleet import FleetEStop
from .service import CHANNEL, EStopEngaged, EStopService
from .store import EStopStore

__all__ = ["init_app", "EStopService", "EStopEngaged", "FleetEStop"]


def init_app(app: Flask, fleet: Fleet) -> None:
    for rover in fleet:
        _init_robot(rover)
    fleet.graph.add_feature(FleetEStop({rover.robot.name: rover.feature(EStopService) for rover in fleet}))
    app.register_blueprint(routes.bp)

    @app.context_processor
    def _estop_context():
        return {"estop_state": current_feature(EStopService).state()}


def _init_robot(rover: Rover) -> None:
    config = rover.config
    actions = config["ROVER_WEB_ESTOP_CANCEL_ACTIONS"]
    for name in actions:
        if not isinstance(name, str) or not TOPIC_PATTERN.match(name):
            raise ConfigError(f"ROVER_WEB_ESTOP_CANCEL_ACTIONS: {name!r} is not an action name such as "
                              "/navigate_to_pose")
    flag = rover.runtime.publisher(msgs.MSG_TYPE, config["ROVER_WEB_ESTOP_TOPIC"], qos="latched")
    canceller = GoalCanceller(rover.runtime, actions, rover.robot.namespace) if actions else None
    rover.hub.register(CHANNEL)
    estop = EStopService(
        EStopStore(rover.db),
        zero=rover.cmd_vel.zero,
        hold=rover.cmd_vel.hold_zero, unhold=rover.cmd_vel.release_hold,
        publish_flag=lambda engaged: flag.publish(msgs.flag(engaged)),
        canceller=canceller,
        on_change=lambda state: rover.hub.publish(CHANNEL, state))
    rover.add_feature(estop)
    # Who engaged and released it, for recordings (events/audit.py); `via` says from where.
    estop.on_engage(lambda by: rover.audit.record("estop.engage", by=by, detail=f"e-stop engaged by {by}",
                                                  via=estop.state().get("via")))
    estop.on_release(lambda by: rover.audit.record("estop.release", by=by, detail=f"e-stop released by {by}"))
    rover.hub.publish(CHANNEL, estop.state())
    estop.republish()  # a late joiner gets the latch from the transient-local history at once
    rover.every(config["ROVER_WEB_ESTOP_REPEAT_S"], estop.republish, name="estop-republish")
    rover.every(1.0 / config["ROVER_WEB_TELEOP_RATE_HZ"], estop.hold, name="estop-hold-zero",
                only_while=estop.engaged_event)  # asleep unless engaged: no 40 Hz wake-ups all day
