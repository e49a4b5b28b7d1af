"""The GPS map's sensor offsets through TF: the antenna moved to base_link, an IMU's mount turned out."""

import math

import pytest

from rover_web.sim.geodesy import geodetic_to_enu
from rover_web.tf.buffer import TfBuffer
from rover_web.waypoints.mounts import EARTH_RADIUS_M, base_yaw, robot_centre


def test_an_antenna_behind_the_centre_puts_the_robot_ahead_of_its_fix_along_its_heading():
    lat, lng = 27.3742443, -82.4500873
    # Antenna 0.5 m behind base_link; robot facing north (ENU yaw 90 degrees): the centre is 0.5 m north.
    clat, clng = robot_centre(lat, lng, (-0.5, 0.0), math.pi / 2)
    assert clng == pytest.approx(lng, abs=1e-12)
    assert (clat - lat) == pytest.approx(math.degrees(0.5 / EARTH_RADIUS_M), rel=1e-9)
    assert geodetic_to_enu(clat, clng, lat, lng) == pytest.approx((0.0, 0.5), abs=1e-6)  # (east, north)
    # Facing east, an antenna 1 m to the robot's left is 1 m north of it: the centre 1 m south.
    clat, clng = robot_centre(lat, lng, (0.0, 1.0), 0.0)
    assert clat < lat and clng == pytest.approx(lng, abs=1e-12)
    assert geodetic_to_enu(clat, clng, lat, lng) == pytest.approx((0.0, -1.0), abs=1e-6)


def test_an_imu_mounted_turned_gives_the_robot_s_heading_once_its_mount_is_composed_in():
    b = TfBuffer()
    # The IMU is turned 90 degrees left on the robot (its x axis is the robot's y axis).
    b.set_transform("base_link", "imu_link", (0.1, 0.0, 0.2), (0.0, 0.0, math.sin(math.pi / 4), math.cos(math.pi / 4)),
                    0, static=True)
    mount = b.lookup("base_link", "imu_link")
    # The IMU reads its own x axis at 30 degrees (ENU): the robot faces 30 - 90 = -60 degrees.
    q_imu = (0.0, 0.0, math.sin(math.radians(15)), math.cos(math.radians(15)))
    assert math.degrees(base_yaw(q_imu, mount.inverse().rotation)) == pytest.approx(-60.0)
    # Upside down (roll 180), its x axis still the robot's: it reads Rz(30) Rx(180); the robot faces 30.
    b.set_transform("base_link", "imu2", (0.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0), 0, static=True)
    q_flipped = (math.cos(math.radians(15)), math.sin(math.radians(15)), 0.0, 0.0)  # Rz(30) Rx(180)
    assert math.degrees(base_yaw(q_flipped, b.lookup("base_link", "imu2").inverse().rotation)) == pytest.approx(30.0)
