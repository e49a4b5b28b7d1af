"""The simulator's frames: its laser mount, cast and placed back through TF, lands on the walls; the
configured offset (the fallback, 0 0 0) would not; an initial pose moves map -> odom, not odometry."""

import math

import numpy as np
import pytest

from rover_web.placement import Planar
from rover_web.sim import frames
from rover_web.sim.rover import default_start, first_map
from rover_web.sim.sensors import Floorplan
from rover_web.tf.buffer import TfBuffer


def on_walls(plan: Floorplan, xs, ys, within_m=0.075) -> float:
    rows, cols = np.nonzero(plan.walls)
    cx = plan.origin_x + (cols + 0.5) * plan.resolution
    cy = plan.origin_y + (rows + 0.5) * plan.resolution
    reach = within_m + plan.resolution / 2
    near = [np.min(np.maximum(np.abs(cx - x), np.abs(cy - y))) <= reach for x, y in zip(xs, ys, strict=True)]
    return float(np.mean(near))


@pytest.fixture(scope="module")
def plan():
    return Floorplan.from_definition(first_map())


def cast(plan, robot, angles):
    x, y, heading = frames.laser_origin(robot)
    return plan.raycast(x, y, heading, frames.beam_directions(angles), 12.0).astype(np.float64)


@pytest.mark.parametrize("turn", [0.0, 1.0, -2.5])
def test_the_scan_cast_from_the_mount_lands_on_the_walls_through_tf_and_not_through_the_fallback(plan, turn):
    x0, y0, yaw0 = default_start()
    robot = (x0, y0, yaw0 + turn)
    angles = np.linspace(-math.pi, math.pi, 360, endpoint=False)
    ranges = cast(plan, robot, angles)
    hit = np.isfinite(ranges)
    assert hit.sum() > 300
    loc = frames.Localisation((0.0, 0.0, 0.0))
    odom = loc.odom_pose(robot)
    b = TfBuffer()
    b.set_transform("map", "odom", (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0), 5, static=False)
    b.set_transform("odom", "base_link", (odom[0], odom[1], 0.0), (0.0, 0.0, math.sin(odom[2] / 2),
                                                                   math.cos(odom[2] / 2)), 5, static=False)
    m = frames.LASER
    b.set_transform("base_link", m.frame, (m.x, m.y, m.z), m.quaternion, 0, static=True)
    t = b.lookup("map", m.frame, 5)
    lx, ly = ranges[hit] * np.cos(angles[hit]), ranges[hit] * np.sin(angles[hit])
    mx, my, mz = t.apply_many(lx, ly)
    assert on_walls(plan, mx, my) == 1.0
    assert mz == pytest.approx(np.full(mz.shape, m.z))  # upside down and level: the scan plane stays at its height
    # The configured offset (0, 0, 0) at the robot's pose: mirrored and off by the mount: mostly off the walls.
    fx, fy, _ = Planar(*robot).apply_many(lx, ly)
    assert on_walls(plan, fx, fy) < 0.6


def test_mount_quaternions_are_tf2_s_set_rpy():
    q = frames.Mount("x", 0, 0, 0, roll=math.pi, yaw=0.5).quaternion
    # Rz(0.5) Rx(pi): x axis turned 0.5 rad, y axis pointing at -(0.5 + 90 degrees), z down.
    assert q == pytest.approx((math.cos(0.25), math.sin(0.25), 0.0, 0.0), abs=1e-12)
    assert sum(v * v for v in frames.CAMERA.quaternion) == pytest.approx(1.0)


def test_an_initial_pose_moves_map_to_odom_and_odometry_s_position_stays_continuous():
    loc = frames.Localisation((0.0, 0.0, 0.0))
    before = (2.0, 3.0, 0.5)
    odom = loc.odom_pose(before)
    loc.relocalise(before, (10.0, -1.0, 2.0))
    after = loc.odom_pose((10.0, -1.0, 2.0))
    assert after[:2] == pytest.approx(odom[:2])                        # odometry's position did not jump
    assert after[2] == pytest.approx(2.0) and loc.map_t_odom[2] == 0.0   # odom stays aligned with the map
    assert frames.compose(loc.map_t_odom, after) == pytest.approx((10.0, -1.0, 2.0))
    assert loc.map_t_odom[:2] == pytest.approx((8.0, -4.0))
