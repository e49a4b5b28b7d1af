"""Drive frames with "source": "gamepad" over the real socket: a separate rclpy subscriber sees them,
the `teleop` channel and the log name the source, and the server's rules apply as to the joystick.
Its waits are generous (3 s): it checks which frames drive, not how fast a stop lands, which the
e-stop and deadman tests bound."""

import logging

import pytest

from rover_web.estop import EStopService
from tests.support.teleop_support import TeleopClient, is_zero, subscribe_cmd_vel, twists, warm_up


@pytest.fixture
def rig(live_server, ros_peer):
    peer = ros_peer()
    subscribe_cmd_vel(peer)
    warm_up(peer, live_server.url)
    return live_server, peer


def test_gamepad_frames_drive_are_recorded_and_obey_the_estop(rig, sse_client, caplog):
    server, peer = rig
    stream = sse_client(server.url + "/api/events?channels=teleop")
    pad = TeleopClient(server.url, name="alice")
    with caplog.at_level(logging.INFO, logger="rover_web.teleop.control"):
        pad.drive(0.5, -0.25, source="gamepad")
        peer.wait_for("/cmd_vel", lambda m: (m["linear"]["x"], m["angular"]["z"]) == (2.5, -0.5), timeout=3.0)
        stream.wait_for("teleop", lambda s: s["source"] == "gamepad" and s["linear_mps"] == 2.5)
    assert "teleop: alice drives with the gamepad" in [r.getMessage() for r in caplog.records]

    # A value outside [-1, 1] is refused as for the joystick, and the robot is at zero.
    pad.send({"linear": 1.5, "angular": 0, "epoch": pad.epoch, "source": "gamepad"})
    peer.wait_for("/cmd_vel", is_zero, timeout=3.0)
    assert pad.wait_errors(1)[0]["error"] == "out_of_range"
    # An unknown source is refused too.
    pad.send({"linear": 0.5, "angular": 0, "epoch": pad.epoch, "source": "joypad"})
    assert pad.wait_errors(2)[1]["error"] == "bad_value"

    # Another socket's gamepad is view-only while alice holds control.
    pad.drive(0.2, 0.0, source="gamepad")
    peer.wait_for("/cmd_vel", lambda m: m["linear"]["x"] == 1.0, timeout=3.0)
    other = TeleopClient(server.url, name="bob")
    other.drive(-1.0, 0.0, source="gamepad")
    assert other.wait_for(lambda m: m["type"] == "error")["error"] == "not_in_control"

    # E-stop: zero, drive frames refused; after the release a held stick must pass through neutral.
    peer.clear("/cmd_vel")
    pad.send({"estop": True})
    pad.wait_for(lambda m: m["type"] == "state" and m["reason"] == "estop")
    peer.wait_for("/cmd_vel", is_zero, timeout=3.0)
    pad.drive(0.2, 0.0, source="gamepad")
    assert pad.wait_for(lambda m: m["type"] == "error" and m["error"] == "estop_engaged")["status"] == 409
    server.rover.feature(EStopService).release("test")
    pad.wait_for(lambda m: m["type"] == "state" and m["reason"] == "estop_released")
    pad.drive(0.2, 0.0, source="gamepad")
    assert pad.wait_for(lambda m: m["type"] == "error" and m["error"] == "rearm_required")["status"] == 409
    assert all(lin == 0.0 for _, lin, _ in twists(peer))
    pad.drive(0.0, 0.0, source="gamepad")
    pad.drive(0.2, 0.0, source="gamepad")
    peer.wait_for("/cmd_vel", lambda m: m["linear"]["x"] == 1.0, timeout=3.0)
    pad.send({"stop": True})
    peer.wait_for("/cmd_vel", is_zero, timeout=3.0)
