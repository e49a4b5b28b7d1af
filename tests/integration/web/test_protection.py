"""Protection every route has from the start: Host, Origin, content type, body size, JSON errors."""

import socket

import pytest
import requests


def raw_request(url: str, lines: list[str]) -> tuple[int, bytes]:
    host, port = url.removeprefix("http://").split(":")
    with socket.create_connection((host, int(port)), timeout=5) as s:
        s.sendall(("\r\n".join(lines) + "\r\n\r\n").encode())
        data = b""
        while True:
            if b"\r\n\r\n" in data:
                head, body = data.split(b"\r\n\r\n", 1)
                length = [int(line.split(b":")[1]) for line in head.split(b"\r\n")
                          if line.lower().startswith(b"content-length:")]
                if length and len(body) >= length[0]:
                    break
            chunk = s.recv(4096)
            if not chunk:
                break
            data += chunk
    return int(data.split(b" ", 2)[1]), data


def test_foreign_origin_on_a_state_changing_request_is_403(live_server):
    r = requests.post(live_server.url + "/api/status", json={}, headers={"Origin": "http://evil.example"}, timeout=5)
    assert r.status_code == 403
    assert r.json()["error"] == "foreign_origin"


def test_same_origin_and_no_origin_pass_the_guard(live_server):
    # /api/status has no POST: reaching the router (405) means the guard let it through.
    for headers in ({"Origin": live_server.url}, {}):
        r = requests.post(live_server.url + "/api/status", json={}, headers=headers, timeout=5)
        assert r.status_code == 405, r.text
        assert r.json()["error"] == "method_not_allowed"


def test_allowed_origin_setting(live_server_factory):
    server = live_server_factory(ROVER_WEB_ALLOWED_ORIGINS=["http://tablet.local:8080"])
    r = requests.post(server.url + "/api/status", json={}, headers={"Origin": "http://tablet.local:8080"}, timeout=5)
    assert r.status_code == 405


def test_foreign_origin_websocket_handshake_is_403(live_server):
    status, data = raw_request(live_server.url, [
        "GET /ws/teleop HTTP/1.1", f"Host: 127.0.0.1:{live_server.port}", "Upgrade: websocket",
        "Connection: Upgrade", "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==", "Sec-WebSocket-Version: 13",
        "Origin: http://evil.example"])
    assert status == 403
    assert b"foreign_origin" in data


@pytest.mark.parametrize("body, content_type", [
    ("a=1&b=2", "application/x-www-form-urlencoded"),
    ("hello", "text/plain"),
    ('{"a": 1}', "text/plain"),
    ("--x\r\n", "multipart/form-data; boundary=x"),
])
def test_non_json_bodies_are_415(live_server, body, content_type):
    r = requests.post(live_server.url + "/api/status", data=body, headers={"Content-Type": content_type}, timeout=5)
    assert r.status_code == 415
    assert r.json()["error"] == "unsupported_media_type"


def test_oversized_body_is_413(live_server_factory):
    server = live_server_factory(ROVER_WEB_MAX_BODY_BYTES=2048)
    r = requests.post(server.url + "/api/status", data=b'{"x": "' + b"a" * 5000 + b'"}',
                      headers={"Content-Type": "application/json"}, timeout=5)
    assert r.status_code == 413
    assert r.json()["error"] == "request_entity_too_large"
    assert "2048" in r.json()["message"]


@pytest.mark.parametrize("host", ["evil.example", "evil.example:5000", "127.0.0.1.nip.io", "rebind.attacker.test:80"])
def test_foreign_host_is_400(live_server, host):
    status, data = raw_request(live_server.url, ["GET /api/status HTTP/1.1", f"Host: {host}", "Connection: close"])
    assert status == 400
    assert b"untrusted_host" in data


@pytest.mark.parametrize("host", ["localhost:5000", "127.0.0.1", "[::1]:5000"])
def test_local_hosts_are_trusted(live_server, host):
    status, _ = raw_request(live_server.url, ["GET /api/status HTTP/1.1", f"Host: {host}", "Connection: close"])
    assert status == 200


def test_trusted_host_wildcard(live_server_factory):
    # Sign-in off: under auto, a request by a name other than loopback must sign in (docs/security.md).
    server = live_server_factory(ROVER_WEB_TRUSTED_HOSTS=[".robots.example", "10.1.2.3"], ROVER_WEB_AUTH="off")
    assert raw_request(server.url, ["GET /api/status HTTP/1.1", "Host: boat.robots.example:5000"])[0] == 200
    assert raw_request(server.url, ["GET /api/status HTTP/1.1", "Host: 10.1.2.3"])[0] == 200
    assert raw_request(server.url, ["GET /api/status HTTP/1.1", "Host: 127.0.0.1"])[0] == 400


def test_api_errors_are_json_and_pages_are_html(live_server):
    r = requests.get(live_server.url + "/api/nothing-here", timeout=5)
    assert r.status_code == 404 and r.json()["error"] == "not_found"
    r = requests.get(live_server.url + "/no-such-page", headers={"Accept": "text/html"}, timeout=5)
    assert r.status_code == 404 and r.headers["Content-Type"].startswith("text/html")
