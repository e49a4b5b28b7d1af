"""A simulated differential-drive rover: integrates /cmd_vel, publishes /odom, /amcl_pose and /fix.

Like a real base it stops by itself when commands stop for `cmd_timeout_s`. Its GPS fix is its
map pose laid on a local tangent plane around a configurable origin (by default Nathan
Benderson Park, Sarasota, FL, where RobotX is held).
"""

from __future__ import annotations

import argparse
import math
import time

import rclpy
from geometry_msgs.msg import PoseWithCovarianceStamped, Twist, TwistStamped
from nav_msgs.msg import Odometry
from rclpy.node import Node
from sensor_msgs.msg import NavSatFix, NavSatStatus

from ..ros import qos
from ..ros.convert import quaternion_from_yaw

EARTH_RADIUS_M = 6378137.0
BENDERSON_LAT = 27.3742443
BENDERSON_LON = -82.4500873


def enu_to_geodetic(x_east_m: float, y_north_m: float, lat0: float, lon0: float) -> tuple[float, float]:
    """Small-area approximation, good to centimetres over a few kilometres."""
    lat = lat0 + math.degrees(y_north_m / EARTH_RADIUS_M)
    lon = lon0 + math.degrees(x_east_m / (EARTH_RADIUS_M * math.cos(math.radians(lat0))))
    return lat, lon


class DiffDrive:
    """Pure kinematics, so it can be unit-tested without ROS."""

    def __init__(self, x: float = 0.0, y: float = 0.0, yaw: float = 0.0, cmd_timeout_s: float = 0.5,
                 max_linear_mps: float = 5.0, max_angular_rps: float = 2.0):
        self.x, self.y, self.yaw = x, y, yaw
        self.linear = self.angular = 0.0
        self.cmd_timeout_s = cmd_timeout_s
        self.max_linear_mps, self.max_angular_rps = max_linear_mps, max_angular_rps
        self.last_cmd_at = -math.inf

    def command(self, linear: float, angular: float, now: float) -> None:
        if not (math.isfinite(linear) and math.isfinite(angular)):
            linear = angular = 0.0
        self.linear = max(-self.max_linear_mps, min(self.max_linear_mps, linear))
        self.angular = max(-self.max_angular_rps, min(self.max_angular_rps, angular))
        self.last_cmd_at = now

    def step(self, dt: float, now: float) -> None:
        if now - self.last_cmd_at > self.cmd_timeout_s:
            self.linear = self.angular = 0.0
        if self.angular == 0.0:
            self.x += self.linear * dt * math.cos(self.yaw)
            self.y += self.linear * dt * math.sin(self.yaw)
        else:  # exact arc, so a constant command traces a true circle
            new_yaw = self.yaw + self.angular * dt
            radius = self.linear / self.angular
            self.x += radius * (math.sin(new_yaw) - math.sin(self.yaw))
            self.y -= radius * (math.cos(new_yaw) - math.cos(self.yaw))
            self.yaw = math.atan2(math.sin(new_yaw), math.cos(new_yaw))


class RoverSim(Node):
    def __init__(self, *, context=None, x: float = 0.0, y: float = 0.0, yaw: float = 0.0,
                 stamped: bool = False, lat0: float = BENDERSON_LAT, lon0: float = BENDERSON_LON,
                 rate_hz: float = 50.0):
        super().__init__("sim_rover", context=context)
        self.drive = DiffDrive(x, y, yaw)
        self.lat0, self.lon0 = lat0, lon0
        if stamped:
            self.create_subscription(TwistStamped, "/cmd_vel", lambda m: self._on_cmd(m.twist), 10)
        else:
            self.create_subscription(Twist, "/cmd_vel", self._on_cmd, 10)
        self.odom_pub = self.create_publisher(Odometry, "/odom", 10)
        self.pose_pub = self.create_publisher(PoseWithCovarianceStamped, "/amcl_pose", qos.profile("latched"))
        self.fix_pub = self.create_publisher(NavSatFix, "/fix", 10)
        self._dt = 1.0 / rate_hz
        self._ticks = 0
        self._last = time.monotonic()
        self.create_timer(self._dt, self._tick)

    def _on_cmd(self, twist) -> None:
        self.drive.command(twist.linear.x, twist.angular.z, time.monotonic())

    def _tick(self) -> None:
        now = time.monotonic()
        self.drive.step(now - self._last, now)
        self._last = now
        self._ticks += 1
        stamp = self.get_clock().now().to_msg()
        self.odom_pub.publish(self._odom(stamp))
        if self._ticks % 5 == 0:  # amcl and GPS publish slower than odometry, as on a real robot
            self.pose_pub.publish(self._pose(stamp))
            self.fix_pub.publish(self._fix(stamp))

    def _odom(self, stamp) -> Odometry:
        d = self.drive
        msg = Odometry()
        msg.header.stamp = stamp
        msg.header.frame_id = "odom"
        msg.child_frame_id = "base_link"
        msg.pose.pose.position.x, msg.pose.pose.position.y = d.x, d.y
        q = quaternion_from_yaw(d.yaw)
        o = msg.pose.pose.orientation
        o.x, o.y, o.z, o.w = q
        msg.twist.twist.linear.x = d.linear
        msg.twist.twist.angular.z = d.angular
        return msg

    def _pose(self, stamp) -> PoseWithCovarianceStamped:
        d = self.drive
        msg = PoseWithCovarianceStamped()
        msg.header.stamp = stamp
        msg.header.frame_id = "map"
        msg.pose.pose.position.x, msg.pose.pose.position.y = d.x, d.y
        o = msg.pose.pose.orientation
        o.x, o.y, o.z, o.w = quaternion_from_yaw(d.yaw)
        cov = [0.0] * 36
        cov[0] = cov[7] = 0.05
        cov[35] = 0.02
        msg.pose.covariance = cov
        return msg

    def _fix(self, stamp) -> NavSatFix:
        lat, lon = enu_to_geodetic(self.drive.x, self.drive.y, self.lat0, self.lon0)
        msg = NavSatFix()
        msg.header.stamp = stamp
        msg.header.frame_id = "gps"
        msg.status.status = NavSatStatus.STATUS_FIX
        msg.status.service = NavSatStatus.SERVICE_GPS
        msg.latitude, msg.longitude, msg.altitude = lat, lon, 1.0
        msg.position_covariance_type = NavSatFix.COVARIANCE_TYPE_APPROXIMATED
        msg.position_covariance = [0.5, 0.0, 0.0, 0.0, 0.5, 0.0, 0.0, 0.0, 1.0]
        return msg


def add_arguments(parser: argparse.ArgumentParser) -> None:
    group = parser.add_argument_group("rover")
    group.add_argument("--stamped", action="store_true", help="expect geometry_msgs/TwistStamped on /cmd_vel")
    group.add_argument("--start", type=float, nargs=3, metavar=("X", "Y", "YAW"), default=None,
                       help="start pose in the map frame (metres, radians)")


def from_arguments(args: argparse.Namespace, context) -> RoverSim:
    x, y, yaw = args.start if args.start else (0.0, 0.0, 0.0)
    return RoverSim(context=context, x=x, y=y, yaw=yaw, stamped=args.stamped)


def main(argv: list[str] | None = None) -> None:
    from .runner import run_nodes
    parser = argparse.ArgumentParser(description=__doc__)
    add_arguments(parser)
    args = parser.parse_args(argv)
    run_nodes(lambda ctx: [from_arguments(args, ctx)])


if __name__ == "__main__":
    main()
