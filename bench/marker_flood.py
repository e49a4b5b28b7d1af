"""A separate rclpy process for bench/hostile.py: what the review's hostile DDS peer published, one
MarkerArray of N zero-point cubes (default 200,000) on /visualization_marker_array, a few times
(from several DDS writers at once with --writers)."""

import argparse
import time

import rclpy
from rclpy.context import Context
from rclpy.signals import SignalHandlerOptions
from visualization_msgs.msg import Marker, MarkerArray


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--markers", type=int, default=200_000)
    parser.add_argument("--times", type=int, default=3)
    parser.add_argument("--period", type=float, default=2.0)
    parser.add_argument("--writers", type=int, default=1, help="DDS writers publishing it at once")
    args = parser.parse_args()
    context = Context()
    rclpy.init(context=context, signal_handler_options=SignalHandlerOptions.NO)
    node = rclpy.create_node("bench_marker_flood", context=context)
    pubs = [node.create_publisher(MarkerArray, "/visualization_marker_array", 10) for _ in range(args.writers)]
    pub = pubs[0]
    array = MarkerArray()
    for i in range(args.markers):
        m = Marker()
        m.header.frame_id = "map"
        m.ns, m.id, m.type = "flood", i, Marker.CUBE
        m.pose.orientation.w = 1.0
        m.scale.x = m.scale.y = m.scale.z = 0.1
        m.color.a = 1.0
        array.markers.append(m)
    deadline = time.monotonic() + 15
    while pub.get_subscription_count() == 0 and time.monotonic() < deadline:
        time.sleep(0.01)
    time.sleep(0.5)
    print("publishing", flush=True)
    for _ in range(args.times):
        for each in pubs:
            each.publish(array)
        time.sleep(args.period)
    node.destroy_node()
    context.try_shutdown()


if __name__ == "__main__":
    main()
