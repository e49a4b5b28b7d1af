"""A sensor_msgs/PointCloud2 publisher for bench/view3d.py: N points (x, y, z, intensity float32) of a
room seen by a spinning lidar, at a rate, each stamped with the wall clock when it is published.

    .venv/bin/python bench/cloud_publisher.py --points 100000 --rate 10 --seconds 30
"""

from __future__ import annotations

import argparse
import time

import numpy as np
import rclpy
from rclpy.context import Context
from rclpy.qos import qos_profile_sensor_data
from sensor_msgs.msg import PointCloud2, PointField


def room(n: int, rng) -> np.ndarray:
    """Walls of a 20 x 12 m room, 3 m high, and a floor: what a lidar in it returns."""
    a = rng.uniform(0, 2 * np.pi, n)
    wall = rng.random(n) < 0.8
    r = np.where(wall, np.minimum(10 / np.maximum(np.abs(np.cos(a)), 1e-6), 6 / np.maximum(np.abs(np.sin(a)), 1e-6)),
                 rng.uniform(0.5, 6, n))
    z = np.where(wall, rng.uniform(-0.3, 2.7, n), -0.3)
    pts = np.stack([r * np.cos(a), r * np.sin(a), z, rng.uniform(0, 255, n)], axis=1)
    return pts.astype(np.float32)


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--points", type=int, default=100_000)
    parser.add_argument("--rate", type=float, default=10.0)
    parser.add_argument("--seconds", type=float, default=30.0)
    parser.add_argument("--topic", default="/points")
    args = parser.parse_args()
    context = Context()
    rclpy.init(context=context)
    node = rclpy.create_node("bench_cloud_publisher", context=context)
    pub = node.create_publisher(PointCloud2, args.topic, qos_profile_sensor_data)
    rng = np.random.default_rng(1)
    clouds = [room(args.points, rng).tobytes() for _ in range(4)]  # a few, so consecutive clouds differ
    msg = PointCloud2()
    msg.header.frame_id = "base_link"
    msg.height, msg.width = 1, args.points
    msg.fields = [PointField(name=n, offset=4 * i, datatype=PointField.FLOAT32, count=1)
                  for i, n in enumerate(("x", "y", "z", "intensity"))]
    msg.point_step, msg.row_step = 16, 16 * args.points
    msg.is_dense = True
    print("publishing", flush=True)
    period = 1.0 / args.rate
    next_t = time.monotonic()
    end = next_t + args.seconds
    i = 0
    while time.monotonic() < end:
        msg.data = clouds[i % len(clouds)]
        now = time.time()
        msg.header.stamp.sec, msg.header.stamp.nanosec = int(now), int((now % 1) * 1e9)
        pub.publish(msg)
        i += 1
        next_t += period
        time.sleep(max(0.0, next_t - time.monotonic()))
    node.destroy_node()
    rclpy.shutdown(context=context)


if __name__ == "__main__":
    main()
