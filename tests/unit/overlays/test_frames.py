"""AMCL's map -> odom rebuilt from a map pose and an odometry pose at the same stamp."""

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from rover_web.overlays.frames import OdomInMap, compose, invert

coord = st.floats(-1e3, 1e3)
angle = st.floats(-math.pi, math.pi)
pose = st.tuples(coord, coord, angle)


def close(a, b):
    assert a[0] == pytest.approx(b[0], abs=1e-6) and a[1] == pytest.approx(b[1], abs=1e-6)
    assert math.cos(a[2] - b[2]) == pytest.approx(1.0, abs=1e-9)


@given(pose, pose)
def test_composing_with_the_inverse_gives_back_the_pose(a, b):
    close(compose(compose(a, b), invert(b)), a)
    close(compose(invert(a), compose(a, b)), b)


def test_an_odom_grid_lands_where_amcl_puts_the_odom_frame():
    frames = OdomInMap()
    assert frames.transform("odom") is None                      # nothing heard yet
    frames.on_odom("odom", 100.0, (1.0, 0.0, 0.0))               # odometry: 1 m along odom x
    frames.on_map_pose(100.0, (11.0, 5.0, math.pi / 2))         # AMCL: at (11, 5) facing map +y
    map_t_odom = frames.transform("odom")
    close(map_t_odom, (11.0, 4.0, math.pi / 2))
    # The robot's own odom pose, placed with it, is AMCL's pose.
    close(compose(map_t_odom, (1.0, 0.0, 0.0)), (11.0, 5.0, math.pi / 2))
    assert frames.transform("/odom") == map_t_odom
    assert frames.transform("map") is None and frames.transform("base_link") is None


def test_the_transform_uses_the_odometry_at_amcl_s_stamp_not_the_newest():
    frames = OdomInMap()
    frames.on_odom("odom", 10.0, (0.0, 0.0, 0.0))
    frames.on_odom("odom", 11.0, (2.0, 0.0, 0.0))
    frames.on_map_pose(10.5, (5.0, 5.0, 0.0))                    # odometry then was (1, 0)
    close(frames.transform("odom"), (4.0, 5.0, 0.0))


def test_non_finite_odometry_is_ignored():
    frames = OdomInMap()
    frames.on_odom("odom", 1.0, (float("nan"), 0.0, 0.0))
    frames.on_map_pose(1.0, (0.0, 0.0, 0.0))
    assert frames.transform("odom") is None
