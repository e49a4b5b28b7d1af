"""Dashboard layouts: which cards the dashboard shows, where, with what settings; kept on the robot.

HTTP (routes.py; docs/dashboards.md):
  GET    /api/layouts          every layout of this robot, and the caller's active one
  POST   /api/layouts          add one (import); a bad layout is a 400 naming the field, nothing saved
  GET    /api/layouts/<id>     one layout, as POST takes it (export; ?download=1 for a file)
  PUT    /api/layouts/<id>     replace it
  DELETE /api/layouts/<id>     delete it; whoever had chosen it falls back to the robot's default
  GET    /api/me/layout        the caller's active layout
  PUT    /api/me/layout        {"id": n}: choose it (per user; one shared choice while sign-in is off)
Each robot of a fleet keeps its layouts in its own database. Modules: cards (the card types and
their settings), schema (the versioned document and its validation), defaults (the first start's
layouts), store (SQLite), service, page (the dashboard's cards and channels from a layout).
"""

from __future__ import annotations

from rover_web.core.fleet import Fleet
from rover_web.core.state import Rover, current_feature
from rover_web.logs.ring import LEVELS
from rover_web.logs.service import RosoutLog

from . import routes
from .service import LayoutService
from .store import LayoutStore

__all__ = ["init_app", "LayoutService"]


def init_app(app, fleet: Fleet) -> None:
    for rover in fleet:
        _init_robot(rover)
    app.register_blueprint(routes.bp)
    app.jinja_env.globals["log_card_lines"] = log_card_lines


def log_card_lines(level: str, limit: int) -> dict:
    """A logs card's first lines (newest first) and the number of the newest line the ring saw."""
    lines, last_seq = current_feature(RosoutLog).ring.query_at(LEVELS.get(level, 0), limit=limit)
    return {"lines": lines, "last_seq": last_seq}


def _init_robot(rover: Rover) -> None:
    rover.add_feature(LayoutService(LayoutStore(rover.db, rover.robot.kind)))
