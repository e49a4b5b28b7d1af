"""Live plots of any numeric field: GET /plot, GET /api/plot, GET /api/plot/fields, the `plot` channel.

A series (topic, field path such as twist.twist.linear.x or position[2]) keeps its last
ROVER_WEB_PLOT_KEEP_POINTS samples server-side; GET /api/plot answers a window of it decimated to
at most 2,000 points (min and max kept), and the `plot` channel carries new points 10 times a
second. Topics are subscribed through the topic browser's shared subscriptions and caps. A series
ends ROVER_WEB_PLOT_IDLE_S after a page last asked for it.
Modules: field (paths, reading a number), series (ring, decimation), msgs (numeric fields of a type).
"""

from __future__ import annotations

from rover_web.core.state import Rover
from rover_web.i18n import N_

from . import routes
from .service import TICK_S, Plots


def init_app(app, rover: Rover) -> None:
    plots = Plots(rover)
    rover.add_feature(plots)
    rover.hub.register("plot")
    app.register_blueprint(routes.bp)
    rover.add_nav(N_("Plot"), "/plot")
    rover.every(TICK_S, plots.tick, name="plot-tick", only_while=plots.plotting)
    rover.on_shutdown(plots.close)
