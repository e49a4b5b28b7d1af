"""Teleop: the joystick WebSocket, REST drive commands, the e-stop, and the `teleop` SSE channel.

Thin routes over TeleopController (control.py), which holds every rule (scaling, deadman with
hold and ramp, epochs, one operator at a time, re-arming after an e-stop). Velocity leaves the
process only via rover.cmd_vel.

  WS   /ws/teleop           joystick and keyboard frames (protocol.py, read by websocket.py)
  GET  /api/teleop          the controller's state (same as the `teleop` channel)
  POST /api/teleop          {"command": forward|back|left|right|stop, "speed": 0..1, "duration_s": ...}
The e-stop itself is its own feature (rover_web.estop); teleop refuses motion while it is engaged
and re-arms each socket on release only after a neutral input.

Modules: service (the per-app object), routes, control (the controller) with commands, sessions,
ramp, link and repeater, rest_drive (a REST drive ends with its credential), protocol (frames),
websocket and ws_frames (the socket).
"""

from __future__ import annotations

import logging

from flask_sock import Sock

from rover_web.core.fleet import Fleet
from rover_web.core.state import Rover
from rover_web.estop import EStopService
from rover_web.i18n import N_

from . import routes
from .service import CHANNEL, CHANNEL_MAX_HZ, TeleopService
from .websocket import FrameReader

log = logging.getLogger(__name__)


def init_app(app, fleet: Fleet) -> None:
    for rover in fleet:
        _init_robot(rover)
    # FrameReader: simple_websocket does the handshake, then our reader thread reads the frames
    # (websocket.py, ws_frames.py); TeleopSocket sends the pings.
    app.config["SOCK_SERVER_OPTIONS"] = {"ping_interval": None, "thread_class": FrameReader}
    app.before_request(routes.before_handshake)
    app.teardown_request(routes.release_slot)
    sock = Sock(app)
    sock.route("/ws/teleop")(routes.teleop_socket)  # on the app: the blueprint is shared by every app
    app.register_blueprint(routes.bp)  # with the dashboard card's context (teleop_state)


def _init_robot(rover: Rover) -> None:
    """Each robot: its own controller, so deadman, operator and re-arming are per robot."""
    teleop = TeleopService(rover, rover.feature(EStopService))
    teleop.controller.audit = rover.audit  # sessions and who held control, for recordings
    rover.add_feature(teleop)
    rover.hub.register(CHANNEL)
    rover.hub.publish_throttled(CHANNEL, teleop.controller.state(), CHANNEL_MAX_HZ)
    rover.add_panel(5, "panels/teleop.html", N_("Drive"), channels=(CHANNEL,))

    if teleop.controller.estop["engaged"]:
        log.warning("the e-stop is engaged (since the last run); release it to drive")
    teleop.repeater.start()
    rover.on_shutdown(teleop.repeater.stop)
    rover.on_shutdown(teleop.rest.close)
