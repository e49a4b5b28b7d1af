"""Who may do what, and when sign-in is required. Pure Python: decided here, enforced by routes.py.

Roles, each including the ones below it:
  viewer    every GET (pages, APIs, SSE, camera, topic echo) and ENGAGING the e-stop: anyone who
            sees danger must be able to stop the robot.
  operator  also everything that moves or commands the robot: driving (the teleop WebSocket and
            REST), taking over, releasing the e-stop, LiveMap goals and initial poses, Nav2's goals,
            routes and cancels (POST /api/nav2/...: the default below), waypoint writes,
            the mission send, panel unlock and commands, canceling a goal sent from /ros.
  admin     also users and API tokens (refused to everyone while sign-in is off: the CLI remains),
            and /ros's writes: other nodes' parameters, service calls, action goals (root over the
            ROS graph; docs/ros_admin.md#who-may-write).
The default is closed: a state-changing route nobody listed needs the operator role.
GET /metrics (Prometheus, a viewer's token as its bearer credentials) and the hub's
GET /api/robots/<name>/history are reads like any other: the viewer role.
"""

from __future__ import annotations

import ipaddress
from collections.abc import Iterable

from .accounts import ROLES

MODES = ("auto", "required", "off")
READ_METHODS = frozenset({"GET", "HEAD", "OPTIONS"})
# Reachable without signing in: the sign-in form itself and the files it needs.
# estop.login_estop: the sign-in page's engage-only e-stop (docs/security.md#the-sign-in-pages-e-stop).
PUBLIC_ENDPOINTS = frozenset({"auth.login_form", "auth.login", "estop.login_estop", "static"})
# Any signed-in user, whatever the method.
# estop_set: the view checks release; estop_all only engages: whoever may watch may stop every robot.
# The WHEP offer and its DELETE only watch the camera; the teleop data channel in a WHEP session is
# refused unless its user was an operator when the session was made (camera/webrtc/service.py).
# camera.viewer_ack: a page watching MJPEG says what it has received (camera/acks.py); only watching.
# hub.estop_all: the fleet hub's stop-all (rover_web/hub) only engages, as estop_all does on a robot.
# layouts.choose_layout: which layout the caller's own dashboard shows (a viewer picks; only operators
# and admins change layouts). prefs.set_preferences: the caller's own theme and language.
ANY_USER_ENDPOINTS = frozenset({"auth.logout", "auth.revoke_my_sessions", "estop.estop_set", "estop.estop_all",
                                "estop.estop_form",
                                "hub.estop_all", "layouts.choose_layout", "prefs.set_preferences",
                                "camera_webrtc.whep_offer", "camera_webrtc.whep_end", "camera.viewer_ack"})
ADMIN_ENDPOINT_PREFIX = "auth.admin_"
# recording.delete_recording: a recording is the record of what happened; only an admin destroys it.
ADMIN_ENDPOINTS = frozenset({"ros_admin.api_set_parameter", "ros_admin.api_call_service", "ros_admin.api_send_goal",
                             "recording.delete_recording"})


def required_role(method: str, path: str, endpoint: str | None) -> str | None:
    """The least role a request needs; None when it needs no sign-in at all."""
    if endpoint in PUBLIC_ENDPOINTS:
        return None
    if endpoint and (endpoint.startswith(ADMIN_ENDPOINT_PREFIX) or endpoint in ADMIN_ENDPOINTS):
        return "admin"
    if path.startswith("/ws/"):
        return "operator"  # the teleop socket is how an operator drives
    if endpoint in ANY_USER_ENDPOINTS or method in READ_METHODS:
        return "viewer"
    return "operator"


def role_allows(role: str, needed: str) -> bool:
    return ROLES.index(role) >= ROLES.index(needed)


def is_loopback(host: str) -> bool:
    host = host.strip().strip("[]")
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False  # a name, 0.0.0.0, :: or a unix socket: assume others can reach it


def is_admin_endpoint(endpoint: str | None) -> bool:
    return bool(endpoint and endpoint.startswith(ADMIN_ENDPOINT_PREFIX))


# Headers a reverse proxy adds (RFC 7239's Forwarded, the de-facto X-Forwarded-*, nginx's X-Real-IP):
# a request that carries one did not come from a browser on this machine, whatever address it came from.
FORWARDING_HEADERS = ("forwarded", "x-real-ip")
FORWARDING_PREFIX = "x-forwarded-"


def forwarded_header(headers: Iterable[tuple[str, str]]) -> str | None:
    """The name of the first forwarding header among `headers`, or None."""
    for name, _value in headers:
        lowered = name.lower()
        if lowered in FORWARDING_HEADERS or lowered.startswith(FORWARDING_PREFIX):
            return name
    return None


def exposed_host(host: str) -> str | None:
    """The Host header's name when it is not loopback (a name others use to reach this server)."""
    if host.startswith("["):
        name = host[1:host.find("]")] if "]" in host else host
    else:
        name = host.rsplit(":", 1)[0] if host.count(":") == 1 else host
    return None if is_loopback(name.rstrip(".")) else name


def sign_in_required(mode: str, listen_hosts: Iterable[str]) -> bool:
    """auto: required unless every address the server listens on is loopback."""
    if mode == "required":
        return True
    if mode == "off":
        return False
    hosts = [h for h in listen_hosts if h]
    return not hosts or not all(is_loopback(h) for h in hosts)
