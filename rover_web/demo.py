"""`python -m rover_web.demo`: the simulator in its own process plus the GUI, stopped by one Ctrl-C.

The simulator is a separate process on purpose: the GUI talks to it over DDS exactly as it would
talk to a real robot. The terminal shows what an operator needs (where the GUI is, warnings, errors
and failed requests); `--verbose` adds a line per request and the simulator's DEBUG lines.
"""

from __future__ import annotations

import argparse
import os
import signal
import subprocess
import sys

from werkzeug.serving import WSGIRequestHandler

DEMO_GEOFENCE = "map_files/geofence.geojson"


class QuietRequestHandler(WSGIRequestHandler):
    """Only failed requests reach the terminal: an open dashboard alone asks for something every second."""

    def log_request(self, code="-", size="-") -> None:
        try:
            failed = int(code) >= 500
        except (TypeError, ValueError):
            failed = True
        if failed:
            super().log_request(code, size)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m rover_web.demo", description=__doc__)
    parser.add_argument("--host", default=None, help="address to serve on (default ROVER_WEB_HOST, 127.0.0.1)")
    parser.add_argument("--port", type=int, default=None, help="port (default ROVER_WEB_PORT, 5000)")
    parser.add_argument("--domain-id", type=int, default=None,
                        help="ROS domain for both (default: ROS_DOMAIN_ID, else a private 42)")
    parser.add_argument("--robots", default=None, metavar="NAMES",
                        help="several simulated robots, e.g. boat,rover,drone: each in its own namespace, "
                             "the GUI serves them all (sets ROVER_WEB_ROBOTS)")
    parser.add_argument("--verbose", action="store_true",
                        help="print every HTTP request and the simulator's DEBUG lines (off: only what matters)")
    args, sim_args = parser.parse_known_args(argv)
    if args.robots:
        os.environ["ROVER_WEB_ROBOTS"] = args.robots
        sim_args = ["--robots", args.robots, *sim_args]
    if args.verbose:
        sim_args = ["--debug-logs", *sim_args]

    # Keep the demo's DDS traffic on this machine unless the operator chose otherwise.
    os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
    if args.domain_id is not None:
        os.environ["ROS_DOMAIN_ID"] = str(args.domain_id)
    os.environ.setdefault("ROS_DOMAIN_ID", "42")

    from rover_web import config as config_module
    from rover_web import create_app
    from rover_web.core.state import rover_of

    # Said before create_app: whether sign-in is required depends on where the GUI listens.
    try:
        host = args.host or config_module.load()["ROVER_WEB_HOST"] or "127.0.0.1"
    except config_module.ConfigError as exc:
        raise SystemExit(f"rover_web: {exc}") from None
    os.environ["ROVER_WEB_HOST"] = host
    # The simulator drives around Nathan Benderson Park: its fence is stored when the demo's
    # database has none, so the map shows one and leaving it raises the breach warning.
    os.environ.setdefault("ROVER_WEB_GEOFENCE_FILE", DEMO_GEOFENCE)
    app = create_app()
    config = app.config
    port = args.port or config["ROVER_WEB_PORT"]
    tls = (config["ROVER_WEB_TLS_CERT"], config["ROVER_WEB_TLS_KEY"]) if config["ROVER_WEB_TLS_CERT"] else None
    scheme = "https" if tls else "http"
    sim = subprocess.Popen([sys.executable, "-m", "rover_web.sim", *sim_args])
    print(f"rover_web: GUI on {scheme}://{'127.0.0.1' if host == '0.0.0.0' else host}:{port}/ "
          f"(ROS domain {os.environ['ROS_DOMAIN_ID']}); Ctrl-C stops the GUI and the simulator", flush=True)
    try:
        app.run(host=host, port=port, threaded=True, use_reloader=False, ssl_context=tls,
                request_handler=WSGIRequestHandler if args.verbose else QuietRequestHandler)
    except KeyboardInterrupt:
        pass
    finally:
        rover_of(app).shutdown()
        if sim.poll() is None:
            # Ctrl-C in a terminal reaches the simulator too; SIGTERM covers every other way we stop.
            sim.send_signal(signal.SIGTERM)
        try:
            sim.wait(10)
        except subprocess.TimeoutExpired:
            sim.kill()
    return 0


if __name__ == "__main__":
    sys.exit(main())
