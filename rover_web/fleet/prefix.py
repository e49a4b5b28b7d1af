"""/robots/<name>/... serves every route for robot <name>, as WSGI mounting does.

The prefix moves from PATH_INFO to SCRIPT_NAME, so the routes stay as they are, `url_for` and
`request.script_root` give the robot's own URLs, and pages reach their robot's API by prefixing
their paths with the script root. The robot's name is left in the environ for current_rover().
"""

from __future__ import annotations

from rover_web.core.state import ROBOT_ENVIRON

PREFIX = "/robots/"
APP_ROOT = "rover_web.app_root"  # the SCRIPT_NAME before the robot's prefix: where /robots is


def app_root(environ) -> str:
    return environ.get(APP_ROOT, environ.get("SCRIPT_NAME", ""))


class RobotPrefix:
    def __init__(self, wsgi_app, names: list[str]):
        self.wsgi_app = wsgi_app
        self.names = frozenset(names)

    def __call__(self, environ, start_response):
        path = environ.get("PATH_INFO", "")
        if path.startswith(PREFIX):
            name, slash, rest = path[len(PREFIX):].partition("/")
            if name in self.names:
                environ[APP_ROOT] = environ.get("SCRIPT_NAME", "")
                environ["SCRIPT_NAME"] = f"{environ.get('SCRIPT_NAME', '')}{PREFIX}{name}"
                environ["PATH_INFO"] = f"/{rest}" if slash else "/"
                environ[ROBOT_ENVIRON] = name
        return self.wsgi_app(environ, start_response)
