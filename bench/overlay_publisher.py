"""A separate rclpy process for bench/overlays.py: a 1,080-beam LaserScan at 20 Hz and a 400 x 400
costmap at 1 Hz, both stamped with CLOCK_MONOTONIC (so the reader can age each event), plus a
latched AMCL pose for the scan to be placed with; with --tf, /tf (map -> odom -> base_link, with each
scan, same stamp) and /tf_static (the laser turned and off centre) instead, so every scan is placed
through a TF lookup."""

import argparse
import math
import sys
import time

import numpy as np
import rclpy
from geometry_msgs.msg import PoseWithCovarianceStamped
from nav_msgs.msg import OccupancyGrid
from rclpy.context import Context
from rclpy.signals import SignalHandlerOptions
from sensor_msgs.msg import LaserScan

from rover_web.ros import qos


def stamp(msg) -> None:
    ns = time.monotonic_ns()
    msg.header.stamp.sec, msg.header.stamp.nanosec = ns // 1_000_000_000, ns % 1_000_000_000


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--seconds", type=float, default=10.0)
    parser.add_argument("--beams", type=int, default=1080)
    parser.add_argument("--scan-hz", type=float, default=20.0)
    parser.add_argument("--grid", type=int, default=400)
    parser.add_argument("--tf", action="store_true", help="publish TF and place the scan through it")
    args = parser.parse_args()
    context = Context()
    rclpy.init(context=context, signal_handler_options=SignalHandlerOptions.NO)
    node = rclpy.create_node("bench_overlay_publisher", context=context)
    pose_pub = node.create_publisher(PoseWithCovarianceStamped, "/amcl_pose", qos.profile("latched"))
    scan_pub = node.create_publisher(LaserScan, "/scan", qos.profile("sensor_data"))
    grid_pub = node.create_publisher(OccupancyGrid, "/global_costmap/costmap", qos.profile("latched"))
    tf = _TfPublisher(node) if args.tf else None
    deadline = time.monotonic() + 15
    while (scan_pub.get_subscription_count() == 0 or grid_pub.get_subscription_count() == 0) \
            and time.monotonic() < deadline:
        time.sleep(0.01)
    pose = PoseWithCovarianceStamped()
    pose.header.frame_id = "map"
    pose.pose.pose.position.x, pose.pose.pose.position.y = 20.0, 10.0
    pose.pose.pose.orientation.w = 1.0
    pose_pub.publish(pose)  # unstamped: every scan is placed with it
    rng = np.random.default_rng(1)
    angles = np.linspace(-math.pi, math.pi, args.beams, endpoint=False)
    base = (4.0 + np.sin(angles * 3)).astype(np.float32)
    cells = np.zeros((args.grid, args.grid), dtype=np.int8)
    cells[::25, :] = 100
    cells[:, ::40] = 60
    time.sleep(0.5)
    print("publishing", flush=True)
    period = 1.0 / args.scan_hz
    start = time.monotonic()
    i = 0
    while (now := time.monotonic()) - start < args.seconds:
        target = start + i * period
        if (wait := target - now) > 0:
            time.sleep(wait)
        scan = LaserScan()
        scan.header.frame_id = "base_scan"
        scan.angle_min, scan.angle_increment = -math.pi, 2 * math.pi / args.beams
        scan.angle_max = math.pi - scan.angle_increment
        scan.range_min, scan.range_max = 0.05, 30.0
        scan.ranges = (base + rng.normal(0, 0.02, args.beams).astype(np.float32)).tolist()
        stamp(scan)
        if tf is not None:
            tf.publish(scan.header.stamp)
        scan_pub.publish(scan)
        if i % int(args.scan_hz) == 0:
            grid = OccupancyGrid()
            grid.header.frame_id = "map"
            grid.info.width = grid.info.height = args.grid
            grid.info.resolution = 0.05
            grid.info.origin.orientation.w = 1.0
            grid.data = np.roll(cells, i, axis=1).ravel().tobytes()
            stamp(grid)
            grid_pub.publish(grid)
        i += 1
    print("done", flush=True)
    time.sleep(0.2)
    node.destroy_node()
    context.try_shutdown()
    sys.exit(0)


class _TfPublisher:
    def __init__(self, node):
        from geometry_msgs.msg import TransformStamped
        from tf2_msgs.msg import TFMessage

        self.message, self.transform = TFMessage, TransformStamped
        self.pub = node.create_publisher(TFMessage, "/tf", qos.profile("default", depth=100))
        static = node.create_publisher(TFMessage, "/tf_static", qos.profile("latched"))
        static.publish(TFMessage(transforms=[self._make("base_link", "base_scan", (0.2, -0.1, 0.3), 0.4)]))

    def _make(self, parent, child, xyz, yaw, stamp=None):
        t = self.transform()
        if stamp is not None:
            t.header.stamp = stamp
        t.header.frame_id, t.child_frame_id = parent, child
        t.transform.translation.x, t.transform.translation.y, t.transform.translation.z = xyz
        t.transform.rotation.z, t.transform.rotation.w = math.sin(yaw / 2), math.cos(yaw / 2)
        return t

    def publish(self, stamp) -> None:
        self.pub.publish(self.message(transforms=[self._make("map", "odom", (18.0, 9.0, 0.0), 0.1, stamp),
                                                  self._make("odom", "base_link", (2.0, 1.0, 0.0), 0.2, stamp)]))


if __name__ == "__main__":
    main()
