"""A simulated differential-drive rover: integrates cmd_vel, publishes odom, amcl_pose, fix and its
frames on tf and tf_static (frames.py: map -> odom -> base_link, and its sensors' mounts).

Topic names are relative, so in the root namespace they are /cmd_vel, /odom, ... and in a robot's
namespace (`--robots`) /boat/cmd_vel, /boat/odom, ...

Like a real base it stops by itself when commands stop for `cmd_timeout_s`. Its GPS fix is its
map pose laid on a local tangent plane around a configurable origin (by default Nathan
Benderson Park, Sarasota, FL, where RobotX is held).

It starts on the first floorplan of map_files/all_maps.json (at that map's first waypoint), jumps
to an initial pose on /initialpose (as AMCL would re-localise: map -> odom moves, odometry's
position stays continuous; it has no odometry drift), and
drives itself to a goal received on /goal_pose (frame `map`) with a simple turn-and-drive
controller, publishing a straight-line /plan while it goes, and stops there. The operator always
wins: any /cmd_vel message, a stop included, cancels the goal, as a stop button would on a
navigating robot.

It also drives a GPS mission sent on /mission (mission.py), stops or slides at the floorplan's
walls (walls.py) and publishes /battery_state from a pack that drains as it drives (battery.py).
With nav2_msgs installed it answers Nav2's navigate_to_pose, navigate_through_poses and
follow_waypoints, planning around those walls (nav2_server.py, planner.py).
"""

from __future__ import annotations

import argparse
import functools
import math
import os
import sys
import time
from dataclasses import dataclass

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from geometry_msgs.msg import PoseStamped, PoseWithCovarianceStamped, Twist, TwistStamped
from nav_msgs.msg import Odometry, Path
from rclpy.logging import LoggingSeverity
from rclpy.node import Node
from sensor_msgs.msg import BatteryState, NavSatFix, NavSatStatus

from rover_web.ros import qos
from rover_web.ros.convert import quaternion_from_yaw, yaw_from_quaternion

from .battery import START_CHARGE, Battery, battery_state
from .frames import FramePublisher, Localisation
from .geodesy import enu_to_geodetic
from .health import HealthModel
from .mission import MissionDriver
from .model import DescriptionPublisher
from .robots import SPACING_EAST_M
from .walls import StallWatch, Walls

BENDERSON_LAT = 27.3742443
BENDERSON_LON = -82.4500873


class DiffDrive:
    """Pure kinematics, so it can be unit-tested without ROS."""

    def __init__(self, x: float = 0.0, y: float = 0.0, yaw: float = 0.0, cmd_timeout_s: float = 0.5,
                 max_linear_mps: float = 5.0, max_angular_rps: float = 2.0):
        self.x, self.y, self.yaw = x, y, yaw
        self.linear = self.angular = 0.0
        self.cmd_timeout_s = cmd_timeout_s
        self.max_linear_mps, self.max_angular_rps = max_linear_mps, max_angular_rps
        self.last_cmd_at = -math.inf
        self.walls: Walls | None = None

    def command(self, linear: float, angular: float, now: float) -> None:
        if not (math.isfinite(linear) and math.isfinite(angular)):
            linear = angular = 0.0
        self.linear = max(-self.max_linear_mps, min(self.max_linear_mps, linear))
        self.angular = max(-self.max_angular_rps, min(self.max_angular_rps, angular))
        self.last_cmd_at = now

    def step(self, dt: float, now: float) -> None:
        if now - self.last_cmd_at > self.cmd_timeout_s:
            self.linear = self.angular = 0.0
        x0, y0 = self.x, self.y
        if self.angular == 0.0:
            self.x += self.linear * dt * math.cos(self.yaw)
            self.y += self.linear * dt * math.sin(self.yaw)
        else:  # exact arc, so a constant command traces a true circle
            new_yaw = self.yaw + self.angular * dt
            radius = self.linear / self.angular
            self.x += radius * (math.sin(new_yaw) - math.sin(self.yaw))
            self.y -= radius * (math.cos(new_yaw) - math.cos(self.yaw))
            self.yaw = math.atan2(math.sin(new_yaw), math.cos(new_yaw))
        if self.walls is not None:
            self.x, self.y = self.walls.move(x0, y0, self.x, self.y)


