"""RobotPrefix: /robots/<name>/... is served as /... for robot <name>, like a WSGI mount."""

import pytest

from rover_web.core.state import ROBOT_ENVIRON
from rover_web.fleet.prefix import APP_ROOT, RobotPrefix, app_root


def seen_by_app(path: str, script_name: str = "") -> dict:
    """The environ the wrapped app was called with, for a request to `path`."""
    seen = {}

    def app(environ, start_response):
        seen.update(environ)
        start_response("200 OK", [])
        return [b""]

    environ = {"PATH_INFO": path, "SCRIPT_NAME": script_name, "REQUEST_METHOD": "GET"}
    body = RobotPrefix(app, ["boat", "drone"])(environ, lambda status, headers: None)
    assert list(body) == [b""]
    return seen


@pytest.mark.parametrize("path, script_name, rest", [
    ("/robots/boat/api/teleop", "/robots/boat", "/api/teleop"),
    ("/robots/drone/ws/teleop", "/robots/drone", "/ws/teleop"),
    ("/robots/boat/", "/robots/boat", "/"),
    ("/robots/boat", "/robots/boat", "/"),
    ("/robots/boat/robots/drone/x", "/robots/boat", "/robots/drone/x"),  # mounted once, not again
])
def test_a_known_robot_s_prefix_moves_to_the_script_name(path, script_name, rest):
    environ = seen_by_app(path)
    assert (environ["SCRIPT_NAME"], environ["PATH_INFO"]) == (script_name, rest)
    assert environ[ROBOT_ENVIRON] == script_name.rsplit("/", 1)[1]
    assert app_root(environ) == ""


def test_behind_a_proxy_prefix_the_app_root_is_kept():
    environ = seen_by_app("/robots/drone/livemap", script_name="/gui")
    assert (environ["SCRIPT_NAME"], environ["PATH_INFO"]) == ("/gui/robots/drone", "/livemap")
    assert environ[APP_ROOT] == "/gui" and app_root(environ) == "/gui"


@pytest.mark.parametrize("path", ["/api/status", "/robots", "/robots/", "/robots/nope/api/status",
                                  "/robots/Boat/api/status", "/robots/boatx/api/status", "/robotsboat/api",
                                  "/api/robots/boat"])
def test_other_paths_pass_through_untouched(path):
    environ = seen_by_app(path, script_name="/gui")
    assert (environ["SCRIPT_NAME"], environ["PATH_INFO"]) == ("/gui", path)
    assert ROBOT_ENVIRON not in environ and APP_ROOT not in environ
    assert app_root(environ) == "/gui"
