"""Teleop: the joystick WebSocket, REST drive commands, the e-stop, and the `teleop` SSE channel.

Thin routes over TeleopController (teleop_control.py), which holds every rule (scaling, deadman,
epochs, one operator at a time, e-stop latch). Velocity leaves the process only via rover.cmd_vel.

  WS   /ws/teleop           joystick and keyboard frames (teleop_protocol.py)
  GET  /api/teleop          the controller's state (same as the `teleop` channel)
  POST /api/teleop          {"command": forward|back|left|right|stop, "speed": 0..1, "duration_s": ...}
  GET  /api/estop           the e-stop latch
  POST /api/estop           {"engaged": true|false, "by": "name"}
"""

from __future__ import annotations

import logging
import threading
import time

from flask import Blueprint, current_app, jsonify, request
from flask_sock import Sock

from rover_web.config import ConfigError
from rover_web.core.state import Rover
from rover_web.web.http import ApiError, json_body
from .control import REST_COMMANDS, Limits, Refused, Repeater, TeleopController
from .websocket import FrameReader, TeleopSocket
from .estop_store import EStopStore
from rover_web.web.validate import InvalidInput, number, only_keys, text

log = logging.getLogger(__name__)

CHANNEL = "teleop"
# The commanded velocity can change at the joystick's event rate; browsers need far less.
CHANNEL_MAX_HZ = 20.0
NAME_MAX_LEN = 40

bp = Blueprint("teleop", __name__)


class Teleop:
    """The feature's state, kept in app.extensions["teleop"]."""

    def __init__(self, rover: Rover):
        config = rover.config
        self.config = config
        if config["ROVER_WEB_TELEOP_REST_DEFAULT_DURATION_S"] > config["ROVER_WEB_TELEOP_REST_MAX_DURATION_S"]:
            raise ConfigError("ROVER_WEB_TELEOP_REST_DEFAULT_DURATION_S: must not exceed "
                              "ROVER_WEB_TELEOP_REST_MAX_DURATION_S")
        self.store = EStopStore(rover.db)
        self._estop_lock = threading.Lock()
        hub = rover.hub
        self.controller = TeleopController(
            rover.cmd_vel,
            Limits(config["ROVER_WEB_MAX_LINEAR_MPS"], config["ROVER_WEB_MAX_ANGULAR_RPS"]),
            rate_hz=config["ROVER_WEB_TELEOP_RATE_HZ"], deadman_s=config["ROVER_WEB_TELEOP_DEADMAN_S"],
            on_state=lambda state: hub.publish_throttled(CHANNEL, state, CHANNEL_MAX_HZ),
            estop=self.store.load())
        self.repeater = Repeater(self.controller)
        self.max_frame_bytes = config["ROVER_WEB_TELEOP_MAX_FRAME_BYTES"]

    def hello(self) -> dict:
        deadman_s = self.controller.deadman_s
        return {"rate_hz": self.controller.rate_hz, "deadman_s": deadman_s,
                # how often a client should repeat a held input: three chances per deadman period
                "keepalive_s": round(min(0.1, deadman_s / 3), 3),
                "max_linear_mps": self.controller.limits.max_linear_mps,
                "max_angular_rps": self.controller.limits.max_angular_rps,
                "max_frame_bytes": self.max_frame_bytes}

    def set_estop(self, engaged: bool, by: str) -> dict:
        with self._estop_lock:
            if engaged:
                state = self.controller.engage_estop(by)  # the robot stops before anything else
                try:
                    self.store.save(state)
                except Exception:
                    log.exception("e-stop engaged but not recorded on disk")
                    return {**state, "persisted": False}
                return {**state, "persisted": True}
            current = self.controller.estop
            if not current["engaged"]:
                return {**current, "persisted": True}
            try:
                self.store.save({"engaged": False, "since": time.time(), "by": by})
            except Exception:
                log.exception("could not record the e-stop release")
                raise ApiError(503, "estop_not_recorded",
                               "the release could not be written to the database; the e-stop stays engaged") from None
            return {**self.controller.release_estop(by), "persisted": True}


def _teleop() -> Teleop:
    return current_app.extensions["teleop"]


def _name(raw: str | None) -> str | None:
    if not raw:
        return None
    name = " ".join(raw.split())[:NAME_MAX_LEN]
    return name if name.isprintable() and name else None


# --- WebSocket ---

def teleop_socket(ws) -> None:
    teleop = _teleop()
    controller = teleop.controller
    try:
        session = controller.connect(_name(request.args.get("name")))
        hello = {**controller.session_state(session, "connected"), "type": "hello", "session": session.id,
                 "name": session.name, **teleop.hello()}
        TeleopSocket(ws, controller, session, teleop.max_frame_bytes).serve(
            hello, current_app.extensions["rover_web"].stopping, teleop.config["ROVER_WEB_TELEOP_WS_PING_S"] or None)
    finally:
        ws.thread.attach(None)  # a reader that never got a TeleopSocket ends rather than wait forever