def _wrap(angle: float) -> float:
    return math.atan2(math.sin(angle), math.cos(angle))


@dataclass(frozen=True)
class Goal:
    x: float
    y: float
    yaw: float


class GoalFollower:
    """Turn towards the goal, drive to it, turn to its heading, stop. Pure, so it is unit-tested.

    Linear speed falls with the heading error (nothing while facing more than 60 degrees away) and
    with the distance left, so the robot arcs in without overshooting; once within
    `position_tolerance_m` it only turns, and it never drives off again for the same goal.
    """

    def __init__(self, max_linear_mps: float = 0.5, max_angular_rps: float = 1.0,
                 position_tolerance_m: float = 0.05, yaw_tolerance_rad: float = 0.05,
                 linear_gain: float = 1.0, angular_gain: float = 2.0):
        self.max_linear_mps, self.max_angular_rps = max_linear_mps, max_angular_rps
        self.position_tolerance_m, self.yaw_tolerance_rad = position_tolerance_m, yaw_tolerance_rad
        self.linear_gain, self.angular_gain = linear_gain, angular_gain
        self.goal: Goal | None = None
        self._turning_in_place = False
        self.reached = 0  # goals completed, for logs and tests

    @property
    def active(self) -> bool:
        return self.goal is not None

    def set_goal(self, x: float, y: float, yaw: float) -> bool:
        if not all(math.isfinite(v) for v in (x, y, yaw)):
            return False
        self.goal = Goal(x, y, _wrap(yaw))
        self._turning_in_place = False
        return True

    def cancel(self) -> bool:
        """Forget the goal; True if there was one."""
        had = self.goal is not None
        self.goal = None
        return had

    def command(self, x: float, y: float, yaw: float) -> tuple[float, float]:
        """(linear m/s, angular rad/s) towards the goal from pose (x, y, yaw); (0, 0) once there."""
        goal = self.goal
        if goal is None:
            return 0.0, 0.0
        dx, dy = goal.x - x, goal.y - y
        distance = math.hypot(dx, dy)
        if not self._turning_in_place and distance <= self.position_tolerance_m:
            self._turning_in_place = True
        if self._turning_in_place:
            error = _wrap(goal.yaw - yaw)
            if abs(error) <= self.yaw_tolerance_rad:
                self.goal = None
                self.reached += 1
                return 0.0, 0.0
            return 0.0, self._clamp(self.angular_gain * error, self.max_angular_rps)
        error = _wrap(math.atan2(dy, dx) - yaw)
        angular = self._clamp(self.angular_gain * error, self.max_angular_rps)
        facing = max(0.0, (math.cos(error) - 0.5) / 0.5)  # 1 facing the goal, 0 at 60 degrees or more
        linear = min(self.max_linear_mps, self.linear_gain * distance) * facing
        return linear, angular

    @staticmethod
    def _clamp(value: float, limit: float) -> float:
        return max(-limit, min(limit, value))


# rclpy remembers each logging call site's severity and refuses another one there: one site per level.
_LOG = {
    "debug": lambda logger, text: logger.debug(text),
    "info": lambda logger, text: logger.info(text),
    "warning": lambda logger, text: logger.warning(text),
    "error": lambda logger, text: logger.error(text),
    "fatal": lambda logger, text: logger.fatal(text),
}


