"""Server-rendered pages. Each renders with its data already in it; SSE only keeps it current."""

from __future__ import annotations

from flask import Blueprint, render_template

from rover_web.core.state import current_rover

from .status import build_status

bp = Blueprint("pages", __name__)


@bp.get("/")
def dashboard():
    rover = current_rover()
    channels = ["status"]
    for panel in rover.dashboard_panels:
        channels += [c for c in panel.channels if c not in channels]
    return render_template("dashboard.html", status=build_status(rover), odom=rover.hub.latest("odom"),
                           battery=rover.hub.latest("battery"),
                           panels=rover.dashboard_panels, channels=channels)


@bp.get("/status")
def status_page():
    """The node, its topics and the link plot (round trip, newest robot message), on a page of their own."""
    return render_template("status.html", status=build_status(current_rover()))


@bp.app_context_processor
def layout_context():
    rover = current_rover()
    return {"nav_links": rover.nav_links, "rover_config": rover.config}
