"""The simulated rover's frames, published as a real robot's are: /tf and /tf_static (REP 105).

`odom` -> `base_link` is its odometry and `map` -> `odom` its own localisation's correction: an
operator's initial pose moves the robot on the map by changing `map` -> `odom` (as AMCL does), not
by making odometry's position jump. Both go out with every odometry message, at its rate and
stamp. The sensors' mounts go out once on /tf_static (transient local, as robot_state_publisher
sends them): a laser mounted upside down (roll 180 degrees), turned and off the robot's centre, a
GPS antenna above it, and a camera pitched down. The laser's scan is ray-cast from that
mount (perception.py), so it lands on the walls only when it is placed through TF: the configured
offset (0, 0, 0 by default) would draw it mirrored.

The mount maths is pure (`Mount`, `beam_directions`); tf2_msgs is imported only by `FramePublisher`,
and a simulator without it publishes no TF and says so once.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

Pose2D = tuple[float, float, float]

MAP_FRAME, ODOM_FRAME, BASE_FRAME = "map", "odom", "base_link"
LASER_FRAME, GPS_FRAME, CAMERA_FRAME = "base_scan", "gps", "camera"


@dataclass(frozen=True)
class Mount:
    """A sensor fixed on base_link: translation (m) and roll, pitch, yaw (rad, applied as z-y-x)."""

    frame: str
    x: float
    y: float
    z: float
    roll: float = 0.0
    pitch: float = 0.0
    yaw: float = 0.0

    @property
    def quaternion(self) -> tuple[float, float, float, float]:
        """(x, y, z, w) of Rz(yaw) Ry(pitch) Rx(roll), tf2's setRPY."""
        cr, sr = math.cos(self.roll / 2), math.sin(self.roll / 2)
        cp, sp = math.cos(self.pitch / 2), math.sin(self.pitch / 2)
        cy, sy = math.cos(self.yaw / 2), math.sin(self.yaw / 2)
        return (sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy,
                cr * cp * sy - sr * sp * cy, cr * cp * cy + sr * sp * sy)


LASER = Mount(LASER_FRAME, 0.15, -0.08, 0.25, roll=math.pi, yaw=0.5)
# The antenna straight above the centre: the simulated /fix is the robot's map pose, so a mount off
# centre would make the GPS map (which takes it out through TF) draw the robot off its fix.
GPS = Mount(GPS_FRAME, 0.0, 0.0, 0.60)
CAMERA = Mount(CAMERA_FRAME, 0.20, 0.0, 0.35, pitch=0.3)
MOUNTS = (LASER, GPS, CAMERA)


def compose(a: Pose2D, b: Pose2D) -> Pose2D:
    c, s = math.cos(a[2]), math.sin(a[2])
    yaw = a[2] + b[2]
    return a[0] + c * b[0] - s * b[1], a[1] + s * b[0] + c * b[1], math.atan2(math.sin(yaw), math.cos(yaw))


def invert(a: Pose2D) -> Pose2D:
    c, s = math.cos(a[2]), math.sin(a[2])
    return -c * a[0] - s * a[1], s * a[0] - c * a[1], -a[2]


def laser_origin(robot: Pose2D, mount: Mount = LASER) -> tuple[float, float, float]:
    """(x, y, heading of the mount's x axis) of a level (roll 0 or pi, pitch 0) laser in the map."""
    return compose(robot, (mount.x, mount.y, mount.yaw))


def beam_directions(angles: np.ndarray, mount: Mount = LASER) -> np.ndarray:
    """Each beam's angle from the mount's x axis, in the map plane: a laser rolled upside down
    sweeps the other way (its y axis points down the robot's -y), so a beam at +a points at -a."""
    flipped = math.cos(mount.roll) < 0
    return -angles if flipped else angles


class Localisation:
    """map -> odom of a robot whose map pose is its truth (the simulator has no drift).

    Odometry is the map pose seen from where odometry started; a relocalisation (initial pose)
    moves map -> odom so odometry's position stays continuous. Its heading is kept (odom stays
    aligned with the map, east in the demo), and the turn goes into odometry's yaw as a compass-aided
    base's would: the GPS map reads the heading from /odom."""

    def __init__(self, start: Pose2D):
        self.map_t_odom: Pose2D = start

    def odom_pose(self, map_pose: Pose2D) -> Pose2D:
        return compose(invert(self.map_t_odom), map_pose)

    def relocalise(self, old_map_pose: Pose2D, new_map_pose: Pose2D) -> None:
        """The robot is told it is at new_map_pose while its odometry still reads old's position."""
        ox, oy, _ = self.odom_pose(old_map_pose)
        yaw = self.map_t_odom[2]
        c, s = math.cos(yaw), math.sin(yaw)
        self.map_t_odom = (new_map_pose[0] - (c * ox - s * oy), new_map_pose[1] - (s * ox + c * oy), yaw)


class FramePublisher:
    """/tf (map -> odom, odom -> base_link) per odometry tick and /tf_static once, on the robot's node."""

    def __init__(self, node, localisation: Localisation, mounts=MOUNTS):
        self.node = node
        self.localisation = localisation
        try:
            from geometry_msgs.msg import TransformStamped
            from tf2_msgs.msg import TFMessage
        except ImportError:
            node.get_logger().warning("tf2_msgs is not installed: the simulator publishes no /tf or /tf_static "
                                      "(scripts/build_interfaces.sh builds it into the venv)")
            self.tf_pub = None
            return
        from rover_web.ros import qos

        self._message, self._transform = TFMessage, TransformStamped
        # tf2's QoS: /tf reliable volatile, /tf_static reliable transient local keeping its one message.
        self.tf_pub = node.create_publisher(TFMessage, "tf", qos.profile("default", depth=100))
        self.static_pub = node.create_publisher(TFMessage, "tf_static", qos.profile("latched"))
        stamp = node.get_clock().now().to_msg()
        self.static_pub.publish(TFMessage(transforms=[self._stamped(stamp, BASE_FRAME, m.frame, (m.x, m.y, m.z),
                                                                    m.quaternion) for m in mounts]))

    def _stamped(self, stamp, parent: str, child: str, xyz, q):
        t = self._transform()
        t.header.stamp = stamp
        t.header.frame_id, t.child_frame_id = parent, child
        t.transform.translation.x, t.transform.translation.y, t.transform.translation.z = map(float, xyz)
        r = t.transform.rotation
        r.x, r.y, r.z, r.w = map(float, q)
        return t

    def publish(self, stamp, map_pose: Pose2D) -> None:
        if self.tf_pub is None:
            return
        odom = self.localisation.odom_pose(map_pose)
        m = self.localisation.map_t_odom
        self.tf_pub.publish(self._message(transforms=[
            self._stamped(stamp, MAP_FRAME, ODOM_FRAME, (m[0], m[1], 0.0), _yaw_quaternion(m[2])),
            self._stamped(stamp, ODOM_FRAME, BASE_FRAME, (odom[0], odom[1], 0.0), _yaw_quaternion(odom[2]))]))


def _yaw_quaternion(yaw: float) -> tuple[float, float, float, float]:
    return 0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)
