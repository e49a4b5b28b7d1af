"""The geofence's per-app object: the fence in force, its checks, and the robot's side of it."""

from __future__ import annotations

import logging
import threading
import time

from rover_web.estop import EStopService
from rover_web.panels.oplog import OperatorLog
from rover_web.web.api_messages import Text, said, text_of, with_wire

from .rules import Fence, OutsideGeofence, parse_fence
from .store import GeofenceStore

log = logging.getLogger(__name__)

CHANNEL = "geofence"
ESTOP_BY = "geofence breach"
OPLOG_PANEL = "geofence"  # its entries in the operator log (panel_log)


def breach_message(refused: OutsideGeofence) -> Text:
    """The banner every viewer reads: said, so each browser shows it in its own language."""
    return said("the robot left the geofence: %(why)s", why=text_of(refused))


class GeofenceService:
    def __init__(self, store: GeofenceStore, estop: EStopService, hub, *, max_vertices: int,
                 engage_estop: bool, oplog: OperatorLog | None = None):
        self.store = store
        self.oplog = oplog
        self.estop = estop
        self.hub = hub
        self.max_vertices = max_vertices
        self.engage_estop = engage_estop
        loaded = store.load()
        # Stored fences were checked when they were stored; a changed vertex cap must not lock
        # the operator out of the fence they already have.
        self.fence = parse_fence(loaded[0], 1 << 31) if loaded else Fence()
        self.revision = loaded[1] if loaded else 0
        self._write_lock = threading.Lock()
        # The /fix callback only leaves the position here and sets `pending`; the check runs on
        # the geofence loop, never on the executor thread.
        self.pending = threading.Event()
        self._position: tuple[float, float] | None = None
        self.refused = 0  # goals and routes refused for leaving the fence
        self._state = {"state": "unknown", "lng": None, "lat": None, "since": None, "message": None}

    # --- the fence ---

    def collection(self) -> dict:
        return {**self.fence.to_geojson(), "revision": self.revision}

    def replace(self, doc, by: str = "") -> dict:
        """Check and store a new fence; InvalidInput (nothing changed) when it is not one. Who did
        it goes in the operator log (panel "geofence")."""
        fence = parse_fence(doc, self.max_vertices)
        with self._write_lock:
            revision = self.store.save(fence.to_geojson())
            self.fence, self.revision = fence, revision
        log.info("geofence replaced by %s: revision %d, %d areas", by or "?", revision, len(fence.areas))
        if self.oplog is not None:
            action = "empty" if fence.empty else "replace"
            done = "emptied" if fence.empty else "replaced"
            self.oplog.record(OPLOG_PANEL, action, f"geofence {done}: revision {revision}, {len(fence.areas)} areas",
                              None, "sent", client=by)
        self.pending.set()  # the robot may be outside the new fence
        self._publish()
        return self.collection()

    def seed(self, doc) -> None:
        """The default fence (ROVER_WEB_GEOFENCE_FILE) when none was ever stored."""
        if self.revision == 0:
            self.replace(doc, by="ROVER_WEB_GEOFENCE_FILE")

    # --- checks other features make before anything is stored or published ---

    def check_point(self, lng: float, lat: float) -> None:
        try:
            self.fence.check_point(lng, lat)
        except OutsideGeofence:
            self.refused += 1  # for /metrics (rover_web/metrics)
            raise

    def check_route(self, points) -> None:
        try:
            self.fence.check_route(points)
        except OutsideGeofence:
            self.refused += 1
            raise

    # --- the robot's position ---

    def note_position(self, lng: float, lat: float) -> None:
        """Called from the /fix callback with a valid fix: cheap, no geometry here."""
        self._position = (lng, lat)
        self.pending.set()

    def evaluate(self) -> None:
        """The loop's work: one prepared point-in-polygon test per new position."""
        self.pending.clear()
        position = self._position
        if position is None:
            return
        fence = self.fence
        refused = fence.refusal(*position)
        state = "unknown" if fence.empty else ("outside" if refused else "inside")
        if state == self._state["state"]:
            return
        was_outside = self._state["state"] == "outside"
        self._state = {"state": state, "lng": position[0], "lat": position[1], "since": time.time(),
                       "message": breach_message(refused) if refused else None}
        if state == "outside":
            log.warning("geofence breach: %s", refused)
            if self.engage_estop:
                self.estop.engage(ESTOP_BY, via="geofence")
        elif was_outside:
            log.warning("geofence: the robot is back inside")
        self._publish()

    def state(self) -> dict:
        return with_wire({**self._state, "revision": self.revision, "areas": len(self.fence.areas),
                          "estop_on_breach": self.engage_estop})

    def _publish(self) -> None:
        self.hub.publish(CHANNEL, self.state())
