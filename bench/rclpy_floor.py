"""What receiving 100 Hz nav_msgs/Odometry costs a bare rclpy subscriber, as messages and as raw bytes.

    .venv/bin/python bench/rclpy_floor.py [--seconds 8] [--rounds 2]

The floor under rover_web's event path that no web code can go below: a process with one node,
one subscription and rclpy's SingleThreadedExecutor, its CPU while bench/odom_publisher.py (another
process) publishes at 100 Hz. "raw" takes the serialized bytes (raw=True), as telemetry does since
ros/cdr.py; "message" lets rclpy build the whole message.
"""

from __future__ import annotations

import argparse
import os
import random
import resource
import subprocess
import sys
import threading
import time

from common import ROOT, machine


def child(raw: bool, seconds: float) -> None:
    import rclpy
    from nav_msgs.msg import Odometry
    from rclpy.context import Context
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.signals import SignalHandlerOptions

    context = Context()
    rclpy.init(context=context, signal_handler_options=SignalHandlerOptions.NO)
    node = rclpy.create_node("bench_rclpy_floor", context=context)
    received = [0]

    def on_message(_msg) -> None:
        received[0] += 1

    node.create_subscription(Odometry, "/odom", on_message, 10, raw=raw)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(node)
    spinner = threading.Thread(target=executor.spin, daemon=True)
    spinner.start()
    print("ready", flush=True)
    deadline = time.monotonic() + 20
    while received[0] == 0 and time.monotonic() < deadline:  # discovery, then the publisher's start
        time.sleep(0.05)
    time.sleep(1.0)
    r0, t0, n0 = resource.getrusage(resource.RUSAGE_SELF), time.monotonic(), received[0]
    time.sleep(seconds)
    r1, t1, n1 = resource.getrusage(resource.RUSAGE_SELF), time.monotonic(), received[0]
    cpu = r1.ru_utime + r1.ru_stime - r0.ru_utime - r0.ru_stime
    print(f"{'raw' if raw else 'message':8s} {n1 - n0:5d} messages  CPU {100 * cpu / (t1 - t0):5.1f}% of one core"
          f"  {1e6 * cpu / max(1, n1 - n0):5.0f} µs per message", flush=True)
    executor.shutdown(timeout_sec=1.0)
    spinner.join(1.0)
    node.destroy_node()
    context.try_shutdown()


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--seconds", type=float, default=8.0)
    parser.add_argument("--rounds", type=int, default=2)
    parser.add_argument("--child", choices=["raw", "message"])
    args = parser.parse_args()
    if args.child:
        child(args.child == "raw", args.seconds)
        return
    print(f"# rclpy floor on {machine()}: /odom at 100 Hz from another process")
    env = {**os.environ, "ROS_DOMAIN_ID": str(random.randint(201, 230)), "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST",
           "PYTHONPATH": str(ROOT)}
    for _ in range(args.rounds):
        for mode in ("message", "raw"):
            sub = subprocess.Popen([sys.executable, __file__, "--child", mode, "--seconds", str(args.seconds)],
                                   env=env, stdout=subprocess.PIPE, text=True)
            assert sub.stdout.readline().strip() == "ready"
            count = int((args.seconds + 4) * 100)
            pub = subprocess.Popen([sys.executable, str(ROOT / "bench" / "odom_publisher.py"), "--rate", "100",
                                    "--count", str(count)], env=env, stdout=subprocess.DEVNULL)
            print(sub.stdout.readline().rstrip())
            sub.wait(30)
            pub.wait(30)


if __name__ == "__main__":
    main()
