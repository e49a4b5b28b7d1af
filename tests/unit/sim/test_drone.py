"""The simulated drone's flight logic, with a fake clock (no ROS)."""

import pytest

from rover_web.sim import drone as drone_module
from rover_web.sim.drone import FLYING, HOVERING, NO_TAG, STANDBY, DroneModel, OwnEcho


@pytest.fixture
def model():
    return DroneModel(transition_s=2.0, height_m=5, tag_spacing_m=4.0)


def test_take_off_flies_then_hovers_above_the_pad(model):
    assert (model.status, model.tag, model.position(0.0)) == (STANDBY, 0, (0.0, 0.0, 0.0))
    assert model.control_phase(1, 10.0) == "taking off to 5 m"
    assert model.status == FLYING and model.tag == NO_TAG
    assert model.position(11.0) == (0.0, 0.0, 2.5)
    assert model.step(11.9) is False and model.status == FLYING
    assert model.step(12.0) is True
    assert (model.status, model.tag, model.position(12.5)) == (HOVERING, 0, (0.0, 0.0, 5.0))


def test_destination_return_and_the_rules(model):
    assert "ignored" in model.fly_to(3, 0.0)          # not while on the pad
    assert "ignored" in model.control_phase(2, 0.0)   # return only while hovering
    model.control_phase(1, 0.0)
    assert "ignored" in model.control_phase(1, 1.0)   # take off while flying
    model.step(2.0)
    assert model.fly_to(7, 2.0) == "flying to tag 7"
    assert model.status == FLYING
    model.step(4.0)
    assert (model.status, model.tag, model.position(4.0)) == (HOVERING, 7, (8.0, 4.0, 5.0))
    assert model.control_phase(2, 4.0) == "returning to the home pad"
    model.step(6.0)
    assert (model.status, model.tag, model.position(6.0)) == (STANDBY, 0, (0.0, 0.0, 0.0))


def test_stop_hovers_in_place(model):
    model.control_phase(1, 0.0)
    model.step(2.0)
    model.fly_to(2, 2.0)  # tag 2 is 8 m east
    assert model.control_phase(0, 2.5).startswith("stop: hovering at 2.0, 0.0, 5.0")
    assert (model.status, model.tag) == (HOVERING, NO_TAG)  # between tags 0 and 1
    assert model.position(10.0) == (2.0, 0.0, 5.0)
    assert model.control_phase(0, 11.0) == "stop: already Hovering"
    # Stopped on the ground (right at the start of a take off), it stays on the pad.
    fresh = DroneModel(transition_s=2.0)
    fresh.control_phase(1, 0.0)
    assert fresh.control_phase(0, 0.0) == "stop: still on the ground" and fresh.status == STANDBY


def test_flight_height(model):
    assert model.set_height(12, 0.0) == "flight height set to 12 m"
    model.control_phase(1, 0.0)
    model.step(2.0)
    assert model.position(2.0)[2] == 12.0
    assert "ignored" in model.set_height(0, 2.0)
    model.set_height(20, 2.0)
    assert model.status == FLYING
    model.step(4.0)
    assert model.status == HOVERING and model.position(4.0)[2] == 20.0


def test_unknown_phase_and_tag_range(model):
    assert "ignored" in model.control_phase(9, 0.0)
    model.control_phase(1, 0.0)
    model.step(2.0)
    assert "ignored" in model.fly_to(-3, 2.0)


def test_own_echo_is_recognised_by_its_source_timestamp():
    echo = OwnEcho(keep=2)
    echo.published(100, 110)
    echo.published(200, 205)
    assert echo.is_own(105) and echo.is_own(200) and not echo.is_own(150)
    echo.published(300, 301)
    assert not echo.is_own(105)  # only recent windows are kept


def test_the_drone_is_a_simulator_part():
    from rover_web.sim.__main__ import PARTS
    assert drone_module in PARTS
