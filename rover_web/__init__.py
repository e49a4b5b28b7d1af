"""rover_web: a web GUI for ROS 2 robots. One Flask process that is itself a ROS 2 node."""

from __future__ import annotations

import atexit
import gc
import importlib
import logging
import os
import signal
import sys
import threading
import weakref
from pathlib import Path
from typing import Any, Mapping

from flask import Flask

from rover_web import config as config_module
from .config import ConfigError
from rover_web.events.hub import EventHub

ROOT = Path(__file__).resolve().parent.parent

# Feature modules, each with init_app(app, rover): routes, subscriptions, channels, panels.
FEATURES = ("telemetry", "teleop", "waypoints", "scan_the_code", "panels", "livemap", "camera", "topics")

# Modules with init_cli(app): `flask --app rover_web <command>` commands. They are registered
# before (and without) the ROS node, so a command such as `flask tiles fetch` never joins the ROS
# graph or publishes a stop on exit.
CLI_MODULES = ("tiles",)

log = logging.getLogger(__name__)

__all__ = ["create_app", "ConfigError", "ROOT"]


def _is_reloader_watcher() -> bool:
    """True in the file-watching parent of `flask run --reload`, which never serves a request.

    Werkzeug's reloader loads the app in the watcher *and* in the serving child; only the child
    (WERKZEUG_RUN_MAIN=true) may create the ROS node, or two nodes with one name would appear.
    """
    if os.environ.get("WERKZEUG_RUN_MAIN") == "true":
        return False
    try:
        import click
        from flask.helpers import get_debug_flag
    except ImportError:  # pragma: no cover
        return False
    ctx = click.get_current_context(silent=True)
    if ctx is None or ctx.info_name != "run":
        return False
    reload = ctx.params.get("reload")
    return bool(get_debug_flag() if reload is None else reload)


def _is_cli_command_lookup() -> bool:
    """True when the flask CLI loads the app only to find one of its own commands (or list them).

    For an app-provided command (`flask tiles fetch`, `flask --help`) Flask's FlaskGroup loads the
    app while resolving the command name, so the current click context is the group itself; for
    `flask run` (and `routes`, `shell`) the context is that command's.
    """
    try:
        import click
        from flask.cli import FlaskGroup
    except ImportError:  # pragma: no cover
        return False
    ctx = click.get_current_context(silent=True)
    return ctx is not None and isinstance(ctx.command, FlaskGroup)


def create_app(test_config: Mapping[str, Any] | None = None) -> Flask:
    """The application factory. Outside tests, a bad setting or missing ROS exits with one sentence."""
    try:
        return _create_app(test_config)
    except (ConfigError, _ros_unavailable()) as exc:
        if test_config is not None:
            raise
        raise SystemExit(f"rover_web: {exc}") from None


def _ros_unavailable() -> type[Exception]:
    from .ros import RosUnavailable
    return RosUnavailable


def _create_app(test_config: Mapping[str, Any] | None) -> Flask:
    settings = config_module.load(test_config)
    app = Flask(__name__, template_folder=str(ROOT / "templates"), static_folder=str(ROOT / "static"),
                instance_relative_config=True)
    app.config.update(settings)
    app.config["MAX_CONTENT_LENGTH"] = settings["ROVER_WEB_MAX_BODY_BYTES"]
    app.json.sort_keys = False  # keep fields in the order the code builds them
    if test_config:
        app.config.update({k: v for k, v in test_config.items() if not k.startswith(config_module.PREFIX)})

    from .web import http, pages, sse, status

    http.init_app(app)
    for name in CLI_MODULES:
        importlib.import_module(f"{__name__}.{name}").init_cli(app)
    if _is_reloader_watcher():
        log.warning("reloader watcher process: the ROS node starts in the serving child only")
        return app
    if _is_cli_command_lookup():
        return app  # a CLI command, not a server: no node, no database, no stop-on-exit hooks

    from .ros import require_rclpy
    require_rclpy()
    from rover_web.core.state import Rover
    from rover_web.storage.db import Database, database_path
    from rover_web.events.broadcast import Broadcaster
    from rover_web.ros.cmd_vel import CmdVelOutput
    from rover_web.ros.runtime import RosRuntime

    runtime = RosRuntime(settings["ROVER_WEB_NODE_NAME"], settings["ROVER_WEB_ROS_DOMAIN_ID"])
    try:
        cmd_vel = CmdVelOutput(runtime, settings["ROVER_WEB_CMD_VEL_TOPIC"],
                               max_linear_mps=settings["ROVER_WEB_MAX_LINEAR_MPS"],
                               max_angular_rps=settings["ROVER_WEB_MAX_ANGULAR_RPS"],
                               stamped=settings["ROVER_WEB_CMD_VEL_STAMPED"],
                               frame_id=settings["ROVER_WEB_CMD_VEL_FRAME_ID"])
        hub = EventHub(max_clients=settings["ROVER_WEB_SSE_MAX_CLIENTS"])
        rover = Rover(settings, hub, runtime, cmd_vel)
        rover.broadcaster = Broadcaster(hub, settings["ROVER_WEB_SSE_KEEPALIVE_S"])
        rover.db = Database(database_path(app))
        rover.on_shutdown(rover.db.close)
        app.extensions["rover_web"] = rover
        for name in FEATURES:
            importlib.import_module(f"{__name__}.{name}").init_app(app, rover)
    except BaseException:
        runtime.stop(0.5)
        raise
    app.register_blueprint(pages.bp)
    app.register_blueprint(status.bp)
    app.register_blueprint(sse.bp)
    runtime.start()
    status.start_reporter(rover)
    if not app.testing:
        _stop_with_process(rover)
        _freeze_startup_heap()
    return app


def _freeze_startup_heap() -> None:
    """What start-up built (modules, routes, message classes: ~60,000 objects) lives as long as the
    process. Taking it out of the garbage collector's reach turns a full collection from ~20 ms,
    a pause every thread waits out under the GIL (a joystick frame, an SSE delivery), into well
    under a millisecond."""
    gc.collect()
    gc.freeze()


_live_rovers: "weakref.WeakSet" = weakref.WeakSet()


def _stop_with_process(rover) -> None:
    """Stop the robot first on SIGTERM/SIGINT or interpreter exit, then let the server exit.

    A previous SIGTERM handler (gunicorn's graceful stop) still runs after ours; with none, the
    process exits. The ordered ROS shutdown itself happens at exit, once serving has stopped.
    """
    _live_rovers.add(rover)
    atexit.register(rover.shutdown)
    if threading.current_thread() is not threading.main_thread():
        return
    for signum in (signal.SIGTERM, signal.SIGINT):
        previous = signal.getsignal(signum)
        if getattr(previous, "_rover_web", False):
            continue

        def handler(sig, frame, previous=previous):
            for live in list(_live_rovers):
                try:
                    live.cmd_vel.halt()
                except Exception:
                    log.exception("could not stop the robot")
            if callable(previous) and previous not in (signal.SIG_IGN, signal.SIG_DFL):
                return previous(sig, frame)
            if sig == signal.SIGINT:
                raise KeyboardInterrupt
            sys.exit(0)

        handler._rover_web = True  # type: ignore[attr-defined]
        signal.signal(signum, handler)
