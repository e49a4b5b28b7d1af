"""Diagnostics: /diagnostics and /diagnostics_agg into the board, the `diagnostics` channel."""

from __future__ import annotations

from rover_web.core.state import Rover

from . import msgs
from .board import DiagnosticsBoard

MAX_HZ = 4.0  # a diagnostic_updater publishes at ~1 Hz; an aggregator burst must not flood browsers
REFRESH_S = 1.0  # ages and staleness move on even when nothing arrives


class Diagnostics:
    def __init__(self, rover: Rover):
        self.rover = rover
        self.board = DiagnosticsBoard(rover.config["ROVER_WEB_DIAGNOSTICS_STALE_S"])

    def subscribe(self) -> None:
        # /diagnostics_agg is subscribed even when no aggregator runs: an unmatched subscription costs nothing.
        for topic in map(self.rover.resolve, msgs.TOPICS):  # each robot's own /diagnostics
            self.rover.runtime.subscribe(msgs.DIAGNOSTIC_ARRAY, topic,
                                         lambda msg, topic=topic: self.on_array(msg, topic), qos=50, track=False)

    def on_array(self, msg, topic: str) -> None:
        self.board.update(msgs.statuses(msg), topic)
        self.publish()

    def snapshot(self) -> dict:
        statuses = self.board.snapshot()
        return {"stale_after_s": self.board.stale_s, "statuses": statuses,
                "hardware": DiagnosticsBoard.worst_by_hardware(statuses)}

    def publish(self) -> None:
        self.rover.hub.publish_throttled("diagnostics", self.snapshot(), MAX_HZ)

    def refresh(self) -> None:
        if len(self.board):
            self.publish()
