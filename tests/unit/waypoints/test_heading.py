"""The GPS map's heading: ENU yaw to compass bearing, orientations that are none, going stale."""

import math

import pytest

from rover_web.waypoints.heading import Heading, bearing_deg, yaw_of_quaternion


@pytest.mark.parametrize("yaw_deg,offset,bearing", [(0, 0, 90.0), (90, 0, 0.0), (180, 0, 270.0), (-90, 0, 180.0),
                                                    (-135, 0, 225.0), (0, 90, 0.0), (0, -30, 120.0), (89.96, 0, 0.0)])
def test_bearing_is_clockwise_from_north_of_a_yaw_counter_clockwise_from_east(yaw_deg, offset, bearing):
    assert bearing_deg(math.radians(yaw_deg), offset) == pytest.approx(bearing)
    assert 0 <= bearing_deg(math.radians(yaw_deg), offset) < 360


@pytest.mark.parametrize("q", [(0, 0, 0, 0), (float("nan"), 0, 0, 1), (0, 0, float("inf"), 1)])
def test_orientations_that_are_no_rotation_give_none(q):
    assert yaw_of_quaternion(*q) is None


def test_an_unnormalised_quaternion_still_gives_its_yaw():
    half = math.radians(30) / 2
    assert yaw_of_quaternion(0, 0, 3 * math.sin(half), 3 * math.cos(half)) == pytest.approx(math.radians(30))


def test_skips_are_counted_and_the_heading_goes_stale_once():
    now = [100.0]
    heading = Heading("/odom", 0.0, 2.0, clock=lambda: now[0])
    assert heading.update(None) is None and heading.skipped == 1
    assert heading.went_stale() is None  # nothing yet: nothing to announce
    state = heading.update(0.0)
    assert state == {"heading_deg": 90.0, "yaw_rad": 0.0, "topic": "/odom", "stale": False}
    now[0] += 1.9
    assert heading.went_stale() is None
    now[0] += 0.2
    assert heading.went_stale()["stale"] is True
    assert heading.went_stale() is None  # announced once
    assert heading.update(math.pi / 2)["stale"] is False
