"""Behind a reverse proxy (ROVER_WEB_PROXY_HOPS): each client keeps its own address for the
per-address limits, and without the setting a client cannot choose its address (issue 27).

The proxy is played by the test: every request reaches a live server from 127.0.0.1, as from
nginx on the robot's computer, with the X-Forwarded-For value nginx would append."""

import requests

from tests.support.auth import PASSWORD, add_users

FREE_FAILURES = 10  # rover_web/auth/throttle.py FREE_FAILURES_PER_ADDRESS


def via_proxy(client: str, **headers) -> dict:
    return {"X-Forwarded-For": client, **headers}


def sign_in(server, name, password, headers):
    return requests.post(server.url + "/login", json={"username": name, "password": password},
                         headers=headers, timeout=30)


def fail_until_throttled(server, headers_for) -> requests.Response:
    """Wrong passwords for different names (no name reaches its own limit) until the address waits."""
    for i in range(FREE_FAILURES):
        answer = sign_in(server, f"nobody{i}", "wrong password", headers_for(i))
        assert answer.status_code == 401, answer.text
    return sign_in(server, "operator", PASSWORD, headers_for(FREE_FAILURES))


def proxied_server(live_server_factory, tmp_path, **settings):
    db_path = tmp_path / "proxied.sqlite3"
    tokens = add_users(db_path, "viewer", "operator")
    server = live_server_factory(ROVER_WEB_AUTH="required", ROVER_WEB_DB_PATH=str(db_path),
                                 ROVER_WEB_SIGNIN_ATTEMPTS_PER_MIN=100, **settings)
    server.tokens = tokens
    return server


def test_two_clients_behind_the_proxy_have_separate_sign_in_back_off(live_server_factory, tmp_path):
    server = proxied_server(live_server_factory, tmp_path, ROVER_WEB_PROXY_HOPS=1)
    # A client may write its own X-Forwarded-For; the proxy appends the address it saw, and only
    # that last value is believed.
    waiting = fail_until_throttled(server, lambda i: via_proxy(f"10.0.0.{i + 50}, 10.0.0.1"))
    assert waiting.status_code == 429 and "from this address" in waiting.json()["message"]
    other = sign_in(server, "operator", PASSWORD, via_proxy("10.0.0.2"))
    assert other.status_code == 200, other.text
    # The guesser still waits, whatever it writes in front of the proxy's value.
    assert sign_in(server, "viewer", PASSWORD, via_proxy("10.0.0.2, 10.0.0.1")).status_code == 429


def test_without_the_setting_a_forwarded_address_is_not_believed(live_server_factory, tmp_path):
    server = proxied_server(live_server_factory, tmp_path)
    waiting = fail_until_throttled(server, lambda i: via_proxy(f"10.0.0.{i + 50}"))
    assert waiting.status_code == 429  # every request came from 127.0.0.1, whatever the header said


def test_the_sign_in_page_e_stop_limit_is_per_client_behind_the_proxy(live_server_factory, tmp_path):
    server = proxied_server(live_server_factory, tmp_path, ROVER_WEB_PROXY_HOPS=1)
    press = lambda client: requests.post(server.url + "/login/estop", json={}, headers=via_proxy(client),  # noqa: E731
                                         timeout=10)
    assert [press("10.0.0.1").status_code for _ in range(7)] == [200] * 6 + [429]
    assert press("10.0.0.2").status_code == 200
    operator = {"Authorization": f"Bearer {server.tokens['operator']}"}
    state = requests.get(server.url + "/api/estop", headers=operator, timeout=10).json()
    assert state["by"] == "sign-in page (10.0.0.1)"  # the client's address, not the proxy's


def test_stream_shares_with_sign_in_off_are_per_client_behind_the_proxy(live_server_factory):
    server = live_server_factory(ROVER_WEB_AUTH="off", ROVER_WEB_PROXY_HOPS=1, ROVER_WEB_MAX_STREAMS_PER_CLIENT=1)
    url = server.url + "/api/events?channels=status"
    opened = []
    try:
        opened.append(requests.get(url, headers=via_proxy("10.0.0.1"), stream=True, timeout=10))
        assert opened[-1].status_code == 200
        opened.append(requests.get(url, headers=via_proxy("10.0.0.1"), stream=True, timeout=10))
        assert opened[-1].status_code == 503 and opened[-1].json()["error"] == "too_many_streams"
        opened.append(requests.get(url, headers=via_proxy("10.0.0.2"), stream=True, timeout=10))
        assert opened[-1].status_code == 200
    finally:
        for response in opened:
            response.close()


def test_under_auto_a_proxied_request_still_must_sign_in_with_the_setting_on(live_server_factory):
    """ProxyFix rewrites REMOTE_ADDR (here to a loopback address the client chose) and Host, but
    the forwarding headers stay, and they are what makes a request "exposed" under auto."""
    server = live_server_factory(ROVER_WEB_PROXY_HOPS=1)  # auto, listening on loopback, no user
    assert requests.get(server.url + "/api/status", timeout=10).status_code == 200  # this machine
    for headers in (via_proxy("127.0.0.1"), via_proxy("127.0.0.1", **{"X-Forwarded-Host": "localhost"}),
                    {"X-Forwarded-Proto": "http"}):
        refused = requests.get(server.url + "/api/status", headers=headers, timeout=10)
        assert refused.status_code == 403 and refused.json()["error"] == "sign_in_needed", headers
