"""Which role a request needs, and when sign-in is required."""

import pytest

from rover_web.auth.policy import is_loopback, required_role, role_allows, sign_in_required


@pytest.mark.parametrize("method,path,endpoint,role", [
    ("GET", "/login", "auth.login_form", None),
    ("POST", "/login", "auth.login", None),
    ("GET", "/static/js/core/api.js", "static", None),
    ("GET", "/", "pages.dashboard", "viewer"),
    ("GET", "/api/events", "sse.events", "viewer"),
    ("GET", "/stream", "camera.stream", "viewer"),
    ("POST", "/api/estop", "estop.estop_set", "viewer"),
    ("POST", "/logout", "auth.logout", "viewer"),
    ("POST", "/api/camera/viewers/x/ack", "camera.viewer_ack", "viewer"),
    ("GET", "/ws/teleop", "teleop_socket", "operator"),
    ("POST", "/api/teleop", "teleop.teleop_command", "operator"),
    ("POST", "/api/maps/x/goal", "livemap.post_goal", "operator"),
    ("DELETE", "/api/waypoints", "waypoints.clear", "operator"),
    ("POST", "/api/new/route/nobody/listed", "new.view", "operator"),
    ("GET", "/api/users", "auth.admin_list_users", "admin"),
    ("POST", "/api/tokens", "auth.admin_create_token", "admin"),
    ("GET", "/no/such/page", None, "viewer"),
])
def test_required_role(method, path, endpoint, role):
    assert required_role(method, path, endpoint) == role


def test_role_order():
    assert role_allows("admin", "operator") and role_allows("operator", "operator")
    assert not role_allows("viewer", "operator")


@pytest.mark.parametrize("host,loopback", [
    ("127.0.0.1", True), ("127.0.1.1", True), ("localhost", True), ("::1", True), ("[::1]", True),
    ("0.0.0.0", False), ("::", False), ("192.168.1.20", False), ("robot.local", False), ("unix:/run/rw.sock", False),
])
def test_is_loopback(host, loopback):
    assert is_loopback(host) is loopback


def test_sign_in_required_by_mode_and_address():
    assert not sign_in_required("auto", ["127.0.0.1"])
    assert sign_in_required("auto", ["0.0.0.0"])
    assert sign_in_required("auto", ["127.0.0.1", "10.0.0.5"])
    assert sign_in_required("auto", [])  # unknown: assume exposed
    assert sign_in_required("required", ["127.0.0.1"])
    assert not sign_in_required("off", ["0.0.0.0"])


def test_a_proxy_s_forwarding_headers_are_recognised_whatever_their_case():
    from rover_web.auth.policy import forwarded_header

    assert forwarded_header([("Host", "127.0.0.1"), ("x-forwarded-for", "10.0.0.9")]) == "x-forwarded-for"
    assert forwarded_header([("X-Forwarded-Proto", "https")]) == "X-Forwarded-Proto"
    assert forwarded_header([("Forwarded", "for=10.0.0.9")]) == "Forwarded"
    assert forwarded_header([("X-Real-IP", "10.0.0.9")]) == "X-Real-IP"
    assert forwarded_header([("Host", "127.0.0.1"), ("Accept", "*/*")]) is None


def test_a_host_other_than_loopback_is_exposed():
    from rover_web.auth.policy import exposed_host

    for loopback in ("127.0.0.1:5000", "localhost", "localhost:5000", "[::1]:5000", "::1", "127.0.0.2"):
        assert exposed_host(loopback) is None, loopback
    assert exposed_host("robot.example:443") == "robot.example"
    assert exposed_host("192.168.1.20") == "192.168.1.20"
