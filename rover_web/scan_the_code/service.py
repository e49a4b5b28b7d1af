"""The Scan the Code feature's per-app object: the LightSequence and the order its changes go out in."""

from __future__ import annotations

import logging
import threading
import time

from rover_web.config import ConfigError

from .light_sequence import LightSequence, Outcome, parse_colours

log = logging.getLogger(__name__)

STATE_CHANNEL = "light_sequence"
CODE_CHANNEL = "scan_code"


def sequence_from_config(config) -> LightSequence:
    try:
        colours = parse_colours(config["ROVER_WEB_LIGHT_COLOURS"])
    except ValueError as exc:
        raise ConfigError(f"ROVER_WEB_LIGHT_COLOURS: {exc}") from None
    return LightSequence(colours, history_length=config["ROVER_WEB_CODE_HISTORY_LENGTH"],
                         confirm_cycles=config["ROVER_WEB_CODE_CONFIRM_CYCLES"],
                         stale_after_s=config["ROVER_WEB_LIGHT_STALE_AFTER_S"])


class ScanTheCodeService:
    """Owns the LightSequence; every change goes out to the hub in the order it happened."""

    def __init__(self, sequence: LightSequence, hub, publish_code=lambda colours: None,
                 clock=time.monotonic, wall_clock=time.time):
        self.sequence = sequence
        self._hub = hub
        self._publish_code = publish_code
        self._clock, self._wall_clock = clock, wall_clock
        self._lock = threading.Lock()  # ROS callbacks, the freshness loop and requests share the state
        with self._lock:
            self._hub.publish(STATE_CHANNEL, self.sequence.snapshot(self._clock()))

    @property
    def freshness_period_s(self) -> float:
        """How often check_fresh must run for a stale light to show within a quarter of the limit."""
        return min(0.25, self.sequence.stale_after_s / 4)

    def observe(self, text: str) -> None:
        """One message from the detector (ROS callback thread)."""
        with self._lock:
            self._apply(self.sequence.observe(text, self._clock(), self._wall_clock()))

    def check_fresh(self) -> None:
        with self._lock:
            self._apply(self.sequence.check_fresh(self._clock()))

    def snapshot(self) -> dict:
        with self._lock:
            return self.sequence.snapshot(self._clock())

    def _apply(self, outcome: Outcome) -> None:
        # Under the lock, so the hub's sequence numbers follow the state's own order.
        if outcome.cycle is not None and outcome.cycle["result"] != "code":
            log.info("light sequence: %s cycle %s (%s)", outcome.cycle["result"],
                     ",".join(outcome.cycle["colours"]), ", ".join(outcome.cycle["problems"]))
        if outcome.changed:
            self._hub.publish(STATE_CHANNEL, self.sequence.snapshot(self._clock()))
        if outcome.confirmed is not None:
            code = outcome.confirmed
            log.info("scan the code: %s (confidence %d)", code["text"], code["confidence"])
            self._hub.emit(CODE_CHANNEL, code)
            try:
                self._publish_code(code["colours"])
            except Exception:  # e.g. the publisher is gone during shutdown; the state is still right
                log.exception("could not publish the code %s", code["text"])
