"""A separate rclpy process logging through its node's logger (so to /rosout) at a steady rate."""

import argparse
import sys
import time

import rclpy
from rclpy.context import Context
from rclpy.signals import SignalHandlerOptions


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--rate", type=float, default=1000.0, help="lines a second (0: as fast as possible)")
    parser.add_argument("--count", type=int, default=10000)
    args = parser.parse_args()
    context = Context()
    rclpy.init(context=context, signal_handler_options=SignalHandlerOptions.NO)
    node = rclpy.create_node("bench_rosout_publisher", context=context)
    logger = node.get_logger()
    time.sleep(1.0)  # discovery: the app's /rosout subscription matches
    print("publishing", flush=True)
    start = time.monotonic()
    for i in range(args.count):
        if args.rate > 0 and i % 10 == 0:  # 10 lines per wake-up: a sleep per line overshoots at 1 kHz
            while (wait := start + i / args.rate - time.monotonic()) > 0:
                time.sleep(wait)
        logger.info(f"bench line {i}: wheel odometry {i % 97} ticks")
    print(f"done {time.monotonic() - start:.2f}", flush=True)
    time.sleep(0.5)
    node.destroy_node()
    context.try_shutdown()
    sys.exit(0)


if __name__ == "__main__":
    main()
