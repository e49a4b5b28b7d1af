"""Teleop's views: the joystick WebSocket, REST drive commands, the e-stop, and the dashboard card's context.

The WebSocket view is routed on the app by flask_sock in init_app (the blueprint is shared by
every app); `before_handshake` runs before its handshake, `release_slot` after the socket ends.
"""

from __future__ import annotations

from flask import Blueprint, jsonify, request

from rover_web.auth import on_revoke, signed_in_name
from rover_web.core.state import current_feature, current_rover
from rover_web.web.api_messages import request_catalogues, text_of
from rover_web.web.http import ApiError, json_body
from rover_web.web.streams import stream_slot
from rover_web.web.validate import InvalidInput, number, only_keys, text

from .control import REST_COMMANDS, Refused
from .service import TeleopService
from .websocket import TeleopSocket

NAME_MAX_LEN = 40
SLOT_KEY = "rover_web.stream_slot"

bp = Blueprint("teleop", __name__)


@bp.app_context_processor
def teleop_context():
    return {"teleop_state": current_feature(TeleopService).controller.state()}


def operator_name(raw: str | None) -> str | None:
    if not raw:
        return None
    name = " ".join(raw.split())[:NAME_MAX_LEN]
    return name if name.isprintable() and name else None


# --- WebSocket ---

def teleop_socket(ws) -> None:
    teleop = current_feature(TeleopService)
    controller = teleop.controller
    try:
        # Signed in, the session is the user's, whatever name the page asks for.
        session = controller.connect(signed_in_name() or operator_name(request.args.get("name")))
        session.catalogues = request_catalogues()
        hello = {**controller.session_state(session, "connected"), "type": "hello", "session": session.id,
                 "name": session.name, **teleop.hello()}
        teleop_ws = TeleopSocket(ws, controller, session, teleop.max_frame_bytes)
        with on_revoke(teleop_ws.revoke):  # a revoked token or session: the robot stops, then 1008
            teleop_ws.serve(hello, current_rover().stopping, teleop.config["ROVER_WEB_TELEOP_WS_PING_S"] or None)
    finally:
        ws.thread.attach(None)  # a reader that never got a TeleopSocket ends rather than wait forever


def before_handshake() -> None:
    """A slot under the stream cap (503 before any handshake beyond it), and no extension: teleop
    frames are ~50 bytes, so permessage-deflate would save nothing and cost zlib work on every
    frame at both ends; our reader (ws_frames.py) reads plain frames and refuses compressed ones."""
    if request.endpoint == "teleop_socket":
        request.environ[SLOT_KEY] = stream_slot("teleop")
        request.environ.pop("HTTP_SEC_WEBSOCKET_EXTENSIONS", None)


def release_slot(_exc=None) -> None:
    """After the socket's request ends, however it ended (a failed handshake included)."""
    slot = request.environ.pop(SLOT_KEY, None)
    if slot is not None:
        slot.release()


# --- REST ---

@bp.get("/api/teleop")
def teleop_state():
    return jsonify(current_feature(TeleopService).controller.state())


@bp.post("/api/teleop")
def teleop_command():
    teleop = current_feature(TeleopService)
    config = teleop.config
    body = json_body()
    if body.get("command") == "stop":  # stop always wins, whatever else the body says
        teleop.controller.rest_stop()
        return jsonify(command="stop", linear_mps=0.0, angular_rps=0.0, duration_s=0.0)
    try:
        only_keys(body, {"command", "speed", "duration_s"})
        for key in ("speed", "duration_s"):
            if key in body and body[key] is None:
                raise InvalidInput("'%(key)s' must be a number, got null", "bad_type", key=key)
        command = text(body, "command", max_len=20)
        if command not in REST_COMMANDS:
            raise InvalidInput("unknown command %(command)s; use one of %(rest_commands)s, stop",
                               "unknown_command", command=repr(command), rest_commands=', '.join(REST_COMMANDS))
        speed = number(body, "speed", low=0.0, high=1.0, default=config["ROVER_WEB_TELEOP_REST_DEFAULT_SPEED"])
        max_s = config["ROVER_WEB_TELEOP_REST_MAX_DURATION_S"]
        duration_s = number(body, "duration_s", low=0.0, high=max_s,
                            default=config["ROVER_WEB_TELEOP_REST_DEFAULT_DURATION_S"])
        if duration_s <= 0:
            raise InvalidInput("'duration_s' must be greater than 0 and at most %(max_s)s", "out_of_range",
                               max_s=format(max_s, "g"))
    except InvalidInput as exc:
        raise ApiError(400, exc.code, text_of(exc)) from None
    try:
        # The drive outlives this request: its credential is watched until the next one replaces
        # it, and a revocation stops it at once (rest_drive.py).
        linear_mps, angular_rps = teleop.rest.start(command, speed, duration_s, on_revoke)
    except Refused as exc:
        raise ApiError(exc.status, exc.code, exc.text) from None
    return jsonify(command=command, speed=speed, duration_s=duration_s, linear_mps=linear_mps,
                   angular_rps=angular_rps)
