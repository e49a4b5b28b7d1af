"""Scan the Code: the light tower monitor. ROS and HTTP glue around light_sequence.LightSequence.

- subscribes ROVER_WEB_LIGHT_SEQUENCE_TOPIC (std_msgs/String colour names);
- `light_sequence` SSE channel (conflated): the whole state, resent on every visible change;
- `scan_code` SSE channel (events, never conflated, replayable with Last-Event-ID): one per
  confirmed code, so a client that was busy still sees every detection;
- publishes each confirmed code on ROVER_WEB_CODE_TOPIC (std_msgs/String "red,green,blue",
  transient local, so a node that starts later still gets the last one);
- GET /api/light_sequence; the dashboard panel.
"""

from __future__ import annotations

import logging
import threading
import time

from flask import Blueprint, current_app, jsonify

from rover_web.config import ConfigError
from rover_web.core.state import Rover
from .light_sequence import LightSequence, Outcome, parse_colours

log = logging.getLogger(__name__)

bp = Blueprint("scan_the_code", __name__)

EXTENSION = "scan_the_code"
STATE_CHANNEL = "light_sequence"
CODE_CHANNEL = "scan_code"


class ScanTheCode:
    """Owns the LightSequence; every change goes out to the hub in the order it happened."""

    def __init__(self, sequence: LightSequence, hub, publish_code=lambda colours: None,
                 clock=time.monotonic, wall_clock=time.time):
        self.sequence = sequence
        self._hub = hub
        self._publish_code = publish_code
        self._clock, self._wall_clock = clock, wall_clock
        self._lock = threading.Lock()  # ROS callbacks, the freshness thread and requests share the state
        with self._lock:
            self._hub.publish(STATE_CHANNEL, self.sequence.snapshot(self._clock()))

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


def _freshness_loop(feature: ScanTheCode, stopping: threading.Event, period_s: float) -> None:
    while not stopping.wait(period_s):
        try:
            feature.check_fresh()
        except Exception:  # pragma: no cover - the watcher must outlive a bug
            log.exception("light sequence freshness check failed")


def clock_time(epoch_s: float | None) -> str:
    """Wall-clock time of day for the panel, as the server renders it before any event arrives."""
    return "—" if epoch_s is None else time.strftime("%H:%M:%S", time.localtime(epoch_s))


@bp.get("/api/light_sequence")
def light_sequence():
    return jsonify(current_app.extensions[EXTENSION].snapshot())


def init_app(app, rover: Rover) -> None:
    from . import msgs

    config = rover.config
    try:
        colours = parse_colours(config["ROVER_WEB_LIGHT_COLOURS"])
    except ValueError as exc:
        raise ConfigError(f"ROVER_WEB_LIGHT_COLOURS: {exc}") from None
    sequence = LightSequence(colours, history_length=config["ROVER_WEB_CODE_HISTORY_LENGTH"],
                             confirm_cycles=config["ROVER_WEB_CODE_CONFIRM_CYCLES"],
                             stale_after_s=config["ROVER_WEB_LIGHT_STALE_AFTER_S"])
    rover.hub.register(STATE_CHANNEL, CODE_CHANNEL)
    code_pub = rover.runtime.publisher(msgs.STRING, config["ROVER_WEB_CODE_TOPIC"], "latched")
    feature = ScanTheCode(sequence, rover.hub, lambda colours: code_pub.publish(msgs.code_message(colours)))
    app.extensions[EXTENSION] = feature
    rover.runtime.subscribe(msgs.STRING, config["ROVER_WEB_LIGHT_SEQUENCE_TOPIC"],
                            lambda msg: feature.observe(msgs.text_of(msg)),
                            qos=config["ROVER_WEB_LIGHT_SEQUENCE_QOS"])

    period_s = min(0.25, sequence.stale_after_s / 4)
    watcher = threading.Thread(target=_freshness_loop, args=(feature, rover.stopping, period_s),
                               name="light-sequence-freshness", daemon=True)
    watcher.start()
    rover.on_shutdown(lambda: watcher.join(1.0))

    app.register_blueprint(bp)
    # The panel renders with the state already in it; SSE keeps it current.
    app.add_template_global(feature.snapshot, "light_sequence_state")
    app.add_template_filter(clock_time, "stc_clock")
    rover.add_panel(30, "panels/scan_the_code.html", "Scan the Code", channels=(STATE_CHANNEL,))
