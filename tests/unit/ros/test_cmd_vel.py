"""The velocity output's own rules: clamped, finite, zero only while the e-stop holds it or after halt.

The publisher is a recorder: what is checked here is what CmdVelOutput hands it, not ROS (the
ROS side is tests/integration/estop and tests/integration/teleop)."""

import threading

import pytest

pytest.importorskip("geometry_msgs")

from rover_web.ros.cmd_vel import CmdVelOutput  # noqa: E402


class Recorder:
    def __init__(self):
        self.sent = []

    def publish(self, msg):
        self.sent.append((msg.linear.x, msg.angular.z))


class Runtime:
    def __init__(self):
        self.publisher_made = Recorder()

    def publisher(self, msg_type, topic, qos):
        return self.publisher_made


def output():
    runtime = Runtime()
    return CmdVelOutput(runtime, "/cmd_vel", max_linear_mps=1.0, max_angular_rps=2.0), runtime.publisher_made.sent


def test_commands_are_clamped_and_a_non_finite_one_is_a_stop():
    out, sent = output()
    out.send(5.0, -7.0)
    out.send(float("nan"), float("inf"))
    assert sent == [(1.0, -2.0), (0.0, 0.0)]


def test_while_the_estop_holds_every_command_goes_out_as_zero_until_it_is_released():
    out, sent = output()
    out.hold_zero()
    assert out.send(0.8, 1.0) == (0.0, 0.0)  # teleop not yet told: still nothing moves
    out.hold_zero()  # pressed again
    out.release_hold()
    out.send(0.5, 0.0)
    assert sent == [(0.0, 0.0), (0.0, 0.0), (0.0, 0.0), (0.5, 0.0)]


def test_after_halt_only_zero_ever_goes_out():
    out, sent = output()
    out.halt()
    out.release_hold()  # a release after shutdown changes nothing
    out.send(0.5, 0.5)
    assert sent == [(0.0, 0.0), (0.0, 0.0)]


def test_a_stop_signal_arriving_inside_a_publish_does_not_deadlock():
    """rover_web.process's SIGINT/SIGTERM handler calls halt() on the main thread, which may be inside
    halt() already (a second Ctrl-C while the demo stops): the demo hung there for good."""
    out, sent = output()
    recorder = out._publisher
    real_publish = recorder.publish

    def publish_then_signal(msg):
        real_publish(msg)
        if len(sent) == 1:
            out.halt()  # what the signal handler does, on the same thread, mid-publish

    recorder.publish = publish_then_signal
    worker = threading.Thread(target=out.halt, daemon=True)  # a deadlock must fail the test, not hang it
    worker.start()
    worker.join(5)
    assert not worker.is_alive()
    assert sent == [(0.0, 0.0), (0.0, 0.0)]
