"""rover_web: a web GUI for ROS 2 robots. One Flask process that is itself a ROS 2 node.

This module is the application factory and nothing else: read create_app top to bottom to see
every part of the app and the order it is wired in.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from flask import Flask

from rover_web import config as config_module
from rover_web import process
from rover_web.config import ROOT, ConfigError
from rover_web.i18n import N_
from rover_web.ros import RosUnavailable, require_rclpy

log = logging.getLogger(__name__)

__all__ = ["create_app"]


def create_app(test_config: Mapping[str, Any] | None = None) -> Flask:
    """The application factory. Outside tests, a bad setting or missing ROS exits with one sentence."""
    try:
        return _create_app(test_config)
    except (ConfigError, RosUnavailable) as exc:
        if test_config is not None:
            raise
        raise SystemExit(f"rover_web: {exc}") from None


def _create_app(test_config: Mapping[str, Any] | None) -> Flask:
    settings = config_module.load(test_config)
    app = Flask(__name__, template_folder=str(ROOT / "templates"), static_folder=str(ROOT / "static"),
                instance_relative_config=True)
    app.config.update(settings)
    app.config["MAX_CONTENT_LENGTH"] = settings["ROVER_WEB_MAX_BODY_BYTES"]
    app.json.sort_keys = False  # keep fields in the order the code builds them
    if test_config:
        app.config.update({k: v for k, v in test_config.items() if not k.startswith(config_module.PREFIX)})

    # The web layer first (every route's protection), then the CLI commands: those are registered
    # before, and without, the ROS node, so `flask tiles fetch` or `flask users add` never joins
    # the ROS graph.
    from rover_web import auth, basemap, linkemu, recording
    from rover_web.web import dev_server, http

    http.init_app(app)
    dev_server.install()  # `flask run`: no epoll descriptor left per dropped request (issue 27)
    auth.init_cli(app)
    basemap.init_cli(app)
    linkemu.init_cli(app)
    recording.init_cli(app)  # `flask replay` makes its own ROS node, only when it runs
    if process.is_reloader_watcher():
        log.warning("reloader watcher process: the ROS node starts in the serving child only")
        return app
    if process.is_cli_command_lookup():
        return app  # a CLI command, not a server: no node, no database, no stop-on-exit hooks
    from rover_web import i18n
    from rover_web.web import assets

    i18n.init_app(app)  # robot and hub: the pages' language; before assets, which serves the browser's catalogues
    assets.init_app(app)  # hashed, pre-compressed static files and each page's modules named up front
    if settings["ROVER_WEB_HUB"]:
        from rover_web import hub  # a fleet hub: robots heard over Zenoh, and no ROS at all

        return hub.create(app, settings, testing=app.testing)
    from rover_web import zenoh_link

    zenoh_link.check_settings(settings)  # Zenoh on without the fleet key: refused before the node starts

    require_rclpy()
    from rover_web import (
        apidocs,
        camera,
        diagnostics,
        estop,
        geofence,
        layouts,
        livemap,
        logs,
        metrics,
        nav2,
        overlays,
        panels,
        plot,
        prefs,
        recording,
        ros_admin,
        scan_the_code,
        telemetry,
        teleop,
        tf,
        topics,
        view3d,
        waypoints,
    )
    from rover_web import fleet as fleet_pages
    from rover_web.core.state import EXTENSION
    from rover_web.fleet import build_fleet
    from rover_web.ros import dds_profiles
    from rover_web.ros.runtime import RosRuntime
    from rover_web.storage.claim import claim
    from rover_web.storage.db import database_path
    from rover_web.web import pages, sse, status

    db_path = database_path(app)
    db_claim = claim(db_path)  # before the node: a refused second server never joins the ROS graph
    try:
        # Before the first participant: Fast DDS reads its profiles once (ros/dds_profiles.py).
        dds_profiles.prepare(overlays.reader_topics(settings), Path(app.instance_path) / "dds",
                             settings["ROVER_WEB_NODE_NAME"])
        runtime = RosRuntime(settings["ROVER_WEB_NODE_NAME"], settings["ROVER_WEB_ROS_DOMAIN_ID"])
    except BaseException:
        db_claim.release()
        raise
    fleet = None
    try:
        fleet = build_fleet(settings, runtime, db_path, db_claim)  # one Rover per robot (core/fleet.py)
        graph = fleet.graph  # the graph-wide scope: the first robot when there is only one
        app.extensions[EXTENSION] = fleet.first
        auth.init_app(app, graph)  # first: every route after it is checked for sign-in and role
        prefs.init_app(app, graph)  # each user's theme and language: every page is rendered in them
        estop.init_app(app, fleet)  # before every feature that moves the robot: they gate on it
        geofence.init_app(app, fleet)  # before waypoints and livemap: they check it before publishing
        tf.init_app(app, fleet)  # the frames: before livemap, overlays and GPS, which place things through it
        # Features, in dashboard order of their cards; each registers its routes once and sets up
        # every robot (a fleet) or the graph-wide scope (graph) it serves.
        telemetry.init_app(app, fleet)
        teleop.init_app(app, fleet)
        basemap.init_app(app, graph)
        waypoints.init_app(app, fleet)
        scan_the_code.init_app(app, fleet)
        panels.init_app(app, fleet)
        livemap.init_app(app, fleet)
        nav2.init_app(app, fleet)  # after livemap: goals are checked on its maps; its panel is on LiveMap
        overlays.init_app(app, fleet)  # what the robot senses, on LiveMap
        view3d.init_app(app, fleet)  # after overlays (it shares their markers subscription) and tf
        camera.init_app(app, fleet)
        topics.init_app(app, graph)
        logs.init_app(app, graph)
        diagnostics.init_app(app, fleet)
        tf.add_nav(fleet)  # the TF page's link beside Diagnostics (tf itself is set up first, above)
        plot.init_app(app, graph)  # after topics: plots share its subscriptions
        ros_admin.init_app(app, graph)
        layouts.init_app(app, fleet)  # the dashboard's cards: after every feature that has one
        recording.init_app(app, fleet)  # last of the features: it records what they publish and do
        fleet_pages.init_app(app, fleet)  # /robots, /api/robots and /robots/<name>/... for every route
        zenoh_link.init_app(fleet)  # last: its summaries read every feature; its stop engages the e-stop
        metrics.init_app(app, fleet)  # GET /metrics reads every feature at scrape time
    except BaseException:
        # A feature that failed to start may follow others that already started loops and
        # threads: stop them all in order, not just the node under them.
        if fleet is not None:
            fleet.shutdown()
        else:
            runtime.stop(0.5)
            db_claim.release()
        raise
    app.register_blueprint(pages.bp)
    graph.add_nav(N_("Status"), "/status")
    app.register_blueprint(status.bp)
    app.register_blueprint(sse.bp)
    apidocs.init_app(app, graph)  # after every route: it describes them all (docs/api.md)
    runtime.start()
    for rover in fleet:
        status.start_reporter(rover)
    if not app.testing:
        process.stop_with_process(fleet.first)
        process.freeze_startup_heap()
    return app
