"""A REST drive ends with its credential (rest_drive.py), with a recording output and registrations
that stand in for auth's: only the drive the revoked credential started stops, and only one
registration is kept."""

import pytest

from rover_web.teleop.control import TeleopController
from rover_web.teleop.rest_drive import RestDrives
from tests.unit.teleop.test_control import LIMITS, Clock, Output


class Watch:
    """Stands in for auth's on_revoke: keeps each close callback and whether it was cancelled."""

    def __init__(self):
        self.registrations = []

    def __call__(self, close):
        registration = Registration(close)
        self.registrations.append(registration)
        return registration


class Registration:
    def __init__(self, close):
        self.close = close
        self.cancelled = False

    def cancel(self):
        self.cancelled = True


@pytest.fixture
def drives():
    clock = Clock()
    out = Output(clock)
    ctl = TeleopController(out, LIMITS, rate_hz=40, deadman_s=0.3, clock=clock, wall_clock=lambda: 1.7e9)
    return RestDrives(ctl), ctl, out, Watch()


def test_revoking_the_credential_stops_its_drive_with_one_zero(drives):
    rest, ctl, out, watch = drives
    rest.start("forward", 1.0, 5.0, watch)
    assert out.last == (5.0, 0.0)
    watch.registrations[0].close("token revoked")
    assert out.last == (0.0, 0.0) and len(out.sent) == 2
    assert ctl.state()["last_stop"]["reason"] == "revoked"
    watch.registrations[0].close("token revoked")  # once stopped, nothing more is published
    assert len(out.sent) == 2


def test_a_newer_drive_is_not_stopped_by_the_older_ones_credential(drives):
    rest, ctl, out, watch = drives
    rest.start("forward", 1.0, 5.0, watch)
    rest.start("left", 1.0, 5.0, watch)
    first, second = watch.registrations
    assert first.cancelled and not second.cancelled  # only the drive under way is watched
    first.close("user removed")
    assert out.last == (0.0, 2.0) and ctl.state()["moving"]
    second.close("signed out")
    assert out.last == (0.0, 0.0)


def test_a_joystick_drive_is_not_stopped_by_a_rest_credential(drives):
    rest, ctl, out, watch = drives
    rest.start("forward", 1.0, 5.0, watch)
    session = ctl.connect("alice")
    ctl.drive(session, 0.2, 0.0)
    watch.registrations[0].close("token revoked")
    assert out.last == (1.0, 0.0)


def test_a_refused_drive_leaves_no_registration(drives):
    rest, ctl, _, watch = drives
    ctl.engage_estop("test")
    with pytest.raises(Exception, match="e-stop"):
        rest.start("forward", 1.0, 5.0, watch)
    assert watch.registrations[0].cancelled
    rest.close()
