"""The `waypoints` SSE channel: the stored mission, read back from the database after each change."""

from __future__ import annotations

import logging
import threading

from .store import WaypointStore

log = logging.getLogger(__name__)

CHANNEL = "waypoints"
MAX_HZ = 10.0


class MissionBroadcaster:
    """Keeps the `waypoints` channel equal to the stored mission, read back from the database.

    Writers only say "changed"; this thread reads the committed mission and publishes it at most
    max_hz times a second, so a burst of writes costs one read and one frame per interval, and the
    channel can never show an older mission after a newer one.
    """

    def __init__(self, store: WaypointStore, hub, max_hz: float = MAX_HZ):
        self._store, self._hub = store, hub
        self._interval_s = 1.0 / max_hz
        self._changed = threading.Event()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="waypoints-broadcaster", daemon=True)

    def start(self) -> None:
        self.publish_now()
        self._thread.start()

    def changed(self) -> None:
        self._changed.set()

    def publish_now(self) -> None:
        mission = self._store.mission().to_dict()
        mission["max"] = self._store.max_waypoints
        self._hub.publish(CHANNEL, mission)

    def _run(self) -> None:
        while not self._stop.is_set():
            if not self._changed.wait(0.5):
                continue
            self._changed.clear()
            if self._stop.is_set():
                break
            try:
                self.publish_now()
            except Exception:
                log.exception("could not publish the mission to the waypoints channel")
            self._stop.wait(self._interval_s)

    def stop(self) -> None:
        """Ends the thread and joins it (a shutdown hook)."""
        self._stop.set()
        self._changed.set()
        if self._thread.is_alive():
            self._thread.join(2.0)
