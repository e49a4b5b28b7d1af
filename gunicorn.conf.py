"""gunicorn settings for rover_web: one worker (one ROS node), threads for concurrency.

    gunicorn -c gunicorn.conf.py 'rover_web:create_app()'
"""

import os

bind = f"{os.environ.get('ROVER_WEB_HOST', '127.0.0.1')}:{os.environ.get('ROVER_WEB_PORT', '5000')}"
workers = 1  # every worker would be a separate ROS node; never raise this
worker_class = "gthread"
# Each open stream (SSE, MJPEG, topic echo, teleop socket) holds a thread; rover_web caps them at
# ROVER_WEB_MAX_STREAMS, so these 16 more threads are always there for short requests: the e-stop.
threads = int(os.environ.get("ROVER_WEB_MAX_STREAMS", "64")) + 16
timeout = 0  # event streams are long-lived by design
graceful_timeout = 5
# HTTPS: the same certificate and key the demo uses (`flask --app rover_web tls self-signed` writes a pair).
certfile = os.environ.get("ROVER_WEB_TLS_CERT") or None
keyfile = os.environ.get("ROVER_WEB_TLS_KEY") or None


def on_starting(server):
    # Whether sign-in is required (ROVER_WEB_AUTH=auto) depends on where the server listens; a
    # `-b` on gunicorn's command line overrides `bind` above, so tell the app what was chosen.
    hosts = [address.rsplit(":", 1)[0].strip("[]") if not address.startswith("unix:") else address
             for address in server.cfg.bind]
    os.environ["ROVER_WEB_HOST"] = ",".join(hosts)


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
        rover.fleet.zero_all()  # every robot this worker serves
