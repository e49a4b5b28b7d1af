"""Diagnostics: GET /diagnostics, GET /api/diagnostics, the `diagnostics` channel and a dashboard card.

ROS: subscribes diagnostic_msgs/msg/DiagnosticArray on /diagnostics and /diagnostics_agg. The
latest status per name is kept with its arrival time; one not refreshed for
ROVER_WEB_DIAGNOSTICS_STALE_S is shown stale. The card shows the worst level per hardware id.
Modules: board (latest per name, staleness, worst per hardware id), msgs.
"""

from __future__ import annotations

from rover_web.core.fleet import Fleet
from rover_web.core.state import Rover
from rover_web.i18n import N_

from . import routes
from .service import REFRESH_S, Diagnostics


def init_app(app, fleet: Fleet) -> None:
    for rover in fleet:
        _init_robot(rover)
    app.register_blueprint(routes.bp)


def _init_robot(rover: Rover) -> None:
    diagnostics = Diagnostics(rover)
    rover.add_feature(diagnostics)
    rover.hub.register("diagnostics")
    diagnostics.subscribe()
    rover.add_nav(N_("Diagnostics"), "/diagnostics")
    rover.add_panel(80, "panels/diagnostics.html", N_("Diagnostics"), channels=("diagnostics",))
    rover.every(REFRESH_S, diagnostics.refresh, name="diagnostics-refresh")