class RoverSim(Node):
    def __init__(self, *, context=None, x: float = 0.0, y: float = 0.0, yaw: float = 0.0,
                 stamped: bool = False, lat0: float = BENDERSON_LAT, lon0: float = BENDERSON_LON,
                 rate_hz: float = 50.0, goal_topic: str = "goal_pose", goal_speed_mps: float = 0.5,
                 namespace: str = "/", walls: Walls | None = None, battery_charge: float = START_CHARGE,
                 debug_logs: bool = False, floorplan=None, waypoints=(), scan_beams: int = 360,
                 scan_hz: float = 10.0):
        super().__init__("sim_rover", namespace=namespace, context=context)
        self.drive = DiffDrive(x, y, yaw)
        self.drive.walls = walls
        self.stall = StallWatch()
        self.follower = GoalFollower(max_linear_mps=goal_speed_mps)
        self.lat0, self.lon0 = lat0, lon0
        if stamped:
            self.create_subscription(TwistStamped, "cmd_vel", lambda m: self._on_cmd(m.twist), 10)
        else:
            self.create_subscription(Twist, "cmd_vel", self._on_cmd, 10)
        self.odom_pub = self.create_publisher(Odometry, "odom", 10)
        self.pose_pub = self.create_publisher(PoseWithCovarianceStamped, "amcl_pose", qos.profile("latched"))
        self.fix_pub = self.create_publisher(NavSatFix, "fix", 10)
        self.plan_pub = self.create_publisher(Path, "plan", 1)
        # Odometry starts in the map's coordinates (map -> odom the identity, as a datum would set
        # it); an initial pose then moves map -> odom and odometry's position stays continuous (frames.py).
        self.localisation = Localisation((0.0, 0.0, 0.0))
        self.frames = FramePublisher(self, self.localisation)
        self.description = DescriptionPublisher(self)  # the model the 3D view draws (model.py)
        self.last_stamp = self.get_clock().now().to_msg()  # of the latest odometry: the pose sensors use
        self.create_subscription(PoseStamped, goal_topic, self._on_goal, 10)
        self.mission = MissionDriver(self)
        from .nav2_server import Nav2Sim
        self.nav2 = Nav2Sim(self, walls, goal_speed_mps)
        # Standing in for AMCL: an operator's initial pose (LiveMap's Set pose) puts the robot there.
        self.create_subscription(PoseWithCovarianceStamped, "initialpose", self._on_initial_pose, 10)
        self._dt = 1.0 / rate_hz
        self._ticks = 0
        self._last = time.monotonic()
        self.create_timer(self._dt, self._tick)
        # Diagnostics and the battery once a second, and log lines when something changes, so the
        # demo's /diagnostics, /logs and Robot card show something (rclpy nodes log to /rosout).
        # Named after the node with its namespace, so an operator reading a merged list knows which robot.
        self.health = HealthModel(node=self.get_fully_qualified_name().lstrip("/"), battery=Battery(battery_charge))
        self.diag_pub = self.create_publisher(DiagnosticArray, "diagnostics", 10)
        self.battery_pub = self.create_publisher(BatteryState, "battery_state", qos.profile("sensor_data"))
        # A real node logs at INFO; the health checks' DEBUG lines only with --debug-logs.
        self.get_logger().set_level(LoggingSeverity.DEBUG if debug_logs else LoggingSeverity.INFO)
        self.create_timer(1.0, self._health)
        # What it senses, from its floorplan: scan, costmaps, footprint, markers (perception.py).
        self.perception = None
        if floorplan is not None:
            from .perception import Perception
            self.perception = Perception(self, floorplan, waypoints, scan_beams, scan_hz)

    def _health(self) -> None:
        statuses, lines = self.health.step(self.drive.linear, self.drive.angular)
        statuses.append(self.mission.status(self.health.node))
        msg = DiagnosticArray()
        msg.header.stamp = self.get_clock().now().to_msg()
        self.battery_pub.publish(battery_state(self.health.battery, msg.header.stamp))
        for s in statuses:
            msg.status.append(DiagnosticStatus(level=bytes([s["level"]]), name=s["name"], message=s["message"],
                                               hardware_id=s["hardware_id"],
                                               values=[KeyValue(key=k, value=v) for k, v in s["values"].items()]))
        self.diag_pub.publish(msg)
        for level, text in lines:
            _LOG[level](self.get_logger(), text)

    def _on_cmd(self, twist) -> None:
        self.nav2.operator_command(twist.linear.x, twist.angular.z, time.monotonic())
        self.mission.cancel("operator command on cmd_vel")
        if self.follower.cancel():
            self.get_logger().info("operator command on cmd_vel: goal cancelled")
            self.plan_pub.publish(self._plan(None))
        self.drive.command(twist.linear.x, twist.angular.z, time.monotonic())

    def _on_goal(self, msg: PoseStamped) -> None:
        if msg.header.frame_id not in ("map", ""):
            self.get_logger().warning(f"ignoring a goal in frame {msg.header.frame_id!r}; the sim drives in 'map'")
            return
        q = msg.pose.orientation
        x, y = msg.pose.position.x, msg.pose.position.y
        self.mission.cancel("a new goal")
        self.nav2.preempt("a goal on goal_pose")
        if self.follower.set_goal(x, y, yaw_from_quaternion(q.x, q.y, q.z, q.w)):
            self.get_logger().info(f"goal ({x:.2f}, {y:.2f}) received")
            self.plan_pub.publish(self._plan(self.follower.goal))

    def _on_initial_pose(self, msg: PoseWithCovarianceStamped) -> None:
        p, q = msg.pose.pose.position, msg.pose.pose.orientation
        yaw = yaw_from_quaternion(q.x, q.y, q.z, q.w)
        if msg.header.frame_id not in ("map", "") or not all(map(math.isfinite, (p.x, p.y, yaw))):
            self.get_logger().warning("ignoring an initial pose that is not a finite pose in frame 'map'")
            return
        d = self.drive
        self.localisation.relocalise((d.x, d.y, d.yaw), (p.x, p.y, yaw))
        d.x, d.y, d.yaw = p.x, p.y, yaw
        self.get_logger().info(f"initial pose set: ({p.x:.2f}, {p.y:.2f}), {math.degrees(yaw):.0f} degrees")

    def _tick(self) -> None:
        now = time.monotonic()
        if self.follower.active and self.nav2.active:
            self.nav2.preempt("a mission")
        if self.nav2.active:
            d = self.drive
            command = self.nav2.tick(d.x, d.y, d.yaw, d.linear, now)
            if command is not None:
                d.command(*command, now)
        elif self.follower.active:
            d = self.drive
            linear, angular = self.follower.command(d.x, d.y, d.yaw)
            d.command(linear, angular, now)
            if not self.follower.active and not self.mission.reached():  # else the next waypoint is the goal
                self.get_logger().info(f"goal reached at ({d.x:.2f}, {d.y:.2f})")
                self.plan_pub.publish(self._plan(None))
            elif self._ticks % 50 == 0:  # a planner republishes its path; ours shrinks as we go
                self.plan_pub.publish(self._plan(self.follower.goal))
        self.drive.step(now - self._last, now)
        self._last = now
        d = self.drive
        if self.follower.active and self.stall.stalled(d.x, d.y, now, pushing=abs(d.linear) > 0.05):
            self.follower.cancel()
            self.get_logger().warning(f"goal aborted: blocked by a wall at ({d.x:.2f}, {d.y:.2f})")
            self.mission.cancel("blocked by a wall")
            self.plan_pub.publish(self._plan(None))
        self._ticks += 1
        stamp = self.get_clock().now().to_msg()
        self.last_stamp = stamp
        self.odom_pub.publish(self._odom(stamp))
        self.frames.publish(stamp, (d.x, d.y, d.yaw))
        if self._ticks % 5 == 0:  # amcl and GPS publish slower than odometry, as on a real robot
            self.pose_pub.publish(self._pose(stamp))
            self.fix_pub.publish(self._fix(stamp))

    def _odom(self, stamp) -> Odometry:
        d = self.drive
        x, y, yaw = self.localisation.odom_pose((d.x, d.y, d.yaw))
        msg = Odometry()
        msg.header.stamp = stamp
        msg.header.frame_id = "odom"
        msg.child_frame_id = "base_link"
        msg.pose.pose.position.x, msg.pose.pose.position.y = x, y
        q = quaternion_from_yaw(yaw)
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

    def _plan(self, goal: Goal | None) -> Path:
        """Straight lines from here to the goal and on through a mission's later waypoints, or an empty path."""
        msg = Path()
        msg.header.stamp = self.get_clock().now().to_msg()
        msg.header.frame_id = "map"
        x0, y0 = self.drive.x, self.drive.y
        for x1, y1 in [] if goal is None else [(goal.x, goal.y), *self.mission.beyond()]:
            steps = max(1, int(math.hypot(x1 - x0, y1 - y0) / 0.25))
            for i in range(0 if not msg.poses else 1, steps + 1):
                pose = PoseStamped()
                pose.header = msg.header
                pose.pose.position.x = x0 + (x1 - x0) * i / steps
                pose.pose.position.y = y0 + (y1 - y0) * i / steps
                pose.pose.orientation.w = 1.0
                msg.poses.append(pose)
            x0, y0 = x1, y1
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
                       help="start pose in the map frame (metres, radians); default: the first waypoint "
                            "of the first map in --maps-file. With --robots, each further boat or rover "
                            f"starts {SPACING_EAST_M:g} m east of the one before")
    group.add_argument("--maps-file", default=None,
                       help="all_maps.json or map_server yaml the default start comes from "
                            "(default: $ROVER_WEB_MAPS_FILE, else map_files/all_maps.json)")
    group.add_argument("--goal-topic", default="goal_pose",
                       help="PoseStamped goals to drive to (frame map; default goal_pose, in the robot's namespace)")
    group.add_argument("--goal-speed", type=float, default=0.5, metavar="M_PER_S",
                       help="top speed while driving to a goal or a mission's waypoints")
    group.add_argument("--no-walls", action="store_true",
                       help="drive through the floorplan's walls (by default a rover stops or slides at the "
                            "occupied cells of the first map in --maps-file; a boat of --robots never meets them)")
    group.add_argument("--battery", type=float, default=100 * START_CHARGE, metavar="PERCENT",
                       help="the battery's charge at start (default %(default)g)")
    group.add_argument("--debug-logs", action="store_true",
                       help="log the health checks at DEBUG every 5 s too (a real node logs at INFO)")
    group.add_argument("--no-perception", action="store_true",
                       help="publish no scan, costmaps, footprint or markers")
    group.add_argument("--scan-beams", type=int, default=360, help="beams of the simulated laser scan")
    group.add_argument("--scan-hz", type=float, default=10.0, help="laser scans a second")


