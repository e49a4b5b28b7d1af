"""rclpy -> rclpy: how late a plain rclpy subscriber gets bench/odom_publisher.py's stamped /odom.

    .venv/bin/python bench/odom_latency.py --count N

The ROS part of bench/events.py's latency, with nothing else: prints "ready" once subscribed,
then one JSON line {"n", "median_ms", "p99_ms"} after N messages (or 30 s).
"""

import argparse
import json
import statistics
import time

import rclpy
from nav_msgs.msg import Odometry
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.signals import SignalHandlerOptions


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--topic", default="/odom")
    parser.add_argument("--count", type=int, default=1000)
    args = parser.parse_args()
    context = Context()
    rclpy.init(context=context, signal_handler_options=SignalHandlerOptions.NO)
    node = rclpy.create_node("bench_odom_latency", context=context)
    late: list[float] = []

    def on_odom(msg: Odometry) -> None:
        now = time.monotonic()
        late.append(now - (msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9))

    node.create_subscription(Odometry, args.topic, on_odom, 10)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(node)
    print("ready", flush=True)
    deadline = time.monotonic() + 30
    while len(late) < args.count and time.monotonic() < deadline:
        executor.spin_once(timeout_sec=0.1)
    ms = sorted(x * 1000 for x in late)
    p99 = ms[min(len(ms) - 1, int(len(ms) * 0.99))] if ms else None
    print(json.dumps({"n": len(ms), "median_ms": statistics.median(ms) if ms else None, "p99_ms": p99}), flush=True)
    node.destroy_node()
    context.try_shutdown()


if __name__ == "__main__":
    main()
