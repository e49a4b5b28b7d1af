"""The teleop feature's per-app object: the controller, its repeater thread and the e-stop on disk."""

from __future__ import annotations

import logging
import threading
import time

from rover_web.config import ConfigError
from rover_web.core.state import Rover

from .control import Limits, Repeater, TeleopController
from .estop_store import EStopStore

log = logging.getLogger(__name__)

CHANNEL = "teleop"
# The commanded velocity can change at the joystick's event rate; browsers need far less.
CHANNEL_MAX_HZ = 20.0


class EStopNotRecorded(Exception):
    """A release could not be written to the database, so the e-stop stays engaged."""


class TeleopService:
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
        """Engaging stops the robot first and never fails; releasing raises EStopNotRecorded when
        the release could not be written, and the e-stop then stays engaged."""
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
                raise EStopNotRecorded(
                    "the release could not be written to the database; the e-stop stays engaged") from None
            return {**self.controller.release_estop(by), "persisted": True}
