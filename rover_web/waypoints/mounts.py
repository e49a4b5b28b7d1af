"""The GPS map's sensor offsets through TF: the antenna's place on the robot and a heading sensor's
rotation on it. Pure Python.

A NavSatFix is where the antenna is (its header's frame, e.g. `gps`), not the robot's centre: an
antenna 40 cm behind base_link puts the robot's marker 40 cm off, the wrong side of a buoy. With TF's
base_link <- antenna, the robot's centre is the antenna's position less that offset turned by the
robot's heading (east, north metres, then degrees on a local tangent plane). A heading from an IMU
is the IMU's orientation: one mounted turned on the robot gives the robot's heading only once its
mount (imu_link <- base_link) is composed in. Without TF (or without a heading to turn the antenna
offset by) the fix and the heading are drawn as they came, and say so.
"""

from __future__ import annotations

import math

EARTH_RADIUS_M = 6_378_137.0  # WGS 84's equatorial radius: metres to degrees near the ground


def robot_centre(lat: float, lng: float, antenna_xy: tuple[float, float], yaw_enu: float) -> tuple[float, float]:
    """(lat, lng) of base_link from the antenna's fix: antenna_xy is the antenna on the robot (x ahead,
    y left, metres), yaw_enu the robot's heading (radians counter-clockwise from east)."""
    c, s = math.cos(yaw_enu), math.sin(yaw_enu)
    east = c * antenna_xy[0] - s * antenna_xy[1]
    north = s * antenna_xy[0] + c * antenna_xy[1]
    dlat = math.degrees(north / EARTH_RADIUS_M)
    dlng = math.degrees(east / (EARTH_RADIUS_M * math.cos(math.radians(lat))))
    return lat - dlat, lng - dlng


def _qmul(a, b):
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz)


def base_yaw(sensor_in_world: tuple[float, float, float, float],
             base_in_sensor: tuple[float, float, float, float]) -> float:
    """Yaw of base_link in the heading's world frame: world <- sensor composed with sensor <- base_link."""
    x, y, z, w = _qmul(sensor_in_world, base_in_sensor)
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
