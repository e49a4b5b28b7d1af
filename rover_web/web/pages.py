"""Server-rendered pages. Each renders with its data already in it; SSE only keeps it current."""

from __future__ import annotations

from flask import Blueprint, render_template
from flask_babel import gettext

from rover_web.core.state import current_rover
from rover_web.layouts import LayoutService
from rover_web.layouts.cards import catalogue
from rover_web.layouts.defaults import DEFAULTS
from rover_web.layouts.page import place

from .status import build_status

bp = Blueprint("pages", __name__)


@bp.get("/")
def dashboard():
    """The cards of the user's active layout (rover_web/layouts), and only the channels they need."""
    rover = current_rover()
    service = rover.feature(LayoutService)
    layout_id, layout = service.active()
    cards, channels, missing = place(rover, layout)
    return render_template("dashboard.html", status=build_status(rover), odom=rover.hub.latest("odom"),
                           battery=rover.hub.latest("battery"), layout=layout, layout_id=layout_id,
                           layouts=[{**row, "name": shown_name(row["name"])} for row in service.store.list()],
                           layout_name=shown_name(layout["name"]), cards=cards, missing=missing, channels=channels,
                           uses_uplot=any(c.type in ("plot", "link") for c in cards),
                           card_types=[{**t, "title": gettext(t["title"]), "help": gettext(t["help"])}
                                       for t in catalogue()])


def shown_name(name: str) -> str:
    """A layout's name as the page shows it: a built-in layout's name is a message id (layouts/defaults.py),
    kept by a copy of it; any other name is the user's own."""
    return gettext(name) if name in {d["name"] for d in DEFAULTS.values()} else name


@bp.get("/status")
def status_page():
    """The node, its topics and the link plot (round trip, newest robot message), on a page of their own."""
    return render_template("status.html", status=build_status(current_rover()))


@bp.app_context_processor
def layout_context():
    rover = current_rover()
    return {"nav_links": rover.nav_links, "rover_config": rover.config}  # labels: message ids (base.html translates)
