"""The simulated laser and costmaps from a floorplan: a ray stops at the first wall, costs fall away from it."""

import math

import numpy as np
import pytest

from rover_web.sim.sensors import INSCRIBED, LETHAL, Floorplan, footprint, window


@pytest.fixture
def room():
    walls = np.zeros((40, 40), dtype=bool)   # 4 m x 4 m at 10 cm, origin (-2, -2)
    walls[:, 30] = True                      # a wall at x = 1.0 .. 1.1
    return Floorplan(walls, 0.1, -2.0, -2.0)


def test_a_ray_stops_at_the_first_wall_and_open_space_returns_nothing(room):
    ranges = room.raycast(0.0, 0.0, 0.0, np.array([0.0, math.pi / 2, math.pi]), 10.0)
    assert ranges[0] == pytest.approx(1.0, abs=0.05)
    assert np.isinf(ranges[1]) and np.isinf(ranges[2])   # off the floorplan: no return
    turned = room.raycast(0.0, 0.0, math.pi / 4, np.array([-math.pi / 4]), 10.0)
    assert turned[0] == pytest.approx(1.0, abs=0.05)


def test_costs_are_lethal_on_walls_and_fall_with_distance(room):
    costs = room.costs(inscribed_m=0.15, inflation_m=0.55)
    row = costs[20]
    assert row[30] == LETHAL and row[29] == INSCRIBED
    assert 0 < row[26] < row[27] < INSCRIBED and row[20] == 0
    cells, ox, oy = window(costs, room, 1.0, 0.0, 1.0)
    assert cells.shape == (10, 10) and (ox, oy) == pytest.approx((0.5, -0.5))
    assert (cells == LETHAL).any()
    off, _, _ = window(costs, room, 10.0, 10.0, 1.0)
    assert (off == -1).all()


def test_the_footprint_turns_with_the_robot():
    assert footprint(1.0, 1.0, math.pi / 2, 0.5)[0] == pytest.approx((0.5, 1.5))
