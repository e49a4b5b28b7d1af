"""E-stop latch and REST drive commands, against a real rclpy subscriber in another process."""

import time

import pytest
import requests

from tests.support.teleop_support import TeleopClient, drive_at, is_zero, subscribe_cmd_vel, twists, warm_up


@pytest.fixture
def rig(live_server, ros_peer):
    peer = ros_peer()
    subscribe_cmd_vel(peer)
    warm_up(peer, live_server.url)
    return live_server, peer


def post(server, path, body, **kw):
    return requests.post(server.url + path, json=body, timeout=5, **kw)


def test_estop_while_driving_stops_at_once_refuses_motion_and_releases(rig, sse_client):
    server, peer = rig
    stream = sse_client(server.url + "/api/events?channels=teleop")
    alice = TeleopClient(server.url, name="alice")
    drive_at(alice, [(0.5, 0.0), (0.6, 0.0)] * 4)
    peer.wait_for("/cmd_vel", lambda m: m["linear"]["x"] == 2.5, timeout=2.0)

    # Engaged from another client (curl) while alice holds control and keeps her stick held.
    t0 = time.monotonic()
    response = post(server, "/api/estop", {"engaged": True, "by": "bob"})
    assert response.status_code == 200 and response.json()["engaged"] is True and response.json()["by"] == "bob"
    zero = peer.wait_for("/cmd_vel", is_zero, timeout=1.0)
    assert zero["t"] - t0 < 0.1, zero["t"] - t0
    stream.wait_for("teleop", lambda s: s["estop"]["engaged"] and s["linear_mps"] == 0.0)

    # Joystick and REST are refused with 409 and a clear message; nothing moves.
    alice.wait_for(lambda m: m["type"] == "state" and m["reason"] == "estop")
    alice.drive(0.5, 0.0)
    refused = alice.wait_for(lambda m: m["type"] == "error")
    assert refused["error"] == "estop_engaged" and refused["status"] == 409 and "e-stop" in refused["message"]
    rest = post(server, "/api/teleop", {"command": "forward", "speed": 0.5})
    assert rest.status_code == 409 and rest.json()["error"] == "estop_engaged"
    assert "release" in rest.json()["message"]
    # Reconnecting and reloading do not release it.
    alice.close()
    alice = TeleopClient(server.url, name="alice")
    assert alice.hello["estop"] is True
    alice.drive(0.5, 0.0)
    assert alice.wait_for(lambda m: m["type"] == "error")["error"] == "estop_engaged"
    page = requests.get(server.url + "/", timeout=5).text
    assert 'data-engaged="yes"' in page and "E-STOP ENGAGED" in page
    assert requests.get(server.url + "/api/estop", timeout=5).json()["engaged"] is True
    time.sleep(0.4)
    assert all(lin == 0.0 for t, lin, _ in twists(peer) if t >= zero["t"])
    # stop always works.
    assert post(server, "/api/teleop", {"command": "stop"}).status_code == 200

    # Released: the stick alice still holds does not drive; a neutral input re-arms, then it does.
    released = post(server, "/api/estop", {"engaged": False})
    assert released.status_code == 200 and released.json()["engaged"] is False
    stream.wait_for("teleop", lambda s: not s["estop"]["engaged"])
    notice = alice.wait_for(lambda m: m["type"] == "state" and m["reason"] == "estop_released")
    assert notice["armed"] is False
    peer.clear("/cmd_vel")
    alice.drive(0.4, 0.0)
    assert alice.wait_for(lambda m: m["type"] == "error" and m["error"] == "rearm_required")
    time.sleep(0.3)
    assert not [t for t in twists(peer) if t[1] != 0.0]
    alice.send({"stop": True})
    alice.drive(0.4, 0.0)
    peer.wait_for("/cmd_vel", lambda m: m["linear"]["x"] == 2.0, timeout=2.0)
    alice.close()


def test_estop_survives_a_server_restart(app_factory, tmp_path):
    db = str(tmp_path / "latch.sqlite3")
    first = app_factory(ROVER_WEB_DB_PATH=db)
    client = first.test_client()
    assert client.post("/api/estop", json={"engaged": True, "by": "alice"}).json["persisted"] is True
    first.extensions["rover_web"].shutdown()

    second = app_factory(ROVER_WEB_DB_PATH=db)
    client = second.test_client()
    state = client.get("/api/estop").json
    assert state["engaged"] is True and state["by"] == "alice"
    assert client.post("/api/teleop", json={"command": "forward"}).status_code == 409
    assert client.post("/api/estop", json={"engaged": False}).json["engaged"] is False
    second.extensions["rover_web"].shutdown()

    third = app_factory(ROVER_WEB_DB_PATH=db)
    assert third.test_client().get("/api/estop").json["engaged"] is False


@pytest.mark.parametrize("body", [
    {}, {"engaged": "yes"}, {"engaged": None}, {"engaged": 1}, {"engaged": False, "extra": 1},
    {"engaged": False, "by": 5},
])
def test_estop_bad_requests(client, body):
    response = client.post("/api/estop", json=body)
    assert response.status_code == 400 and response.json["error"]
    assert client.get("/api/estop").json["engaged"] is False


