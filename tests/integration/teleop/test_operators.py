"""One operator drives at a time; everyone sees who does and what is commanded (SSE `teleop`)."""

import pytest

from tests.support.teleop_support import TeleopClient, drive_at, is_zero, subscribe_cmd_vel, twists, warm_up


@pytest.fixture
def rig(live_server, ros_peer):
    peer = ros_peer()
    subscribe_cmd_vel(peer)
    warm_up(peer, live_server.url)
    return live_server, peer


def test_second_operator_is_view_only_takes_over_and_gets_control_when_the_holder_leaves(rig, sse_client):
    server, peer = rig
    stream = sse_client(server.url + "/api/events?channels=teleop")
    alice = TeleopClient(server.url, name="alice")
    bob = TeleopClient(server.url, name="bob")

    drive_at(alice, [(0.5, 0.0), (0.4, 0.0)] * 4)
    alice_holds = stream.wait_for("teleop", lambda s: s["holder"] and s["holder"]["name"] == "alice")
    assert alice_holds["json"]["holder"]["id"] == alice.hello["session"]
    assert stream.wait_for("teleop", lambda s: s["linear_mps"] == 2.0)["json"]["operators"] == 2

    # Bob is view-only: his frames are refused and nothing he sends reaches /cmd_vel.
    bob.drive(-1.0, 0.0)
    refused = bob.wait_for(lambda m: m["type"] == "error")
    assert refused["error"] == "not_in_control" and refused["status"] == 409
    assert "alice" in refused["message"] and refused["holder"]["name"] == "alice"
    bob.send({"stop": True})  # his tab losing focus does not stop alice either
    drive_at(alice, [(0.5, 0.0), (0.4, 0.0)] * 4)
    assert all(lin > 0 for _, lin, _ in twists(peer))

    # Explicit takeover: the robot stops at the handover, alice is told and becomes view-only.
    peer.clear("/cmd_vel")
    alice.drive(0.5, 0.0)
    bob.send({"takeover": True})
    peer.wait_for("/cmd_vel", is_zero, timeout=2.0)
    told = alice.wait_for(lambda m: m["type"] == "state" and m["reason"] == "taken_over")
    assert told["in_control"] is False and told["holder"]["name"] == "bob"
    assert bob.wait_for(lambda m: m["type"] == "state" and m["in_control"])["holder"]["name"] == "bob"
    stream.wait_for("teleop", lambda s: s["holder"] and s["holder"]["name"] == "bob")
    alice.drive(0.9, 0.0)
    assert alice.wait_for(lambda m: m["type"] == "error")["error"] in ("not_in_control", "stale_epoch")
    peer.clear("/cmd_vel")
    bob.drive(-0.2, 0.1)
    peer.wait_for("/cmd_vel", lambda m: m["linear"]["x"] == -1.0, timeout=2.0)
    stream.wait_for("teleop", lambda s: s["linear_mps"] == -1.0 and s["source"] == "joystick")
    assert all(lin != 4.5 for _, lin, _ in twists(peer))

    # The holder's disconnect stops the robot and frees control; alice drives again.
    bob.close()
    peer.wait_for("/cmd_vel", is_zero, timeout=1.0)
    stream.wait_for("teleop", lambda s: s["holder"] is None and s["operators"] == 1)
    peer.clear("/cmd_vel")
    alice.drive(0.3, 0.0)
    peer.wait_for("/cmd_vel", lambda m: m["linear"]["x"] == 1.5, timeout=2.0)
    stream.wait_for("teleop", lambda s: s["holder"] and s["holder"]["name"] == "alice")
    alice.close()


def test_release_frees_control(rig):
    server, peer = rig
    alice = TeleopClient(server.url, name="alice")
    bob = TeleopClient(server.url, name="bob")
    alice.drive(0.5, 0.0)
    peer.wait_for("/cmd_vel", lambda m: m["linear"]["x"] == 2.5, timeout=2.0)
    alice.send({"release": True})
    peer.wait_for("/cmd_vel", is_zero, timeout=1.0)
    assert alice.wait_for(lambda m: m["type"] == "state" and m["reason"] == "released")["in_control"] is False
    peer.clear("/cmd_vel")
    bob.drive(0.1, 0.0)
    peer.wait_for("/cmd_vel", lambda m: m["linear"]["x"] == 0.5, timeout=2.0)
    assert server.rover.hub.latest("teleop") is not None
    for c in (alice, bob):
        c.close()
