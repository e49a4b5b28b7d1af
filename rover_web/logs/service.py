"""RosoutLog: the /rosout subscription, its ring, the batched `rosout` channel and the error count."""

from __future__ import annotations

from rover_web.core.state import Rover

from . import msgs
from .ring import LogRing

BATCH_PERIOD_S = 0.25  # 1,000 lines a second become 4 events a second on the `rosout` channel
HEALTH_PERIOD_S = 1.0


class RosoutLog:
    def __init__(self, rover: Rover):
        self.rover = rover
        config = rover.config
        self.ring = LogRing(config["ROVER_WEB_ROSOUT_KEEP"], max_bytes=config["ROVER_WEB_ROSOUT_KEEP_BYTES"])
        self.received = 0
        self._health: dict | None = None

    def subscribe(self) -> None:
        self.rover.runtime.subscribe(msgs.LOG, msgs.ROSOUT, self.on_log, qos=msgs.rosout_qos(), track=False)

    def on_log(self, msg) -> None:
        self.received += 1
        self.ring.add(msgs.log_line(msg))

    def flush(self) -> None:
        """Send what arrived since the last flush as one `rosout` value.

        Published, not emitted: a log flood must not fill the hub's replay ring (it would hold 256
        batches of lines and push every other channel's events out of it). A browser that misses
        a batch (a slow socket, a reconnect) sees a gap in the line numbers and reads the ring
        with GET /api/rosout instead.
        """
        lines, skipped = self.ring.drain()
        if lines:
            self.rover.hub.publish("rosout", {"first_seq": lines[0]["seq"], "last_seq": lines[-1]["seq"] + skipped,
                                              "lines": lines, "skipped": skipped})

    def health(self) -> dict:
        return {"errors_last_minute": self.ring.errors_last_minute(), "kept": len(self.ring)}

    def publish_health(self) -> None:
        """The health bar's error count, on `rosout_health`, only when it changed."""
        current = self.health()
        if current != self._health:
            self.rover.hub.publish("rosout_health", current)
            self._health = current
