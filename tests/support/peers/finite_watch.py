"""A real rclpy node that subscribes to every topic a node publishes and checks every float is finite.

Usage: finite_watch.py <publishing node name prefix>. It prints {"event": "watching", "topics": [...]}
each time it subscribes to more topics, {"event": "nonfinite", "found": [...]} at once for a
message with a non-finite float; on the line "quit" (stdin) it prints one JSON report,
{"event": "report", "counts": {topic: n}, "nonfinite": ["topic field=value", ...]}, and exits.
Messages are taken as Python objects, not dicts, so no conversion can hide a NaN.
"""

import array
import json
import math
import sys
import threading

import rclpy
from rclpy.context import Context
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rclpy.signals import SignalHandlerOptions

from rover_web.ros.typesupport import message_class

lock = threading.Lock()
counts: dict[str, int] = {}
nonfinite: list[str] = []


def emit(**event):
    with lock:
        sys.stdout.write(json.dumps(event) + "\n")
        sys.stdout.flush()


def walk(value, where: str, found: list[str]) -> None:
    if isinstance(value, float):
        if not math.isfinite(value):
            found.append(f"{where}={value}")
    elif isinstance(value, (list, tuple, array.array)) or type(value).__name__ == "ndarray":
        for i, item in enumerate(value):
            walk(float(item) if type(item).__name__.startswith("float") else item, f"{where}[{i}]", found)
    elif hasattr(value, "get_fields_and_field_types"):
        for field in value.get_fields_and_field_types():
            walk(getattr(value, field), f"{where}.{field}", found)


def main():
    prefix = sys.argv[1]
    context = Context()
    rclpy.init(context=context, signal_handler_options=SignalHandlerOptions.NO)
    node = rclpy.create_node("finite_watch", context=context)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(node)
    subs = {}

    def on_message(msg, topic):
        found: list[str] = []
        walk(msg, "", found)
        with lock:
            counts[topic] = counts.get(topic, 0) + 1
            nonfinite.extend(f"{topic} {f}" for f in found[:5])
        if found:
            emit(event="nonfinite", found=[f"{topic} {f}" for f in found[:5]])

    def discover():
        added = False
        for topic, types in node.get_topic_names_and_types():
            if topic in subs:
                continue
            ours = [e for e in node.get_publishers_info_by_topic(topic) if e.node_name.startswith(prefix)]
            if not ours:
                continue
            reliable = all(e.qos_profile.reliability == ReliabilityPolicy.RELIABLE for e in ours)
            latched = all(e.qos_profile.durability == DurabilityPolicy.TRANSIENT_LOCAL for e in ours)
            profile = QoSProfile(depth=50, reliability=ReliabilityPolicy.RELIABLE if reliable
                                 else ReliabilityPolicy.BEST_EFFORT,
                                 durability=DurabilityPolicy.TRANSIENT_LOCAL if latched else DurabilityPolicy.VOLATILE)
            subs[topic] = node.create_subscription(message_class(types[0]), topic,
                                                   lambda m, t=topic: on_message(m, t), profile)
            added = True
        if added:
            emit(event="watching", topics=sorted(subs))

    node.create_timer(0.2, discover)

    def spin():
        try:
            executor.spin()
        except ExternalShutdownException:
            pass

    spinner = threading.Thread(target=spin, daemon=True)
    spinner.start()
    emit(event="ready")
    for line in sys.stdin:
        if line.strip() == "quit":
            break
    with lock:
        report = {"event": "report", "counts": dict(counts), "nonfinite": list(nonfinite)}
    executor.shutdown(timeout_sec=2)
    node.destroy_node()
    rclpy.shutdown(context=context)
    spinner.join(2)
    emit(**report)


if __name__ == "__main__":
    main()
