"""A separate rclpy process for bench/overlays.py: a 1,080-beam LaserScan at 20 Hz and a 400 x 400
costmap at 1 Hz, both stamped with CLOCK_MONOTONIC (so the reader can age each event), plus a
latched AMCL pose for the scan to be placed with."""

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
    args = parser.parse_args()
    context = Context()
    rclpy.init(context=context, signal_handler_options=SignalHandlerOptions.NO)
    node = rclpy.create_node("bench_overlay_publisher", context=context)
    pose_pub = node.create_publisher(PoseWithCovarianceStamped, "/amcl_pose", qos.profile("latched"))
    scan_pub = node.create_publisher(LaserScan, "/scan", qos.profile("sensor_data"))
    grid_pub = node.create_publisher(OccupancyGrid, "/global_costmap/costmap", qos.profile("latched"))
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


if __name__ == "__main__":
    main()
