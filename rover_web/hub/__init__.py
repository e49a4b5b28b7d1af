"""The fleet hub (ROVER_WEB_HUB=true): every robot heard over Zenoh on one page, and one stop-all.

  GET  /robots          the hub's page: every robot, live or lost, a link to its own rover_web,
                        and the last stop-all's answers
  GET  /api/robots      every robot's summary (GET /api/robots's shape on a robot) and how it is heard
  POST /api/estop/all   a signed stop to every robot heard; each robot's answer, or no_answer
  GET  /api/status      the hub's own state: fleet, robots in each state, dropped summaries
  GET  /api/robots/<name>/history  a robot's state changes, e-stops and stop-all answers, newest first
  GET  /metrics         each robot's state for Prometheus (rover_web/metrics, hub/metrics.py)
  GET  /api/openapi.json  these routes described
  GET  /tiles/<z>/<x>/<y>  the installed basemap's tiles, for the page's map (rover_web/basemap)
  GET  /basemap/<name>   a drawn (GeoJSON) basemap, for the same map
Sign-in, users, tokens and roles are rover_web/auth's, as on a robot, in the hub's own database.

The hub is no ROS node: create() is called before rover_web imports rclpy, and nothing here
imports it (tests/integration/hub checks the hub process). Modules: directory (what is heard),
history (SQLite), stop_all, metrics, routes; the robots' side is rover_web/zenoh_link.
"""

from __future__ import annotations

import logging
import signal
import sys
import threading

from flask import Flask

from rover_web.config import ConfigError
from rover_web.core.robots import Robot
from rover_web.core.state import EXTENSION, Rover
from rover_web.events.broadcast import Broadcaster
from rover_web.events.hub import EventHub
from rover_web.i18n import N_
from rover_web.zenoh_link.session import link_settings, open_session

from .directory import Directory
from .history import History
from .metrics import StopAnswers
from .stop_all import StopAll

log = logging.getLogger(__name__)

SWEEP_S = 0.25  # how soon a state change reaches the history (the page computes its own at each poll)

__all__ = ["create", "FleetHub"]


class FleetHub:
    """What the hub serves from: the Zenoh session, the directory of robots and the stop-all.

    It stands where a robot's app keeps its ROS runtime (Rover.runtime): the app's ordered
    shutdown ends with runtime.stop(), which here closes the Zenoh session."""

    def __init__(self, session, directory: Directory, stop_all: StopAll, fleet: str, history: History | None = None):
        self.session, self.directory, self.stop_all, self.fleet = session, directory, stop_all, fleet
        self.history = history
        self.stop_answers = StopAnswers()  # for /metrics
        self._closed = False
        self._lock = threading.Lock()

    def sweep(self) -> None:
        """The background loop: each robot's state brought up to date, the changes written down."""
        events = self.directory.sweep()
        if self.history is not None and events:
            try:
                self.history.record(events)
            except Exception:  # a full disk must not stop the hub from showing and stopping robots
                log.exception("hub: could not write %d history events", len(events))

    def stop_robots(self, by: str) -> dict:
        result = self.stop_all.stop(self.directory.names(), by)
        self.stop_answers.add(result)
        if self.history is not None:
            try:
                self.history.record([(name, "stop_all", {"by": by, **{k: v for k, v in answer.items()
                                                                       if k in ("result", "reason")}})
                                     for name, answer in result["robots"].items()])
            except Exception:
                log.exception("hub: could not write the stop-all in the history")
        return result

    def stop(self, timeout_s: float = 0.0) -> None:
        with self._lock:
            if self._closed:
                return
            self._closed = True
        self.directory.close()
        try:
            self.session.close()
        except Exception:
            log.exception("hub: error while closing the Zenoh session")


