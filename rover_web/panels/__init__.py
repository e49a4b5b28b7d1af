"""Mission control panels: operator buttons and status displays for any robot, defined in TOML.

The default file (drone.toml beside this module) is the drone's take-off / return / stop panel;
ROVER_WEB_PANELS_FILE names another. Pages /panels, /panels/<panel>; API /api/panels/...;
SSE channels `panel` (what the panels show) and `panel_log` (the operator log).
Modules: spec (the file and its validation), state (what a panel shows and allows), service (ROS
side and the command path), oplog (SQLite operator log), msgs (message fields), routes (pages and API).
"""

from __future__ import annotations

from rover_web.core.fleet import Fleet
from rover_web.core.state import Rover
from rover_web.estop import EStopService
from rover_web.i18n import N_

from . import routes, spec
from .msgs import field_kind
from .oplog import OperatorLog
from .service import TICK_S, PanelService


def init_app(app, fleet: Fleet) -> None:
    for rover in fleet:
        _init_robot(rover)
    app.register_blueprint(routes.bp)


def _init_robot(rover: Rover) -> None:
    config = rover.config
    specs = spec.load(config["ROVER_WEB_PANELS_FILE"], config["ROVER_WEB_STALE_AFTER_S"], field_kind)
    specs = tuple(s.resolved(rover.resolve) for s in specs)  # each robot's panels drive its own topics
    rover.hub.register("panel", "panel_log")
    estop = rover.feature(EStopService)
    oplog = OperatorLog(rover.db, config["ROVER_WEB_PANELS_LOG_KEEP"], audit=rover.audit)
    service = PanelService(specs, rover, oplog, estop)
    rover.add_feature(service)
    estop.on_engage(service.on_estop)
    estop.on_release(lambda _by: service.publish_view())  # the page's buttons come back
    rover.add_panel(20, "panels/panels.html", N_("Control panels"), channels=("panel",))
    rover.add_nav(N_("Panels"), "/panels")
    service.publish_view()
    rover.every(TICK_S, service.tick, name="panels-ticker")
