"""A rover_web's side of the fleet link: each robot it serves reports to the hub, and obeys its stop.

For each robot of the process: its summary (what GET /api/robots gives) signed on
rover_web/<fleet>/<robot>/summary once a second, and at once when something an operator must
see changes (link, mode, operator, e-stop, alerts); its liveliness token; and the queryable that
takes the hub's signed stop and engages the robot's e-stop exactly as its own e-stop button does
(EStopService.engage), recorded as by the hub's user, via "hub".

The link never stands between the robot and its own GUI: the session is opened on the link's
background loop, retried while it cannot open (a client whose router is not up yet), and every
Zenoh error is logged and survived. A robot whose link is down keeps working alone.
"""

from __future__ import annotations

import json
import logging
import threading
import time
from typing import TYPE_CHECKING

from rover_web.estop import EStopService
from rover_web.fleet.summary import summary as fleet_summary
from rover_web.web.api_messages import Text, said

from . import signing
from .session import LinkSettings, alive_key, open_session, stop_key, summary_key

if TYPE_CHECKING:
    from rover_web.core.fleet import Fleet
    from rover_web.core.state import Rover

log = logging.getLogger(__name__)

TICK_S = 0.25  # how soon a change goes out
PERIOD_S = 1.0  # a summary at least this often, changed or not: the hub's sign of life
RETRY_S = 2.0  # between attempts to open the session
CHANGE_FIELDS = ("link", "mode", "operator", "estop", "alerts")  # sent at once when they change


LINK_ALERTS = {"stale": said("link stale"), "degraded": said("link degraded")}


def robot_summary(rover: Rover, public_url: str | None) -> dict:
    """The robot's line of GET /api/robots, its URL made absolute for the hub, and its alerts."""
    line = fleet_summary(rover, "")
    line["url"] = f"{public_url.rstrip('/')}{line['url']}" if public_url else None
    alerts: list[Text] = [LINK_ALERTS[line["link"]]] if line["link"] in LINK_ALERTS else []
    geofence = rover.hub.latest("geofence") or {}
    if geofence.get("state") == "outside":  # its message: the breach banner's sentence (geofence/service.py)
        alerts.append(geofence.get("message") or said("outside the geofence"))
    # The English for any reader, and each one's id and values for the hub's page in its language.
    line["alerts"] = [a.english() for a in alerts]
    line["alerts_i18n"] = [a.wire() for a in alerts]
    return line


class _Robot:
    """One robot's declarations on the open session, and what it last sent."""

    def __init__(self, rover: Rover):
        self.rover = rover
        self.name = rover.robot.name
        self.publisher = self.token = self.queryable = None
        self.seq = 0
        self.sent_at = 0.0
        self.sent_fields: tuple | None = None


class RobotLink:
    def __init__(self, fleet: Fleet, link: LinkSettings, public_url: str | None, window_s: float):
        self.link = link
        self.public_url = public_url
        self.guard = signing.ReplayGuard(window_s)
        self._robots = [_Robot(rover) for rover in fleet]
        self._session = None
        self._next_open = 0.0
        self._failures = 0
        self._lock = threading.Lock()  # the session's opening and closing
        self._closed = False

    @property
    def open_failures(self) -> int:
        """Attempts to open the session that failed so far (each retried RETRY_S later)."""
        return self._failures

    # --- the background loop (Rover.every on the first robot: joined at shutdown) ---

    def tick(self) -> None:
        try:
            if self._session is None and not self._open():
                return
            now = time.monotonic()
            for robot in self._robots:
                self._report(robot, now)
        except Exception:
            log.exception("zenoh link: could not publish the robots' summaries")

    def _open(self) -> bool:
        now = time.monotonic()
        if now < self._next_open:
            return False
        with self._lock:
            if self._closed:
                return False
            try:
                session = open_session(self.link)
            except Exception as exc:
                self._failures += 1
                self._next_open = now + RETRY_S
                if self._failures in (1, 10) or self._failures % 100 == 0:
                    log.warning("zenoh link: cannot open a session (attempt %d, retrying every %.0f s): %s",
                                self._failures, RETRY_S, exc)
                return False
            try:
                for robot in self._robots:
                    self._declare(session, robot)
            except Exception:
                log.exception("zenoh link: could not declare the robots' keys; retrying")
                session.close()
                self._next_open = now + RETRY_S
                return False
            self._session = session
        log.info("zenoh link open: fleet %s, robots %s", self.link.fleet, ", ".join(r.name for r in self._robots))
        return True

    def _declare(self, session, robot: _Robot) -> None:
        fleet = self.link.fleet
        robot.publisher = session.declare_publisher(summary_key(fleet, robot.name))
        robot.token = session.liveliness().declare_token(alive_key(fleet, robot.name))
        robot.queryable = session.declare_queryable(stop_key(fleet, robot.name),
                                                    lambda query, robot=robot: self._on_stop(robot, query))

    def _report(self, robot: _Robot, now: float) -> None:
        line = robot_summary(robot.rover, self.public_url)
        fields = tuple(json.dumps(line.get(k), sort_keys=True) for k in CHANGE_FIELDS)
        if fields == robot.sent_fields and now - robot.sent_at < PERIOD_S:
            return
        robot.seq += 1
        robot.publisher.put(signing.signed_summary(self.link.key, self.link.fleet, robot.name, robot.seq, line))
        robot.sent_at, robot.sent_fields = now, fields

    # --- the hub's stop (on a Zenoh thread) ---

    def _on_stop(self, robot: _Robot, query) -> None:
        try:
            reply = self.stop_answer(robot.rover, robot.name, query.payload.to_bytes() if query.payload else b"")
            query.reply(query.key_expr, json.dumps(reply).encode())
        except Exception:
            log.exception("zenoh link: could not answer the hub's stop for %s", robot.name)

    def stop_answer(self, rover: Rover, name: str, payload: bytes) -> dict:
        """Check the command; engage the e-stop if it holds; the signed answer either way."""
        key, fleet = self.link.key, self.link.fleet
        try:  # oversized: refused as malformed, unparsed (anyone on the Zenoh network may send it)
            command = json.loads(payload) if payload and len(payload) <= signing.COMMAND_MAX_BYTES else None
        except ValueError:
            command = None
        nonce = command.get("nonce") if isinstance(command, dict) and isinstance(command.get("nonce"), str) else ""
        try:
            self.guard.check(key, fleet, name, command)
        except signing.CommandRefused as exc:
            log.warning("zenoh link: refused a stop for %s: %s", name, exc)
            return signing.answer(key, fleet, name, nonce[:128], "refused", reason=exc.reason, message=str(exc))
        state = rover.feature(EStopService).engage(command["by"], via="hub")
        return signing.answer(key, fleet, name, nonce, "engaged" if state.get("engaged") else "not_engaged",
                              estop={k: state.get(k) for k in ("engaged", "since", "by", "via")})

    # --- shutdown ---

    def close(self) -> None:
        """Undeclare and close: the hub sees each robot's token go at once, not after a lease."""
        with self._lock:
            self._closed = True
            session, self._session = self._session, None
        if session is None:
            return
        try:
            for robot in self._robots:
                for declared in (robot.token, robot.queryable, robot.publisher):
                    if declared is not None:
                        declared.undeclare()
            session.close()
        except Exception:
            log.exception("zenoh link: error while closing the session")