def create(app: Flask, settings: dict, testing: bool) -> Flask:
    """Finish `app` as a hub: sign-in, the Zenoh session, the routes. ConfigError if it cannot serve."""
    from rover_web import auth, basemap, metrics, prefs
    from rover_web.storage.claim import claim
    from rover_web.storage.db import Database, database_path

    from . import routes

    link = link_settings(settings)
    if link is None:
        raise ConfigError("ROVER_WEB_HUB: a hub hears its robots over Zenoh: set ROVER_WEB_ZENOH_MODE to peer or "
                          "client, and ROVER_WEB_ZENOH_LISTEN or _CONNECT")
    # The hub serves no robot: the sign-in page's engage-only e-stop (rover_web/estop) is a robot's route.
    config = {**settings, "ROVER_WEB_LOGIN_ESTOP": False}
    app.config["ROVER_WEB_LOGIN_ESTOP"] = False
    db_path = database_path(app)
    held = claim(db_path)
    db = None
    try:
        db = Database(db_path)
        db.check()
        try:
            session = open_session(link)
        except ConfigError:
            raise
        except Exception as exc:
            raise ConfigError(f"ROVER_WEB_ZENOH_LISTEN/_CONNECT: the hub cannot open its Zenoh session: {exc}") \
                from None
        directory = Directory(link.key, link.fleet, settings["ROVER_WEB_FLEET_LOST_AFTER_S"],
                              window_s=settings["ROVER_WEB_FLEET_COMMAND_WINDOW_S"],
                              forget_after_s=settings["ROVER_WEB_FLEET_FORGET_AFTER_S"])
        history = History(db, settings["ROVER_WEB_HUB_HISTORY_DAYS"] * 86400,
                          settings["ROVER_WEB_HUB_HISTORY_MAX_ROWS"])
        hub = FleetHub(session, directory, StopAll(session, link.key, link.fleet,
                                                   settings["ROVER_WEB_FLEET_STOP_TIMEOUT_S"]), link.fleet, history)
        events = EventHub(max_clients=settings["ROVER_WEB_SSE_MAX_CLIENTS"])
        broadcaster = Broadcaster(events, settings["ROVER_WEB_SSE_KEEPALIVE_S"])
        rover = Rover(config, events, hub, None, db=db, broadcaster=broadcaster,
                      robot=Robot("hub", kind="robot"), nav_links=[(N_("Robots"), "/robots")])
        rover.on_shutdown(held.release)
        rover.on_shutdown(db.close)
        rover.add_feature(hub)
        app.extensions[EXTENSION] = rover
        try:
            auth.init_app(app, rover)  # first: every route after it is checked for sign-in and role
            prefs.init_app(app, rover)
            directory.listen(session)
            rover.every(SWEEP_S, hub.sweep, name="hub-sweep", immediately=True)
        except BaseException:
            rover.shutdown()
            raise
    except BaseException:
        if app.extensions.get(EXTENSION) is None:
            if db is not None:
                db.close()
            held.release()
        raise
    app.register_blueprint(routes.bp)
    metrics.init_hub(app, rover, hub)
    basemap.init_app(app, rover)  # the map on /robots draws the same offline basemap as a robot's
    if not testing:
        _stop_with_process(rover)
    log.info("fleet hub for %s: Zenoh %s, listen %s, connect %s", link.fleet, link.mode, link.listen, link.connect)
    return app


def _stop_with_process(rover: Rover) -> None:
    """The Zenoh session is closed before the interpreter waits for its threads, however the process ends.

    Zenoh runs the subscribers' Python callbacks on threads of its own that are not daemons, and
    at exit the interpreter joins those before it runs atexit hooks: with the session still open
    the process never ended (after SIGTERM, or after `flask run` gave up on a port in use).
    threading's own exit hooks run before that join (concurrent.futures uses them too); SIGTERM
    and SIGINT close the session first as well. The hub has no robot to stop first."""
    import atexit

    register = getattr(threading, "_register_atexit", None)  # CPython 3.9+; private, hence the fallback
    try:
        if register is None:
            raise RuntimeError("threading._register_atexit is not available")
        register(rover.shutdown)
    except RuntimeError:
        atexit.register(rover.shutdown)
    if threading.current_thread() is not threading.main_thread():
        return

    def handler(sig, frame):
        log.warning("hub: %s: closing the Zenoh session and stopping", signal.Signals(sig).name)
        rover.shutdown()
        if sig == signal.SIGINT:
            raise KeyboardInterrupt
        sys.exit(0)

    for signum in (signal.SIGTERM, signal.SIGINT):
        signal.signal(signum, handler)
