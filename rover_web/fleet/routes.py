"""GET /api/robots, the /robots fleet page, and what every page's top bar needs to switch robots."""

from __future__ import annotations

from flask import Blueprint, jsonify, render_template, request

from rover_web.core.state import current_rover
from rover_web.waypoints.service import WaypointsService

from .prefix import app_root
from .summary import summary

bp = Blueprint("fleet", __name__)


def _robots() -> list[dict]:
    rover = current_rover()
    root = app_root(request.environ)
    return [summary(robot, root) for robot in rover.fleet]


@bp.get("/api/robots")
def robots():
    current = current_rover().robot.name
    return jsonify({"current": current, "robots": _robots()})


@bp.get("/robots")
def fleet_page():
    return render_template("robots.html", robots=_robots(),
                           map_config=current_rover().feature(WaypointsService).map_config())


def layout_context() -> dict:
    """The robot selector and "Stop all" in base.html: which robots, which one this page drives,
    and the app root the robots' URLs start from (the page's own root is the robot's prefix)."""
    rover = current_rover()
    return {"fleet_robots": [r.robot for r in rover.fleet], "current_robot": rover.robot,
            "app_root": app_root(request.environ)}
