"""A separate rclpy process publishing /tf like a 200-frame robot: 1,000 transforms a second.

    .venv/bin/python bench/tf_publisher.py --frames 200 --rate 1000 --seconds 20

Frames: a chain f1 ... f10 under map (the 10-frame chain bench/tf.py looks up through), and the
rest as leaves spread under the chain. Each message carries 10 transforms, as robot_state_publisher
batches its joints; the messages take turns so each frame is sent rate / frames times a second.
Prints "publishing", then one JSON line {"sent_transforms", "sent_messages", "seconds"}.
"""

import argparse
import json
import math
import sys
import time

import rclpy
from geometry_msgs.msg import TransformStamped
from rclpy.context import Context
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from rclpy.signals import SignalHandlerOptions
from tf2_msgs.msg import TFMessage

PER_MESSAGE = 10


def frames(count: int) -> list[tuple[str, str]]:
    chain = [("map" if i == 1 else f"f{i - 1}", f"f{i}") for i in range(1, 11)]
    leaves = [(f"f{1 + i % 10}", f"leaf{i}") for i in range(count - len(chain))]
    return chain + leaves


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--topic", default="/tf")
    parser.add_argument("--frames", type=int, default=200)
    parser.add_argument("--rate", type=float, default=1000.0, help="transforms per second")
    parser.add_argument("--seconds", type=float, default=20.0)
    args = parser.parse_args()
    context = Context()
    rclpy.init(context=context, signal_handler_options=SignalHandlerOptions.NO)
    node = rclpy.create_node("bench_tf_publisher", context=context)
    qos = QoSProfile(depth=100, history=HistoryPolicy.KEEP_LAST, reliability=ReliabilityPolicy.RELIABLE,
                     durability=DurabilityPolicy.VOLATILE)
    pub = node.create_publisher(TFMessage, args.topic, qos)
    pairs = frames(args.frames)
    batches = []
    for start in range(0, len(pairs), PER_MESSAGE):
        batch = []
        for parent, child in pairs[start:start + PER_MESSAGE]:
            t = TransformStamped()
            t.header.frame_id, t.child_frame_id = parent, child
            t.transform.translation.x, t.transform.translation.y, t.transform.translation.z = 0.1, 0.2, 0.05
            t.transform.rotation.z, t.transform.rotation.w = math.sin(0.05), math.cos(0.05)
            batch.append(t)
        batches.append(batch)
    deadline = time.monotonic() + 15
    while pub.get_subscription_count() == 0 and time.monotonic() < deadline:
        time.sleep(0.01)
    time.sleep(0.5)
    print("publishing", flush=True)
    period = PER_MESSAGE / args.rate
    count = int(args.seconds / period)
    start = time.monotonic()
    sent = 0
    for i in range(count):
        target = start + i * period
        while (wait := target - time.monotonic()) > 0:
            time.sleep(wait)
        batch = batches[i % len(batches)]
        ns = time.time_ns()
        for t in batch:
            t.header.stamp.sec, t.header.stamp.nanosec = ns // 1_000_000_000, ns % 1_000_000_000
        pub.publish(TFMessage(transforms=batch))
        sent += len(batch)
    elapsed = time.monotonic() - start
    print(json.dumps({"sent_transforms": sent, "sent_messages": count, "seconds": round(elapsed, 2)}), flush=True)
    time.sleep(0.3)
    node.destroy_node()
    context.try_shutdown()
    sys.exit(0)


if __name__ == "__main__":
    main()
