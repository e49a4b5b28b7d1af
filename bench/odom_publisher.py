"""A separate rclpy process publishing nav_msgs/Odometry stamped with CLOCK_MONOTONIC (for latency)."""

import argparse
import sys
import time

import rclpy
from nav_msgs.msg import Odometry
from rclpy.context import Context
from rclpy.signals import SignalHandlerOptions


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--topic", default="/odom")
    parser.add_argument("--rate", type=float, default=100.0)
    parser.add_argument("--count", type=int, default=1000)
    args = parser.parse_args()
    context = Context()
    rclpy.init(context=context, signal_handler_options=SignalHandlerOptions.NO)
    node = rclpy.create_node("bench_odom_publisher", context=context)
    pub = node.create_publisher(Odometry, args.topic, 10)
    deadline = time.monotonic() + 15
    while pub.get_subscription_count() == 0 and time.monotonic() < deadline:
        time.sleep(0.01)
    time.sleep(0.5)
    print("publishing", flush=True)
    period = 1.0 / args.rate
    start = time.monotonic()
    for i in range(args.count):
        target = start + i * period
        while (wait := target - time.monotonic()) > 0:
            time.sleep(wait)
        msg = Odometry()
        msg.header.frame_id = "odom"
        msg.pose.pose.orientation.w = 1.0
        msg.pose.pose.position.x = float(i)
        ns = time.monotonic_ns()
        msg.header.stamp.sec, msg.header.stamp.nanosec = ns // 1_000_000_000, ns % 1_000_000_000
        pub.publish(msg)
    print("done", flush=True)
    time.sleep(0.2)
    node.destroy_node()
    context.try_shutdown()
    sys.exit(0)


if __name__ == "__main__":
    main()
