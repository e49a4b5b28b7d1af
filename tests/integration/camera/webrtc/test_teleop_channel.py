"""Teleop over the WHEP session's `teleop` data channel, against a real rclpy subscriber in another
process. Each scenario runs over the data channel and over WS /ws/teleop with the same test body:
the guarantees are the same because the rules are the same code (handle_frame, TeleopController)."""

import time

import pytest
import requests

from tests.support.teleop_support import TeleopClient, drive_at, is_zero, subscribe_cmd_vel, twists, warm_up
from tests.support.waiting import wait_until
from tests.support.whep import ChannelTeleop, WhepClient

pytestmark = pytest.mark.ros
IMAGE = "msg_type=sensor_msgs/msg/Image"


@pytest.fixture
def rig(webrtc_server, ros_peer, camera):
    server = webrtc_server()
    camera("/cam", width=160, height=120, hz=15)
    peer = ros_peer()
    subscribe_cmd_vel(peer)
    warm_up(peer, server.url)
    return server, peer


@pytest.fixture
def stick():
    """make(server, transport): a teleop client over "datachannel" or "websocket", closed after."""
    made = []

    def make(server, transport, headers=None):
        if transport == "websocket":
            client = TeleopClient(server.url)
        else:
            client = ChannelTeleop(WhepClient(server.url, f"topic=/cam&{IMAGE}", teleop=True, headers=headers))
        made.append(client)
        return client

    yield make
    for client in made:
        client.close()


TRANSPORTS = ["datachannel", "websocket"]


@pytest.mark.parametrize("transport", TRANSPORTS)
def test_drives_cmd_vel_and_stops_on_deadman(rig, stick, transport):
    server, peer = rig
    client = stick(server, transport)
    assert client.hello["type"] == "hello" and client.hello["deadman_s"] == 0.3
    if transport == "datachannel":
        assert client.hello["transport"] == "datachannel"
    t_last = drive_at(client, [(0.5, 0.1), (0.6, -0.1)] * 10)[-1]
    peer.wait_for("/cmd_vel", lambda m: m["linear"]["x"] == pytest.approx(3.0), timeout=5.0)
    assert (pytest.approx(2.5), pytest.approx(0.2)) in [(lin, ang) for _, lin, ang in twists(peer)]
    # The operator's input stops with the channel still open: the deadman zeroes the robot. (On a
    # loaded machine a gap in the frames may already have stopped it once mid-stream: the stop
    # that counts is the one after the last frame.)
    state = client.wait_for(lambda m: m["type"] == "state" and m["reason"] == "deadman" and m["t"] > t_last)
    assert state["epoch"] >= 1 and state["in_control"] is True
    wait_until(lambda: [t for t, lin, ang in twists(peer) if lin == ang == 0.0 and t > t_last], 5,
               "a zero after the last frame")
    zeros = [t for t, lin, ang in twists(peer) if lin == ang == 0.0 and t > t_last]
    time.sleep(0.6)
    assert all(lin == 0.0 and ang == 0.0 for t, lin, ang in twists(peer) if t >= zeros[0])
    # A frame of the old epoch (sent before the client heard of the stop) never moves the robot.
    client.drive(0.5, 0.0, epoch=0)
    assert client.wait_for(lambda m: m["type"] == "error")["error"] == "stale_epoch"
    client.drive(0.5, 0.0)  # the new epoch: a live operator again
    peer.wait_for("/cmd_vel", lambda m: m["linear"]["x"] == pytest.approx(2.5), timeout=5.0)
    client.send({"stop": True})
    peer.wait_for("/cmd_vel", is_zero, timeout=5.0)


@pytest.mark.parametrize("transport", TRANSPORTS)
def test_estop_frame_stops_refuses_and_needs_rearm_after_release(rig, stick, transport):
    server, peer = rig
    client = stick(server, transport)
    drive_at(client, [(0.5, 0.0), (0.6, 0.0)] * 4)
    peer.wait_for("/cmd_vel", lambda m: m["linear"]["x"] == pytest.approx(3.0), timeout=5.0)
    peer.clear("/cmd_vel")
    client.send({"estop": True})
    zero = peer.wait_for("/cmd_vel", is_zero, timeout=5.0)
    client.wait_for(lambda m: m["type"] == "state" and m["reason"] == "estop" and m["estop"] is True)
    assert requests.get(server.url + "/api/estop", timeout=5).json()["engaged"] is True
    client.drive(0.5, 0.0)
    refused = client.wait_for(lambda m: m["type"] == "error")
    assert refused["error"] == "estop_engaged" and refused["status"] == 409
    time.sleep(0.4)
    assert all(lin == 0.0 for t, lin, _ in twists(peer) if t >= zero["t"])

    released = requests.post(server.url + "/api/estop", json={"engaged": False}, timeout=5)
    assert released.status_code == 200
    client.wait_for(lambda m: m["type"] == "state" and m["reason"] == "estop_released")
    client.drive(0.5, 0.0)  # a stick held through the release does not drive
    assert client.wait_for(lambda m: m["type"] == "error" and m["error"] != "estop_engaged")["error"] \
        == "rearm_required"
    client.drive(0.0, 0.0)  # neutral re-arms
    client.drive(0.4, 0.0)
    peer.wait_for("/cmd_vel", lambda m: m["linear"]["x"] == pytest.approx(2.0), timeout=5.0)
    client.send({"stop": True})