def _offer_no_extensions() -> None:
    """Before the handshake: agree to no extension. Teleop frames are ~50 bytes, so
    permessage-deflate would save nothing and cost zlib work on every frame at both ends; our
    reader (ws_frames.py) reads plain frames and refuses compressed ones (1002)."""
    if request.endpoint == "teleop_socket":
        request.environ.pop("HTTP_SEC_WEBSOCKET_EXTENSIONS", None)


# --- REST ---

@bp.get("/api/teleop")
def teleop_state():
    return jsonify(_teleop().controller.state())


@bp.post("/api/teleop")
def teleop_command():
    teleop = _teleop()
    config = teleop.config
    body = json_body()
    if body.get("command") == "stop":  # stop always wins, whatever else the body says
        teleop.controller.rest_stop()
        return jsonify(command="stop", linear_mps=0.0, angular_rps=0.0, duration_s=0.0)
    try:
        only_keys(body, {"command", "speed", "duration_s"})
        for key in ("speed", "duration_s"):
            if key in body and body[key] is None:
                raise InvalidInput(f"'{key}' must be a number, got null", "bad_type")
        command = text(body, "command", max_len=20)
        if command not in REST_COMMANDS:
            raise InvalidInput(f"unknown command {command!r}; use one of {', '.join(REST_COMMANDS)}, stop",
                               "unknown_command")
        speed = number(body, "speed", low=0.0, high=1.0, default=config["ROVER_WEB_TELEOP_REST_DEFAULT_SPEED"])
        max_s = config["ROVER_WEB_TELEOP_REST_MAX_DURATION_S"]
        duration_s = number(body, "duration_s", low=0.0, high=max_s,
                            default=config["ROVER_WEB_TELEOP_REST_DEFAULT_DURATION_S"])
        if duration_s <= 0:
            raise InvalidInput(f"'duration_s' must be greater than 0 and at most {max_s:g}", "out_of_range")
    except InvalidInput as exc:
        raise ApiError(400, exc.code, str(exc)) from None
    try:
        linear_mps, angular_rps = teleop.controller.rest_command(command, speed, duration_s)
    except Refused as exc:
        raise ApiError(exc.status, exc.code, exc.message) from None
    return jsonify(command=command, speed=speed, duration_s=duration_s, linear_mps=linear_mps,
                   angular_rps=angular_rps)


@bp.get("/api/estop")
def estop_state():
    return jsonify(_teleop().controller.estop)


@bp.post("/api/estop")
def estop_set():
    teleop = _teleop()
    body = json_body()
    default_by = request.remote_addr or "unknown"
    if body.get("engaged") is True:  # engaging always works, whatever else the body says
        by = body.get("by") if isinstance(body.get("by"), str) else None
        return jsonify(teleop.set_estop(True, _name(by) or default_by))
    try:
        only_keys(body, {"engaged", "by"})
        if "engaged" not in body:
            raise InvalidInput("'engaged' is required: true engages the e-stop, false releases it", "missing_field")
        if not isinstance(body["engaged"], bool):
            raise InvalidInput("'engaged' must be true or false", "bad_type")
        by = text(body, "by", max_len=NAME_MAX_LEN, default=None)
    except InvalidInput as exc:
        raise ApiError(400, exc.code, str(exc)) from None
    return jsonify(teleop.set_estop(False, _name(by) or default_by))


def init_app(app, rover: Rover) -> None:
    teleop = Teleop(rover)
    app.extensions["teleop"] = teleop
    # FrameReader: simple_websocket does the handshake, then our reader thread reads the frames
    # (teleop_socket.py, ws_frames.py); TeleopSocket sends the pings.
    app.config["SOCK_SERVER_OPTIONS"] = {"ping_interval": None, "thread_class": FrameReader}
    app.before_request(_offer_no_extensions)
    sock = Sock(app)
    sock.route("/ws/teleop")(teleop_socket)  # on the app: the module's blueprint is shared by every app
    app.register_blueprint(bp)

    rover.hub.register(CHANNEL)
    rover.hub.publish_throttled(CHANNEL, teleop.controller.state(), CHANNEL_MAX_HZ)
    rover.add_panel(5, "panels/teleop.html", "Drive", channels=(CHANNEL,))

    @app.context_processor
    def _teleop_context():
        return {"teleop_state": teleop.controller.state()}

    if teleop.controller.estop["engaged"]:
        log.warning("the e-stop is engaged (since the last run); release it to drive")
        rover.cmd_vel.zero()
    teleop.repeater.start()
    rover.on_shutdown(teleop.repeater.stop)
