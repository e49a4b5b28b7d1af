"""A hostile MarkerArray publisher in its own process (tests/integration/overlays/test_dds_profile.py).

    python tests/support/peers/marker_flood.py --topic /visualization_marker_array --markers 200000

Builds one array of N zero-point cubes (about 200 bytes each serialized) once, then answers stdin
lines: "hostile" publishes it, "small" publishes one cube with a new id; each answered with
{"event": "published", "markers": n, "subscribers": k}. Stdout starts with {"event": "ready"};
stdin EOF or "quit" stops it.
"""

import argparse
import json
import sys

import rclpy
from rclpy.context import Context
from rclpy.signals import SignalHandlerOptions
from visualization_msgs.msg import Marker, MarkerArray


def cube(i: int) -> Marker:
    m = Marker()
    m.header.frame_id = "map"
    m.ns, m.id, m.type = "flood", i, Marker.CUBE
    m.pose.orientation.w = 1.0
    m.scale.x = m.scale.y = m.scale.z = 0.1
    m.color.a = 1.0
    return m


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--topic", default="/visualization_marker_array")
    parser.add_argument("--markers", type=int, default=200_000)
    args = parser.parse_args()
    context = Context()
    rclpy.init(context=context, signal_handler_options=SignalHandlerOptions.NO)
    node = rclpy.create_node("test_marker_flood", context=context)
    pub = node.create_publisher(MarkerArray, args.topic, 10)
    hostile = MarkerArray(markers=[cube(i) for i in range(args.markers)])
    small_id = args.markers
    print(json.dumps({"event": "ready"}), flush=True)
    try:
        for line in sys.stdin:
            command = line.strip()
            if command == "quit":
                break
            if command == "hostile":
                pub.publish(hostile)
                n = len(hostile.markers)
            elif command == "small":
                small_id += 1
                pub.publish(MarkerArray(markers=[cube(small_id)]))
                n = 1
            else:
                continue
            print(json.dumps({"event": "published", "markers": n, "subscribers": pub.get_subscription_count()}),
                  flush=True)
    finally:
        node.destroy_node()
        context.try_shutdown()


if __name__ == "__main__":
    main()
