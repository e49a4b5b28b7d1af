"""TF: the robot's coordinate frames, as tf2 keeps them. GET /tf, GET /api/tf, GET /api/tf/lookup, `tf` channel.

ROS: subscribes tf2_msgs/msg/TFMessage on `tf` (reliable, volatile, depth 100) and `tf_static`
(reliable, transient local) under each robot's namespace, as Nav2's multi-robot launch remaps
them. Other features look up through `rover.feature(TfService).buffer` (buffer.py, TF_API in
docs/tf.md), once per message or per tick. Without tf2_msgs the buffer stays empty and the page
says what to install.
Modules: buffer (tf2's semantics, pure), wire (TFMessage from CDR bytes), service, msgs, routes,
replay (a recording's frames).
"""

from __future__ import annotations

from rover_web.core.fleet import Fleet
from rover_web.core.state import Rover
from rover_web.i18n import N_

from . import routes
from .buffer import TfBuffer, TfError, Transform
from .service import CHANNEL, TICK_S, TfService

__all__ = ["TfBuffer", "TfError", "TfService", "Transform", "add_nav", "init_app"]


def init_app(app, fleet: Fleet) -> None:
    from . import msgs  # rclpy: only once the app has a node

    missing = msgs.missing()
    for rover in fleet:
        _init_robot(rover, msgs, missing)
    app.register_blueprint(routes.bp)


def add_nav(fleet: Fleet) -> None:
    """The TF page's link, among the pages that observe the robot (init_app runs early, before them)."""
    for rover in fleet:
        rover.add_nav(N_("TF"), "/tf")


def _init_robot(rover: Rover, msgs, missing) -> None:
    service = TfService(rover, missing=missing, clock_ns=msgs.clock_ns(rover.runtime),
                         publishers=msgs.publishers(rover.runtime))
    rover.add_feature(service)
    rover.hub.register(CHANNEL)
    if missing is not None:
        return
    runtime = rover.runtime
    for kind, qos in (("dynamic", msgs.DYNAMIC_QOS), ("static", msgs.STATIC_QOS)):
        static = kind == "static"
        # /tf's age in /api/status says whether the robot's frames move; /tf_static is sent once
        # per broadcaster, and would only ever read as stale there.
        runtime.subscribe(msgs.TF_MESSAGE, service.topics[kind], lambda raw, s=static: service.on_raw(raw, s),
                          qos, raw=True, share=True, track=not static)
    rover.every(TICK_S, service.publish, name="tf-tree")