@pytest.mark.parametrize("transport", TRANSPORTS)
def test_a_drive_frame_delivered_after_the_stop_it_preceded_moves_nothing(rig, stick, transport):
    """The channel is unordered: a drive frame the page sent just before its stop can arrive after
    the stop. The stop's seq fences it off; input sent after the stop drives again."""
    server, peer = rig
    client = stick(server, transport)
    for seq in (1, 2, 3):
        client.drive(0.2, 0.0, seq=seq)
    peer.wait_for("/cmd_vel", lambda m: m["linear"]["x"] == pytest.approx(1.0), timeout=5.0)
    client.send({"stop": True, "seq": 5})
    zero = peer.wait_for("/cmd_vel", is_zero, timeout=5.0)
    client.drive(0.2, 0.0, seq=4)  # delivered late: sent before the stop
    assert client.wait_for(lambda m: m["type"] == "error")["error"] == "stale_seq"
    time.sleep(0.5)
    assert all(lin == 0.0 and ang == 0.0 for t, lin, ang in twists(peer) if t >= zero["t"])
    assert not requests.get(server.url + "/api/teleop", timeout=5).json()["moving"]
    client.drive(0.3, 0.0, seq=6)
    peer.wait_for("/cmd_vel", lambda m: m["linear"]["x"] == pytest.approx(1.5), timeout=5.0)
    client.send({"stop": True, "seq": 7})
    peer.wait_for("/cmd_vel", is_zero, timeout=5.0)


@pytest.mark.parametrize("transport", TRANSPORTS)
def test_the_link_is_measured_and_reported_every_half_second(rig, stick, transport):
    """The Drive card's link figures and its too-poor banner come from these `state` frames."""
    server, peer = rig
    client = stick(server, transport)
    drive_at(client, [(0.1, 0.0)] * 10)
    client.send({"stop": True})
    reports = []

    def measured(m):
        if m["type"] == "state" and m["reason"] == "link":
            reports.append(m)
        return len(reports) >= 3 and reports[-1]["link"]["rtt_ms"] is not None

    client.wait_for(measured, timeout=15)
    link = reports[-1]["link"]
    assert link["quality"] in ("ok", "poor", "too_poor") and link["rtt_ms"] >= 0.0
    assert {"jitter_ms", "stalls", "lost", "out_of_order"} <= set(link)


@pytest.mark.parametrize("how", ["delete", "peer_gone"])
def test_closing_the_session_mid_drive_stops_at_once_and_frees_control(rig, stick, how):
    server, peer = rig
    client = stick(server, "datachannel")
    drive_at(client, [(0.5, 0.1), (0.6, 0.1)] * 10)
    peer.wait_for("/cmd_vel", lambda m: m["linear"]["x"] == pytest.approx(3.0), timeout=5.0)
    assert server.rover.hub.latest("teleop")["holder"] is not None
    t_closed = time.monotonic()
    if how == "delete":
        assert client.client.delete().status_code == 204
    else:
        client.client.close()  # the browser's side goes away: its channel closes
    zero = peer.wait_for("/cmd_vel", is_zero, timeout=5.0)
    assert zero["t"] >= t_closed
    wait_until(lambda: server.rover.hub.latest("teleop")["holder"] is None, 5, "control freed")
    time.sleep(0.5)
    assert all(lin == 0.0 and ang == 0.0 for t, lin, ang in twists(peer) if t >= zero["t"])


def test_one_holder_across_transports(rig, stick):
    server, peer = rig
    socket_client = stick(server, "websocket")
    channel_client = stick(server, "datachannel")
    socket_client.drive(0.5, 0.0)
    peer.wait_for("/cmd_vel", lambda m: m["linear"]["x"] == pytest.approx(2.5), timeout=5.0)
    channel_client.drive(0.2, 0.0)
    refused = channel_client.wait_for(lambda m: m["type"] == "error")
    assert refused["error"] == "not_in_control"
    channel_client.send({"takeover": True})
    channel_client.wait_for(lambda m: m["type"] == "state" and m["reason"] == "in_control")
    socket_client.wait_for(lambda m: m["type"] == "state" and m["reason"] == "taken_over")
    channel_client.drive(0.2, 0.0)
    peer.wait_for("/cmd_vel", lambda m: m["linear"]["x"] == pytest.approx(1.0), timeout=5.0)
    channel_client.send({"stop": True})
    peer.wait_for("/cmd_vel", is_zero, timeout=5.0)


