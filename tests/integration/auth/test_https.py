"""HTTPS with a self-signed certificate: sign-in, SSE, the teleop socket, and TLS errors that stay local."""

import json
import socket
import ssl
import struct
import sys
import time

import pytest
import requests
import websocket

from rover_web.auth.tls import write_self_signed
from tests.conftest import free_port
from tests.support.auth import PASSWORD, add_users
from tests.support.waiting import wait_until


@pytest.fixture
def https_server(server_process, tmp_path):
    cert, key = write_self_signed(tmp_path / "tls", ["127.0.0.1", "localhost"])
    db_path = tmp_path / "https.sqlite3"
    tokens = add_users(db_path, "operator")
    port = free_port()
    server = server_process(port=port, scheme="https", ca=cert.parent / "ca.pem", env={
        "ROVER_WEB_PORT": str(port), "ROVER_WEB_AUTH": "required", "ROVER_WEB_DB_PATH": str(db_path),
        "ROVER_WEB_TLS_CERT": str(cert), "ROVER_WEB_TLS_KEY": str(key)},
        args=[sys.executable, "-m", "gunicorn", "-c", "gunicorn.conf.py", "rover_web:create_app()"]).start()
    server.token = tokens["operator"]
    server.db_path = db_path
    server.cert = cert.parent / "ca.pem"  # what a client trusts
    return server


def open_stream(server):
    """An SSE request over TLS; returns the TLS socket."""
    raw = socket.create_connection(("127.0.0.1", server.port))
    context = ssl.create_default_context(cafile=str(server.cert))
    tls = context.wrap_socket(raw, server_hostname="127.0.0.1")
    tls.sendall((f"GET /api/events?channels=status HTTP/1.1\r\nHost: 127.0.0.1:{server.port}\r\n"
                 f"Authorization: Bearer {server.token}\r\n\r\n").encode())
    head = tls.recv(4096)
    assert head.startswith(b"HTTP/1.1 200"), head[:200]
    return tls


def open_streams(server) -> int:
    status = requests.get(server.url + "/api/status", headers={"Authorization": f"Bearer {server.token}"},
                          verify=str(server.cert), timeout=5)
    return status.json()["streams"]["open"]


def test_a_stream_over_tls_ends_when_its_token_is_revoked_from_another_process(https_server):
    """The streamed-body hook under gunicorn and TLS, reached by the once-a-second re-check: the
    token is revoked in the database by this process, as `flask tokens revoke` would."""
    from rover_web.auth.accounts import Accounts
    from rover_web.storage.db import Database

    stream = open_stream(https_server)
    assert wait_until(lambda: open_streams(https_server) == 1, what="the stream counted")
    db = Database(https_server.db_path)
    try:
        accounts = Accounts(db)
        accounts.revoke_token(next(t["id"] for t in accounts.tokens() if t["user"] == "operator"))
    finally:
        db.close()
    deadline = time.monotonic() + 10  # a bound for a loaded machine; the server aims at about a second
    stream.settimeout(1)
    ended = False
    while not ended and time.monotonic() < deadline:  # status events keep coming while it lives
        try:
            ended = not stream.recv(65536)
        except (ssl.SSLError, ConnectionError):
            ended = True  # cut under the TLS layer: no close_notify
        except TimeoutError:
            pass
    stream.close()
    assert ended, "the revoked token's stream went on"


def test_sign_in_over_https_sets_a_secure_cookie(https_server):
    session = requests.Session()  # verify= on each call: REQUESTS_CA_BUNDLE would override Session.verify
    response = session.post(https_server.url + "/login", data={"username": "operator", "password": PASSWORD},
                            allow_redirects=False, timeout=5, verify=str(https_server.cert))
    assert response.status_code == 303
    cookie = response.headers["Set-Cookie"]
    assert "Secure" in cookie and "HttpOnly" in cookie and "SameSite=Strict" in cookie
    assert session.get(https_server.url + "/api/me", timeout=5, verify=str(https_server.cert)).json()["user"] == \
        "operator"


def test_sse_and_the_teleop_socket_work_and_a_cut_tls_connection_frees_its_stream(https_server):
    keeper = open_stream(https_server)
    cut = open_stream(https_server)
    assert wait_until(lambda: open_streams(https_server) == 2, what="two streams")
    # One browser's connection dies without a TLS goodbye: a TCP reset under the TLS layer.
    cut.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
    cut.close()
    assert wait_until(lambda: open_streams(https_server) == 1, timeout=10, what="the cut stream freed")
    keeper.settimeout(5)
    got = b""
    deadline = time.monotonic() + 5
    while got.count(b"event: status") < 2 and time.monotonic() < deadline:
        got += keeper.recv(65536)  # the other stream goes on
    assert got.count(b"event: status") >= 2
    keeper.close()

    ws = websocket.create_connection(f"wss://127.0.0.1:{https_server.port}/ws/teleop",
                                     header=[f"Authorization: Bearer {https_server.token}"],
                                     sslopt={"ca_certs": str(https_server.cert)})
    hello = json.loads(ws.recv())
    assert hello["type"] == "hello" and hello["name"] == "operator"
    ws.send(json.dumps({"linear": 0.2, "angular": 0.0}))
    state = requests.get(https_server.url + "/api/teleop", headers={"Authorization": f"Bearer {https_server.token}"},
                         verify=str(https_server.cert), timeout=5).json()
    assert state["holder"]["name"] == "operator"
    ws.close()
    assert wait_until(lambda: open_streams(https_server) == 0, timeout=10, what="every stream freed")
    assert "Traceback" not in https_server.log(), https_server.log()


def test_plain_http_to_the_https_port_is_refused_without_harm(https_server):
    with pytest.raises(requests.ConnectionError):
        requests.get(f"http://127.0.0.1:{https_server.port}/api/status", timeout=5)
    assert requests.get(https_server.url + "/login", verify=str(https_server.cert), timeout=5).status_code == 200


def test_hsts_is_sent_over_tls(https_server):
    page = requests.get(https_server.url + "/login", verify=str(https_server.cert), timeout=5)
    assert page.headers["Strict-Transport-Security"] == "max-age=31536000"

