"""A GPS mission laid on the simulated robot's map frame, one waypoint after another."""

import math

import pytest

from rover_web.sim.geodesy import enu_to_geodetic, geodetic_to_enu
from rover_web.sim.mission import Mission, mission_points
from rover_web.sim.rover import BENDERSON_LAT, BENDERSON_LON


def test_geodetic_to_enu_inverts_the_fix():
    lat, lon = enu_to_geodetic(123.4, -56.7, BENDERSON_LAT, BENDERSON_LON)
    x, y = geodetic_to_enu(lat, lon, BENDERSON_LAT, BENDERSON_LON)
    assert x == pytest.approx(123.4, abs=1e-6) and y == pytest.approx(-56.7, abs=1e-6)


def test_mission_points_pairs_lng_lat_and_refuses_what_is_not_a_position():
    assert mission_points([1.0, 2.0, 3.0, 4.0]) == [(1.0, 2.0), (3.0, 4.0)]
    for bad in ([], [1.0], [1.0, 2.0, 3.0], [1.0, math.nan], [200.0, 0.0], [0.0, -91.0]):
        with pytest.raises(ValueError):
            mission_points(bad)


def test_each_goal_faces_the_next_leg_and_the_last_one_the_leg_before():
    mission = Mission([(1.0, 0.0), (1.0, 2.0), (0.0, 2.0)])
    assert mission.goal(0.0, 0.0) == (1.0, 0.0, pytest.approx(math.pi / 2))
    assert mission.beyond() == [(1.0, 2.0), (0.0, 2.0)]
    mission.index = 2
    assert mission.goal(1.0, 2.0) == (0.0, 2.0, pytest.approx(math.pi))
    assert mission.beyond() == []
    mission.index = 3
    assert mission.done