@functools.lru_cache(maxsize=4)  # once, not once per robot of --robots
def first_map(maps_file: str | None = None):
    """The first map the GUI will show: the robot starts on it and meets its walls."""
    from rover_web.livemap.map_files import load_catalog, maps_file_path

    path = maps_file_path(maps_file or os.environ.get("ROVER_WEB_MAPS_FILE") or "map_files/all_maps.json")
    return next(iter(load_catalog(path).values()))


def default_start(maps_file: str | None = None) -> tuple[float, float, float]:
    """The first waypoint (else the centre) of the first map the GUI will show."""
    from rover_web.livemap.map_files import first_waypoint_or_centre

    return first_waypoint_or_centre(first_map(maps_file))


@functools.lru_cache(maxsize=4)
def floorplan_walls(maps_file: str | None = None) -> Walls | None:
    return Walls.of_map(first_map(maps_file))


def from_arguments(args: argparse.Namespace, context, namespace: str = "/", east_offset_m: float = 0.0,
                   kind: str = "") -> RoverSim:
    x, y, yaw = args.start if args.start else default_start(args.maps_file)
    # A boat is on the water, where the floorplan is only a picture: its GPS missions cross the park.
    walls = None if args.no_walls or kind == "boat" else floorplan_walls(args.maps_file)
    floorplan, waypoints = None, ()
    if not args.no_perception:
        from .sensors import Floorplan
        definition = first_map(args.maps_file)
        floorplan, waypoints = Floorplan.from_definition(definition), definition.waypoints
    return RoverSim(context=context, x=x + east_offset_m, y=y, yaw=yaw, stamped=args.stamped,
                    goal_topic=args.goal_topic, goal_speed_mps=args.goal_speed, namespace=namespace,
                    walls=walls, battery_charge=min(1.0, max(0.0, args.battery / 100)), debug_logs=args.debug_logs,
                    floorplan=floorplan, waypoints=waypoints, scan_beams=args.scan_beams, scan_hz=args.scan_hz)


def main(argv: list[str] | None = None) -> None:
    from .runner import run_part
    run_part(sys.modules[__name__], argv)


if __name__ == "__main__":
    main()