def test_bad_frames_on_the_channel_get_error_frames_binary_closes_it(rig, stick):
    server, peer = rig
    client = stick(server, "datachannel")
    client.drive(0.5, 0.0)
    peer.wait_for("/cmd_vel", lambda m: m["linear"]["x"] == pytest.approx(2.5), timeout=5.0)
    client.send('{"linear": NaN, "angular": 0}')
    assert client.wait_for(lambda m: m["type"] == "error")["error"] == "non_finite"
    peer.wait_for("/cmd_vel", is_zero, timeout=5.0)
    client.send("x" * 5000)
    assert client.wait_for(lambda m: m["type"] == "error" and m["error"] != "non_finite",
                           timeout=10)["error"] == "frame_too_large"
    assert client.closed.wait(10), "the server closed the channel"


@pytest.mark.parametrize("role, allowed", [("viewer", False), ("operator", True)])
def test_the_teleop_channel_needs_the_operator_role(signed_server, camera, stick, role, allowed):
    camera("/cam", width=160, height=120, hz=15)
    client = stick(signed_server, "datachannel", headers={"Authorization": f"Bearer {signed_server.tokens[role]}"})
    if allowed:
        assert client.hello["type"] == "hello" and client.hello["name"] == "operator"
        return
    assert client.hello["type"] == "error" and client.hello["error"] == "forbidden"
    assert "operator role" in client.hello["message"]
    assert client.closed.wait(10)
    wait_until(lambda: len(client.client.frames) > 3, 20, "a viewer still gets the video")


def test_under_auto_a_proxied_viewer_gets_no_teleop_channel(webrtc_server, camera, stick, tmp_path):
    """Sign-in off on loopback under `auto` is a rule for requests made on this machine: a viewer
    whose offer came through a proxy signed in, and its session must not drive."""
    from tests.support.auth import add_users

    db_path = tmp_path / "auto.sqlite3"
    tokens = add_users(db_path)
    server = webrtc_server(ROVER_WEB_AUTH="auto", ROVER_WEB_DB_PATH=str(db_path))
    camera("/cam", width=160, height=120, hz=15)
    client = stick(server, "datachannel", headers={"Authorization": f"Bearer {tokens['viewer']}",
                                                   "X-Forwarded-For": "203.0.113.7"})
    assert client.hello["type"] == "error" and client.hello["error"] == "forbidden"


def test_a_revoked_token_ends_the_peer_connection_and_stops_the_robot(signed_server, ros_peer, camera):
    """Issue 27: a revocation reaches the WebRTC session made with the token, and its teleop channel
    stops the robot first, as it does for the teleop WebSocket."""
    server = signed_server
    camera("/cam", width=160, height=120, hz=15)
    operator = {"Authorization": f"Bearer {server.tokens['operator']}"}
    admin = {"Authorization": f"Bearer {server.tokens['admin']}"}
    peer = ros_peer()
    subscribe_cmd_vel(peer)
    warm_up(peer, server.url, headers=operator)
    viewer = WhepClient(server.url, f"topic=/cam&{IMAGE}",
                        headers={"Authorization": f"Bearer {server.tokens['viewer']}"})
    client = ChannelTeleop(WhepClient(server.url, f"topic=/cam&{IMAGE}", teleop=True, headers=operator))
    try:
        wait_until(lambda: len(viewer.frames) >= 3, 20, "the viewer's frames")
        peer.clear("/cmd_vel")
        drive_at(client, [(0.5, 0.0)] * 5)
        peer.wait_for("/cmd_vel", lambda m: m["linear"]["x"] > 0, timeout=10)
        tokens = requests.get(server.url + "/api/tokens", headers=admin, timeout=5).json()["tokens"]
        token = next(t["id"] for t in tokens if t["user"] == "operator")
        assert requests.delete(f"{server.url}/api/tokens/{token}", headers=admin, timeout=5).ok
        wait_until(lambda: client.client.connection_state in ("closed", "failed"), 15, "the connection ended")
        peer.wait_for("/cmd_vel", is_zero, timeout=5)
        state = requests.get(server.url + "/api/teleop", headers=admin, timeout=5).json()
        assert not state["moving"] and state["holder"] is None, state
        # Only that credential's session ended: the viewer still gets frames.
        seen = len(viewer.frames)
        wait_until(lambda: len(viewer.frames) > seen + 5, 10, "the viewer still receives frames")
    finally:
        client.close()
        viewer.close()
