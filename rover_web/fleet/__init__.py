"""Several robots from one GUI: ROVER_WEB_ROBOTS, /robots/<name>/..., /api/robots and /robots.

  GET  /api/robots          every robot: name, namespace, kind, its URL, link, mode, speed, battery,
                            e-stop and position
  GET  /robots              the fleet page: the same, and every robot on one GPS map
  ANY  /robots/<name>/...   every page and API route, for robot <name> (prefix.py)
  POST /api/estop/all       every robot's e-stop (rover_web.estop)

build_fleet makes one Rover per robot (core/fleet.py); each feature's init_app sets up every robot.
Pages: with several robots every page's top bar has a robot selector (the same page for another
robot, templates/partials/robot_select.html) and "Stop all" (partials/estop_all.html), from the
`fleet_robots`, `current_robot` and `app_root` this package gives every template; the fleet page
polls /api/robots (static/js/fleet/fleet.js says why not a stream per robot).
Modules: prefix (the WSGI mount), summary (a robot's line on
the fleet page), routes; the setting and naming rules are rover_web/core/robots.py.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from flask import Flask

from rover_web.config import TOPIC_KEYS
from rover_web.core import robots as robots_setting
from rover_web.core.fleet import Fleet, FleetHub
from rover_web.core.state import Rover
from rover_web.core.streams import StreamLimit
from rover_web.events.broadcast import Broadcaster
from rover_web.events.hub import EventHub
from rover_web.i18n import N_
from rover_web.ros.cmd_vel import CmdVelOutput
from rover_web.storage.claim import claim
from rover_web.storage.db import Database

from . import routes
from .prefix import RobotPrefix

__all__ = ["build_fleet", "init_app"]


def robot_database(first_path: Path, name: str) -> Path:
    return first_path.with_name(f"{first_path.stem}-{name}{first_path.suffix}")


def build_fleet(settings: dict[str, Any], runtime, db_path: Path, db_claim) -> Fleet:
    """A Rover per robot of ROVER_WEB_ROBOTS on the one runtime; the first keeps `db_path`."""
    robots = robots_setting.parse(settings["ROVER_WEB_ROBOTS"])
    streams = StreamLimit(settings["ROVER_WEB_MAX_STREAMS"])
    nav: list[tuple[str, str]] = [("Dashboard", "/")]
    rovers: list[Rover] = []
    claims = []  # the ones made here; the caller releases db_claim if this fails
    try:
        for i, robot in enumerate(robots):
            config = robots_setting.settings_for(robot, settings, TOPIC_KEYS)
            path = db_path if i == 0 else robot_database(db_path, robot.name)
            held = db_claim
            if i:
                held = claim(path)
                claims.append(held)
            db = Database(path)
            db.check()
            hub = EventHub(max_clients=settings["ROVER_WEB_SSE_MAX_CLIENTS"])
            cmd_vel = CmdVelOutput(runtime, config["ROVER_WEB_CMD_VEL_TOPIC"],
                                   max_linear_mps=config["ROVER_WEB_MAX_LINEAR_MPS"],
                                   max_angular_rps=config["ROVER_WEB_MAX_ANGULAR_RPS"],
                                   stamped=config["ROVER_WEB_CMD_VEL_STAMPED"],
                                   frame_id=config["ROVER_WEB_CMD_VEL_FRAME_ID"])
            rover = Rover(config, hub, runtime, cmd_vel, db=db,
                          broadcaster=Broadcaster(hub, settings["ROVER_WEB_SSE_KEEPALIVE_S"]),
                          robot=robot, streams=streams, nav_links=nav)
            rover.on_shutdown(held.release)  # shutdown hooks run last first: after the database closes
            rover.on_shutdown(rover.db.close)
            rovers.append(rover)
    except BaseException:
        for rover in rovers:
            rover.db.close()
        for held in claims:
            held.release()
        raise
    graph = None
    if len(rovers) > 1:
        first = rovers[0]
        graph = Rover(settings, FleetHub([r.hub for r in rovers]), runtime, None, db=first.db,
                      broadcaster=first.broadcaster, robot=robots_setting.Robot("graph", kind="robot"),
                      streams=streams, nav_links=nav)
    return Fleet(rovers, runtime, graph)


def init_app(app: Flask, fleet: Fleet) -> None:
    app.register_blueprint(routes.bp)
    app.context_processor(routes.layout_context)
    app.wsgi_app = RobotPrefix(app.wsgi_app, fleet.names)
    if len(fleet) > 1:
        fleet.graph.add_nav(N_("Robots"), "/robots")