def test_rest_command_moves_then_stops_by_itself(rig, sse_client):
    server, peer = rig
    stream = sse_client(server.url + "/api/events?channels=teleop")
    t0 = time.monotonic()
    response = post(server, "/api/teleop", {"command": "forward", "speed": 0.5, "duration_s": 0.5})
    assert response.status_code == 200
    assert response.json() == {"command": "forward", "speed": 0.5, "duration_s": 0.5, "linear_mps": 2.5,
                               "angular_rps": 0.0}
    stream.wait_for("teleop", lambda s: s["source"] == "rest" and s["linear_mps"] == 2.5)
    zero = peer.wait_for("/cmd_vel", is_zero, timeout=2.0)
    moving = [t for t, lin, _ in twists(peer) if lin == 2.5]
    assert 0.45 <= zero["t"] - t0 <= 0.7, zero["t"] - t0
    assert 17 <= len(moving) <= 22  # repeated at 40 Hz for 0.5 s
    time.sleep(0.3)
    assert all(lin == 0.0 for t, lin, _ in twists(peer) if t >= zero["t"])
    stream.wait_for("teleop", lambda s: s["source"] is None and s["last_stop"]["reason"] == "duration_elapsed")

    # Turning and the default speed (0.2 of the maxima) and duration (0.5 s).
    peer.clear("/cmd_vel")
    assert post(server, "/api/teleop", {"command": "right"}).json()["angular_rps"] == -0.4
    peer.wait_for("/cmd_vel", lambda m: m["angular"]["z"] == -0.4, timeout=2.0)
    peer.wait_for("/cmd_vel", is_zero, timeout=2.0)


def test_rest_stop_always_wins(rig):
    server, peer = rig
    post(server, "/api/teleop", {"command": "back", "speed": 1, "duration_s": 5})
    peer.wait_for("/cmd_vel", lambda m: m["linear"]["x"] == -5.0, timeout=2.0)
    t0 = time.monotonic()
    # Even with junk around it, a stop is a stop.
    assert post(server, "/api/teleop", {"command": "stop", "speed": "fast"}).status_code == 200
    zero = peer.wait_for("/cmd_vel", is_zero, timeout=1.0)
    assert zero["t"] - t0 < 0.1
    time.sleep(0.3)
    assert all(lin == 0.0 for t, lin, _ in twists(peer) if t >= zero["t"])


def test_rest_is_refused_while_a_joystick_holds_control(rig):
    server, peer = rig
    alice = TeleopClient(server.url, name="alice")
    alice.drive(0.0, 0.0)
    alice.wait_for(lambda m: m["type"] == "state" and m["in_control"])
    response = post(server, "/api/teleop", {"command": "forward"})
    assert response.status_code == 409 and response.json()["error"] == "not_in_control"
    assert "alice" in response.json()["message"]
    alice.close()


BAD_REST = [
    ({"command": "fly"}, "unknown_command"),
    ({"command": "FORWARD"}, "unknown_command"),
    ({}, "missing_field"),
    ({"command": None}, "bad_type"),
    ({"command": 1}, "bad_type"),
    ({"command": "forward", "speed": None}, "bad_type"),
    ({"command": "forward", "speed": "0.5"}, "bad_type"),
    ({"command": "forward", "speed": 1.5}, "out_of_range"),
    ({"command": "forward", "speed": -0.1}, "out_of_range"),
    ({"command": "forward", "duration_s": 6}, "out_of_range"),
    ({"command": "forward", "duration_s": 0}, "out_of_range"),
    ({"command": "forward", "duration_s": None}, "bad_type"),
    ({"command": "forward", "turbo": True}, "unknown_field"),
]


def test_rest_bad_input_is_400_and_publishes_nothing(rig):
    # One server and one subscriber for every case: each is refused by name, and none publishes.
    server, peer = rig
    for body, code in BAD_REST:
        response = post(server, "/api/teleop", body)
        assert response.status_code == 400, (body, response.text)
        assert response.json()["error"] == code and response.json()["message"], body
    time.sleep(0.3)
    assert twists(peer) == []


@pytest.mark.parametrize("raw", ['{"command": "forward", "speed": NaN}', '{"command": "forward", "speed": Infinity}',
                                 '{"command": "forward", "speed": 1e400}', '{"command": "forward"', '[1]',
                                 '{"command": "forward", "speed": 1' + "0" * 400 + '}'])  # float() of it overflows
def test_rest_non_finite_and_broken_json_is_400(client, raw):
    response = client.post("/api/teleop", data=raw, content_type="application/json")
    assert response.status_code == 400 and response.json["error"]
    assert client.get("/api/teleop").json["source"] is None


def test_default_rest_duration_may_not_exceed_the_maximum(app_factory):
    from rover_web.config import ConfigError

    with pytest.raises(ConfigError, match="TELEOP_REST_DEFAULT_DURATION_S"):
        app_factory(ROVER_WEB_TELEOP_REST_DEFAULT_DURATION_S=6.0, ROVER_WEB_TELEOP_REST_MAX_DURATION_S=5.0)
