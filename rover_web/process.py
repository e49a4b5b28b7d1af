"""How the app lives in its process: which Flask CLI invocation loaded it, stopping the robot on
SIGTERM/SIGINT and at exit, and freezing the start-up heap out of the garbage collector."""

from __future__ import annotations

import atexit
import gc
import logging
import os
import signal
import sys
import threading
import weakref

log = logging.getLogger(__name__)

_live_rovers: weakref.WeakSet = weakref.WeakSet()


def is_reloader_watcher() -> bool:
    """True in the file-watching parent of `flask run --reload`, which never serves a request.

    Werkzeug's reloader loads the app in the watcher *and* in the serving child; only the child
    (WERKZEUG_RUN_MAIN=true) may create the ROS node, or two nodes with one name would appear.
    """
    if os.environ.get("WERKZEUG_RUN_MAIN") == "true":
        return False
    import click
    from flask.helpers import get_debug_flag

    ctx = click.get_current_context(silent=True)
    if ctx is None or ctx.info_name != "run":
        return False
    reload = ctx.params.get("reload")
    return bool(get_debug_flag() if reload is None else reload)


def is_cli_command_lookup() -> bool:
    """True when the flask CLI loads the app only to find one of its own commands (or list them).

    For an app-provided command (`flask tiles fetch`, `flask --help`) Flask's FlaskGroup loads the
    app while resolving the command name, so the current click context is the group itself; for
    `flask run` (and `routes`, `shell`) the context is that command's.
    """
    import click
    from flask.cli import FlaskGroup

    ctx = click.get_current_context(silent=True)
    return ctx is not None and isinstance(ctx.command, FlaskGroup)


def freeze_startup_heap() -> None:
    """What start-up built (modules, routes, message classes: ~60,000 objects) lives as long as the
    process. Taking it out of the garbage collector's reach turns a full collection from ~20 ms,
    a pause every thread waits out under the GIL (a joystick frame, an SSE delivery), into well
    under a millisecond."""
    gc.collect()
    gc.freeze()


def stop_with_process(rover) -> None:
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
                live.fleet.zero_all()  # every robot the process serves
            if callable(previous) and previous not in (signal.SIG_IGN, signal.SIG_DFL):
                return previous(sig, frame)
            if sig == signal.SIGINT:
                raise KeyboardInterrupt
            sys.exit(0)

        handler._rover_web = True  # type: ignore[attr-defined]
        signal.signal(signum, handler)


def listen_hosts(settings) -> list[str]:
    """The addresses the server will listen on, as far as the app can know before it serves.

    `flask run --host` is read from its command line; the demo and gunicorn.conf.py bind to
    ROVER_WEB_HOST and set it (gunicorn.conf.py copies a `-b` given on gunicorn's command line
    into it). Under any other server it is unknown unless set: [] then, and sign-in is required.
    """
    import click

    ctx = click.get_current_context(silent=True)
    if ctx is not None and ctx.info_name == "run" and "host" in ctx.params:
        return [ctx.params["host"] or "127.0.0.1"]
    return [h.strip() for h in str(settings["ROVER_WEB_HOST"] or "").split(",") if h.strip()]
