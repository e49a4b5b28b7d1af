"""GET /api/robots and the /robots fleet page."""

from __future__ import annotations

from flask import Blueprint, jsonify, render_template, request

from rover_web.core.state import current_rover

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
    return render_template("robots.html", robots=_robots())
