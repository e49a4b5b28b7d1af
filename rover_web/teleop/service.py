"""The teleop feature's per-app object: the controller and its repeater thread, tied to the e-stop."""

from __future__ import annotations

import logging

from rover_web.config import ConfigError
from rover_web.core.state import Rover
from rover_web.estop import EStopService

from .commands import Limits
from .control import TeleopController
from .repeater import Repeater
from .rest_drive import RestDrives

log = logging.getLogger(__name__)

CHANNEL = "teleop"
# The commanded velocity can change at the joystick's event rate; browsers need far less.
CHANNEL_MAX_HZ = 20.0


class TeleopService:
    def __init__(self, rover: Rover, estop: EStopService):
        config = rover.config
        self.config = config
        if config["ROVER_WEB_TELEOP_REST_DEFAULT_DURATION_S"] > config["ROVER_WEB_TELEOP_REST_MAX_DURATION_S"]:
            raise ConfigError("ROVER_WEB_TELEOP_REST_DEFAULT_DURATION_S: must not exceed "
                              "ROVER_WEB_TELEOP_REST_MAX_DURATION_S")
        hub = rover.hub
        self.controller = TeleopController(
            rover.cmd_vel,
            Limits(config["ROVER_WEB_MAX_LINEAR_MPS"], config["ROVER_WEB_MAX_ANGULAR_RPS"]),
            rate_hz=config["ROVER_WEB_TELEOP_RATE_HZ"], deadman_s=config["ROVER_WEB_TELEOP_DEADMAN_S"],
            deadman_max_s=config["ROVER_WEB_TELEOP_DEADMAN_MAX_S"],
            on_state=lambda state: hub.publish_throttled(CHANNEL, state, CHANNEL_MAX_HZ),
            estop=estop.state(), request_estop=lambda by: estop.engage(by, via="websocket"))
        # The e-stop service owns the latch; the controller keeps a copy to refuse drive frames
        # without a call out of its lock, and re-arms its sockets on release.
        estop.on_engage(self.controller.engage_estop)
        estop.on_release(self.controller.release_estop)
        rover.on_link_lost(self.controller.link_lost)
        self.repeater = Repeater(self.controller)
        self.rest = RestDrives(self.controller)
        self.max_frame_bytes = config["ROVER_WEB_TELEOP_MAX_FRAME_BYTES"]

    def hello(self) -> dict:
        deadman_s = self.controller.deadman_s
        return {"rate_hz": self.controller.rate_hz, "deadman_s": deadman_s,
                "deadman_max_s": self.controller.deadman_max_s,
                # how often a client should repeat a held input: three chances per deadman period
                "keepalive_s": round(min(0.1, deadman_s / 3), 3),
                "max_linear_mps": self.controller.limits.max_linear_mps,
                "max_angular_rps": self.controller.limits.max_angular_rps,
                "max_frame_bytes": self.max_frame_bytes}
