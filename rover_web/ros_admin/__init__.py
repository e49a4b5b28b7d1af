"""Nodes, parameters, services and actions from the browser: GET /ros and its API.

  GET  /api/nodes                                   the graph's nodes, their topics, services, actions
  GET  /api/nodes/<node>/parameters                 (node without its leading '/': ns/talker)
  PUT  /api/nodes/<node>/parameters/<name>          {"value": v}
  GET  /api/services                                POST /api/services/call
  GET  /api/types/<pkg>/<msg|srv|action>/<Name>     a type's fields, for generated forms
  POST /api/actions/goal   GET /api/actions/goals   GET /api/actions/<goal_id>/events (SSE)
  POST /api/actions/<goal_id>/cancel                GET /api/ros/log (the operator log of all this)
Calls go through rover_web.ros.admin on a node and executor of their own; goals sent from here are
canceled when the e-stop engages. Writes need the admin role; ROVER_WEB_ROS_ADMIN (on, read-only,
off), ROVER_WEB_ROS_ADMIN_ALLOW/_DENY and ROVER_WEB_ROS_ADMIN_SAFETY_NODES bound them. See docs/ros_admin.md.
"""

from __future__ import annotations

import logging

from flask import Flask

from rover_web.config import ConfigError, defaults
from rover_web.core.state import Rover
from rover_web.estop import FleetEStop
from rover_web.i18n import N_

from . import routes
from .access import dropped, parse_rules
from .service import RosAdmin, rules_from

__all__ = ["init_app", "RosAdmin"]

log = logging.getLogger(__name__)


def init_app(app: Flask, rover: Rover) -> None:
    # Graph-wide: a call or goal names no robot, so any robot's e-stop refuses it and cancels it.
    try:
        rules = rules_from(rover.config)  # a bad entry stops the app at start, naming the setting
    except ValueError as exc:
        raise ConfigError(str(exc)) from None
    if rover.config["ROVER_WEB_ROS_ADMIN"] == "on":
        warn_dropped_defaults(rules.deny)
    estop = rover.feature(FleetEStop)
    admin = RosAdmin(rover, estop)
    rover.add_feature(admin)
    estop.on_engage(admin.on_estop)
    app.register_blueprint(routes.bp)
    if admin.mode != "off":
        rover.add_nav(N_("ROS"), "/ros")


def warn_dropped_defaults(deny) -> None:
    """Setting ROVER_WEB_ROS_ADMIN_DENY replaces the safe default list: one added entry (say
    `node:/px4*`) silently let /ros set use_sim_time and call every set_parameters again."""
    lost = dropped(deny, parse_rules(defaults()["ROVER_WEB_ROS_ADMIN_DENY"], "ROVER_WEB_ROS_ADMIN_DENY"))
    if lost:
        log.warning("ROVER_WEB_ROS_ADMIN_DENY replaces the default deny list and leaves out %d of its entries, "
                    "which /ros may now write to: %s. To keep them, list them in the setting too "
                    "(docs/ros_admin.md#allow-and-deny)", len(lost), ", ".join(str(r) for r in lost))
