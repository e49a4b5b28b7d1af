"""gunicorn settings for rover_web: one worker (one ROS node), threads for concurrency.

    gunicorn -c gunicorn.conf.py 'rover_web:create_app()'
"""

import os

bind = f"{os.environ.get('ROVER_WEB_HOST', '127.0.0.1')}:{os.environ.get('ROVER_WEB_PORT', '5000')}"
workers = 1  # every worker would be a separate ROS node; never raise this
worker_class = "gthread"
threads = 64  # each open page holds one thread (its SSE stream) plus one per WebSocket
timeout = 0  # event streams are long-lived by design
graceful_timeout = 5


def worker_int(worker):
    _halt(worker)


def worker_abort(worker):
    _halt(worker)


def worker_exit(server, worker):
    # The ordered ROS shutdown (zero velocity first) of every app this worker created.
    _halt(worker, full=True)


def _halt(worker, full=False):
    app = getattr(worker, "wsgi", None)
    rover = getattr(app, "extensions", {}).get("rover_web") if app is not None else None
    if rover is None:
        return
    if full:
        rover.shutdown()
    else:
        rover.cmd_vel.halt()
