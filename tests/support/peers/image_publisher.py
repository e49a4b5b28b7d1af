"""A camera in its own process: publishes sensor_msgs/Image frames at a fixed rate (tests, benchmarks).

    python tests/peers/image_publisher.py --topic /cam --width 320 --height 240 --hz 30 [--qos sensor_data]

Frame n has header.stamp = (n + 1, 0), so every frame is told apart by its stamp, and is filled
with the colour (n mod 256, 100, 200) in rgb8; with --grain G, a fixed random grain of ±G is
added, so its JPEGs are as large as a real camera's (rate-control tests need that).
Stdout (JSON lines): {"event": "ready"}; each stdin
line "status" is answered with {"event": "status", "published": n, "subscribers": k}; stdin EOF
or "quit" stops it.
"""

import argparse
import array
import json
import sys
import threading

import rclpy
from rclpy.context import Context
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.signals import SignalHandlerOptions
from sensor_msgs.msg import Image

from rover_web.ros import qos


def frame_bytes(n: int, width: int, height: int, grain=None) -> array.array:
    pixel = bytes((n % 256, 100, 200))
    data = array.array("B")
    if grain is None:
        data.frombytes(pixel * (width * height))
    else:
        import numpy as np

        data.frombytes(np.clip(grain + np.frombuffer(pixel, np.uint8).astype(np.int16), 0, 255)
                       .astype(np.uint8).tobytes())
    return data


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--topic", default="/camera/image_raw")
    parser.add_argument("--width", type=int, default=320)
    parser.add_argument("--height", type=int, default=240)
    parser.add_argument("--hz", type=float, default=30.0)
    parser.add_argument("--qos", default="default")
    parser.add_argument("--grain", type=int, default=0)
    args = parser.parse_args()
    grain = None
    if args.grain:
        import numpy as np

        grain = np.random.default_rng(7).integers(-args.grain, args.grain + 1, (args.height, args.width, 3),
                                                  dtype=np.int16)

    context = Context()
    rclpy.init(context=context, signal_handler_options=SignalHandlerOptions.NO)
    node = rclpy.create_node("image_publisher", context=context)
    pub = node.create_publisher(Image, args.topic, qos.profile(args.qos))
    count = [0]

    def tick() -> None:
        n = count[0]
        msg = Image()
        msg.header.stamp.sec = n + 1
        msg.header.frame_id = "test_camera"
        msg.width, msg.height, msg.encoding, msg.step = args.width, args.height, "rgb8", args.width * 3
        msg.data = frame_bytes(n, args.width, args.height, grain)
        pub.publish(msg)
        count[0] = n + 1

    node.create_timer(1.0 / args.hz, tick)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(node)

    def spin() -> None:
        try:
            executor.spin()
        except ExternalShutdownException:
            pass

    spinner = threading.Thread(target=spin, daemon=True)
    spinner.start()
    print(json.dumps({"event": "ready"}), flush=True)
    for line in sys.stdin:
        command = line.strip()
        if command == "quit":
            break
        if command == "status":
            print(json.dumps({"event": "status", "published": count[0],
                              "subscribers": pub.get_subscription_count()}), flush=True)
    executor.shutdown(timeout_sec=1.0)
    spinner.join(2)
    node.destroy_node()
    context.try_shutdown()


if __name__ == "__main__":
    main()
